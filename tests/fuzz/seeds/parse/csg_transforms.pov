#declare T = transform { rotate <10, 20, 30> scale 2 translate x };
#declare O = intersection { sphere { 0, 1 } box { -0.5, 0.5 inverse } };
object { O transform { T inverse } pigment { rgb 1 } }
merge { object { O } object { O translate y } matrix <1,0,0, 0,1,0, 0,0,1, 0,0,0> }
quadric { <1, 1, 1>, <0, 0, 0>, <0, 0, 0>, -1 }
light_source { 0, 1 parallel point_at -y shadowless }
camera { orthographic location -z*5 look_at 0 up y right x sky y }
