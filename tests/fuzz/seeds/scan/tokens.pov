// every token kind
/* nested /* block */ comment */
#declare A = 1.5e-3 + .5 - 2. * 3 / 4;
#declare S = "esc \" \\ \n \t \u00e9 \u263a";
#if (A <= 1 & A >= 0 | A != 2) #end
x ? y : z ! [1] <1,2,3> { } ; sphere_sweep camera
