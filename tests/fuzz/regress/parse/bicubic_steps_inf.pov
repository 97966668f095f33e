// fuzz_parse finding: u_steps 1e999 (inf) was cast to int (UBSan float-cast-overflow).
bicubic_patch { type 1 u_steps 1e999 v_steps -1e999
  <0,0,0>, <1,0,0>, <2,0,0>, <3,0,0>, <0,1,0>, <1,1,1>, <2,1,1>, <3,1,0>,
  <0,2,0>, <1,2,1>, <2,2,1>, <3,2,0>, <0,3,0>, <1,3,0>, <2,3,0>, <3,3,0> }
