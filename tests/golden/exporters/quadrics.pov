#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb <0.15, 0.15, 0.15> }
background { color rgb <0.1, 0.12, 0.16> }
camera { perspective location <0, 3.2, 8> direction <-0, -0.2873478856, -0.9578262852> right <1.023637427, 0, 0> up <0, 0.7353501254, -0.2206050376> }
light_source { <-4, 6, 5> color rgb <0.8, 0.8, 0.8> }
light_source { <-42163.70214, 59029.18299, 33730.96171> color rgb <0.35, 0.35, 0.35> parallel point_at <0, 0, 0> }
quadric { <1.234567901, 2.777777778, 2.777777778>, <0, 0, 0>, <0, 0, 0>, -1 clipped_by { box { <-0.9, -0.6, -0.6>, <0.9, 0.6, 0.6> } } texture { pigment { color rgbt <0.8, 0.2, 0.15, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.5 phong_size 50 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, -2.6, 0.6, 0> }
quadric { <4, 0, 4>, <0, 0, 0>, <0, 0, 0>, -1 clipped_by { box { <-0.6, 0, -0.6>, <0.6, 1.6, 0.6> } } texture { pigment { color rgbt <0.2, 0.7, 0.3, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.5 phong_size 50 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, -1.2, 0, -0.8> }
quadric { <4, -1, 4>, <0, 0, 0>, <0, 0, 0>, 0 clipped_by { box { <-1, -1.6, -1>, <1, 0, 1> } } texture { pigment { color rgbt <0.2, 0.35, 0.85, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.5 phong_size 50 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0.2, 1.6, 0.3> }
quadric { <6.25, -2.040816327, 6.25>, <0, 0, 0>, <0, 0, 0>, -1 clipped_by { box { <-1.2, -0.8, -1.2>, <1.2, 0.8, 1.2> } } texture { pigment { color rgbt <0.85, 0.65, 0.2, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.6 phong_size 80 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 1.5, 0.8, -0.8> }
quadric { <4, 0, 4>, <0, 0, 0>, <0, -1, 0>, 0 clipped_by { box { <-1, 0, -1>, <1, 1.2, 1> } } texture { pigment { color rgbt <0.6, 0.3, 0.75, 0> } finish { ambient 0.1 diffuse 0.8 phong 0.5 phong_size 50 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 2.8, 0, 0.6> }
polygon { 5, <-6, 0, 4>, <6, 0, 4>, <6, 0, -4>, <-6, 0, -4>, <-6, 0, 4> texture { pigment { color rgbt <0.7, 0.7, 0.7, 0> } finish { ambient 0.3 diffuse 0.7 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
