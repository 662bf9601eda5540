#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb <0.15, 0.15, 0.15> }
background { color rgb <0.12, 0.12, 0.15> }
camera { perspective location <0.5, 3, 7> direction <-0.06770370531, -0.3114370444, -0.9478518743> right <0.9681207377, -9.1325521e-18, -0.06915148127> up <-0.01615224971, 0.6917376505, -0.2261314959> }
light_source { <-3, 6, 5> color rgb <0.8, 0.8, 0.8> }
light_source { <-42644.53894, 42644.53894, 35537.11578> color rgb <0.35, 0.35, 0.35> parallel point_at <0, 0, 0> }
difference {
  difference {
  difference {
  box { <-0.6, -0.6, -0.6>, <0.6, 0.6, 0.6> texture { pigment { color rgbt <0.92, 0.9, 0.82, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.4 phong_size 60 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  sphere { <0, 0, 0.68>, 0.16 texture { pigment { color rgbt <0.1, 0.1, 0.1, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.3 phong_size 30 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  sphere { <0, 0.68, 0>, 0.16 texture { pigment { color rgbt <0.1, 0.1, 0.1, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.3 phong_size 30 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  sphere { <0.68, 0, 0>, 0.16 texture { pigment { color rgbt <0.1, 0.1, 0.1, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.3 phong_size 30 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  matrix <0.906307787, 0, -0.4226182617, 0, 1, 0, 0.4226182617, 0, 0.906307787, -2, 0.6, 0> }
intersection {
  sphere { <0, 0, -0.7>, 1 texture { pigment { color rgbt <0.3, 0.5, 0.9, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.7 phong_size 120 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  sphere { <0, 0, 0.7>, 1 texture { pigment { color rgbt <0.3, 0.5, 0.9, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.7 phong_size 120 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  matrix <0.5, 0, -0.8660254038, 0, 1, 0, 0.8660254038, 0, 0.5, -0.4, 0.9, 0.8> }
intersection {
  box { <-0.55, -0.55, -0.55>, <0.55, 0.55, 0.55> texture { pigment { color rgbt <0.95, 0.5, 0.15, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.4 phong_size 40 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  sphere { <0, 0, 0>, 0.75 texture { pigment { color rgbt <0.95, 0.5, 0.15, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.4 phong_size 40 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  matrix <0.9396926208, 0, 0.3420201433, 0, 1, 0, -0.3420201433, 0, 0.9396926208, 1, 0.55, -0.6> }
merge {
  intersection { quadric { <8.163265306, 0, 8.163265306>, <0, 0, 0>, <0, 0, 0>, -1 } box { <-0.4, 0, -0.4>, <0.4, 1.2, 0.4> } texture { pigment { color rgbt <0.15, 0.6, 0.6, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.5 phong_size 50 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  sphere { <0, 1.2, 0>, 0.35 texture { pigment { color rgbt <0.15, 0.6, 0.6, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.5 phong_size 50 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
  matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 2.4, 0, 0.6> }
polygon { 5, <-6, 0, 4>, <6, 0, 4>, <6, 0, -4>, <-6, 0, -4>, <-6, 0, 4> texture { pigment { color rgbt <0.6, 0.6, 0.6, 0> } finish { ambient 0.3 diffuse 0.7 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
