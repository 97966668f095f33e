// String functions and macro arguments by reference: every #debug line is
// compared exactly with POV-Ray 3.7.0's output (strings.expected, made by
// `povray +Istrings.pov +W8 +H8 -F -D -GR -GS +GDstrings.out`).
#version 3.7;
global_settings { assumed_gamma 1 }
// ---- str: width > 0, width < 0 (zero padded), width 0, precision < 0 (6)
#debug concat("str1 [", str(3.14159, 0, 2), "][", str(-2.5, -8, 3), "][", str(7, 5, -1), "][", str(0.5, 0, 0), "][", str(1.5, 0, 0), "][", str(2.5, 0, 0), "]\n")
#debug concat("str2 [", str(123456.789, 3, 1), "][", str(-0.0004, 0, 3), "][", str(1/3, 12, 10), "][", str(-7, -6, -1), "][", str(1e300, 0, 2), "][", str(-1e300, 10, -1), "]\n")
#debug concat("str3 [", str(42, 0, 0), "][", str(1e-7, 0, 9), "][", str(pi, -12, 5), "][", str(99.995, 0, 2), "]\n")
// ---- vstr: 2 to 5 terms, a float fills the first term only
#debug concat("vstr1 [", vstr(3, <1, 2, 3>, ", ", 0, 1), "][", vstr(3, 5, ",", 0, 1), "][", vstr(4, <1, 2>, ":", 6, -1), "]\n")
#debug concat("vstr2 [", vstr(2, <1.25, -2.5, 9>, "", -7, 2), "][", vstr(5, <0.1, 0.2, 0.3, 0.4, 0.5>, " ", 0, 3), "][", vstr(9, <1,2,3,4,5>, "/", 0, 0), "][", vstr(1, <7, 8>, "|", 0, 0), "]\n")
#declare Sep = concat(",", " ");
#debug concat("vstr3 [", vstr(3, x + 2 * y, Sep, 5, 2), "][", vstr(3, <1, 2, 3> * 2 - 1, ";", 0, 0), "]\n")
// ---- concat, chr, asc, strlen, strcmp, strupr, strlwr, substr, val
#debug concat("cat [", concat("a"), "][", concat("a", "b", "c", "d"), "][", concat(str(1,0,0), chr(65), chr(97), chr(48)), "]\n")
#debug concat("asc [", str(asc("A"), 0, 0), "][", str(asc("z"), 0, 0), "][", str(asc(" "), 0, 0), "][", str(asc(chr(126)), 0, 0), "][", str(asc(""), 0, 0), "]\n")
#debug concat("len [", str(strlen(""), 0, 0), "][", str(strlen("abc\n"), 0, 0), "][", str(strlen(concat("ab", "cd")), 0, 0), "][", str(strlen("tab\there"), 0, 0), "]\n")
#debug concat("cmp [", str(strcmp("a", "c"), 0, 0), "][", str(strcmp("abc", "ab"), 0, 0), "][", str(strcmp("ab", "abc"), 0, 0), "][", str(strcmp("same", "same"), 0, 0), "][", str(strcmp("", "A"), 0, 0), "][", str(strcmp("Zebra", "apple"), 0, 0), "]\n")
#debug concat("case [", strupr("aBc1-xyz"), "][", strlwr("AbC2_XYZ"), "][", strupr(""), "]\n")
#debug concat("sub [", substr("hello", 2, 3), "][", substr("hello", 1, 5), "][", substr("hello", 5, 1), "][", substr("hello", 3, 0), "][", substr("hello", 6, 0), "]\n")
#debug concat("val [", str(val("12.5e1x"), 0, 3), "][", str(val("  -3e2"), 0, 1), "][", str(val("abc"), 0, 1), "][", str(val(".5"), 0, 2), "][", str(val("0x10"), 0, 1), "]\n")
// ---- datetime: days since 2000-01-01 UTC, default and strftime formats
#debug concat("dt1 [", datetime(0), "][", datetime(1.5, "%Y/%m/%d %H:%M:%S %j"), "][", datetime(-10957.25), "]\n")
#debug concat("dt2 [", datetime(8765.4321), "][", datetime(366, "%y %e %I%% %w %U"), "]\n")
#debug concat("dt4 [", datetime(-0.5 / 86400), "][", datetime(0.49 / 86400), "]\n")
#debug concat("dt3 [", datetime(12345.678, "%H:%M"), "][", datetime(59, "%m-%d"), "][", datetime(60, "%m-%d"), "]\n")
// ---- file_exists: beside the scene, on the library path, missing
#debug concat("fe [", str(file_exists("strings.pov"), 0, 0), str(file_exists("colors.inc"), 0, 0), str(file_exists("no_such_file.inc"), 0, 0), "]\n")
// ---- strings in comparisons and #switch-free logic
#declare S1 = "abc";
#if (strcmp(S1, "abc") = 0 & strlen(S1) = 3) #debug "if [yes]\n" #else #debug "if [no]\n" #end
// ---- macro arguments by reference: identifiers and array elements
#macro Set(A, V) #declare A = V; #end
#macro Inc(A) #declare A = A + 1; #end
#macro Loc(A) #local A = 7; #end
#macro Pass(B) Inc(B) #end
#macro Cat(S) #declare S = concat(S, "!"); #end
#declare Arr = array[5] {1, 2, 3, 4, 5}
Set(Arr[2], 42)
Inc(Arr[0])
Loc(Arr[3])
Pass(Arr[4])
Set(Arr[1] + 0, 99)
#declare G = array[2][2] {{1, 2}, {3, 4}}
#declare I = 1;
Set(G[I][0], -8)
Inc(G[1][I])
#declare Strs = array[2] {"a", "b"}
Cat(Strs[1])
Cat(Strs[1])
#declare Vs = array[2] {<1, 2, 3>, <4, 5, 6>}
Set(Vs[0], <7, 8, 9>)
#declare Nest = array[2]
#declare Nest[1] = array[2] {10, 20}
Inc(Nest[1][1])
#declare K = 5;
Inc(K)
#debug concat("ref1 [", str(Arr[0], 0, 0), ",", str(Arr[1], 0, 0), ",", str(Arr[2], 0, 0), ",", str(Arr[3], 0, 0), ",", str(Arr[4], 0, 0), "]\n")
#debug concat("ref2 [", str(G[1][0], 0, 0), ",", str(G[1][1], 0, 0), "][", Strs[0], Strs[1], "][", vstr(3, Vs[0], ",", 0, 0), "][", str(Nest[1][1], 0, 0), "][", str(K, 0, 0), "]\n")
// ---- charset: ascii (the default) turns each byte above 127 of a literal
// into a space; utf8 keeps code points; output to C strings (#debug) makes
// every code point above 127 a space; \u escapes keep their code
#debug concat("cs1 [", "éx", "][", str(strlen("éx"), 0, 0), "][", str(asc(chr(233)), 0, 0), "][", chr(233), "][", str(asc("\u00e9"), 0, 0), "]\n")
global_settings { charset utf8 }
#debug concat("cs2 [", "éx", "][", str(strlen("éx"), 0, 0), "][", str(asc("é"), 0, 0), "][", str(strcmp("é", "e"), 0, 0), "]\n")
sphere { 0, 1 pigment { rgb 1 } }
