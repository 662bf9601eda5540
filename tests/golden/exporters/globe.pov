#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb <0.15, 0.15, 0.18> }
background { color rgb <0.02, 0.02, 0.05> }
camera { perspective location <0, 1.2, 5.5> direction <-0, -0.1084475102, -0.9941021766> right <0.9705872914, 0, 0> up <0, 0.7236472042, -0.07894333137> }
light_source { <32795.66367, 16397.83183, 40994.57959> color rgb <0.9, 0.9, 0.9> parallel point_at <0, 0, 0> }
light_source { <3, 4, 3> color rgb <0.3, 0.285, 0.27> }
sphere { <0, 0, 0>, 1 texture { pigment { color rgbt <1, 1, 1, 0> } finish { ambient 0.3 diffuse 0.9 phong 0.25 phong_size 40 } } matrix <0.7947988203, 0.3439401623, -0.5, -0.3971478906, 0.9177546257, 0, 0.4588773128, 0.1985739453, 0.8660254038, -0.7, 1, 0> }
quadric { <4.938271605, 0, 4.938271605>, <0, 0, 0>, <0, 0, 0>, -1 clipped_by { box { <-0.5, 0, -0.5>, <0.5, 1.2, 0.5> } } texture { pigment { color rgbt <1, 1, 1, 0> } finish { ambient 0.3 diffuse 0.8 phong 0.4 phong_size 60 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 1.3, 0, 0.4> }
polygon { 5, <-6, 0, 6>, <6, 0, 6>, <6, 0, -6>, <-6, 0, -6>, <-6, 0, 6> texture { pigment { checker color rgbt <0.6, 0.6, 0.6, 0> color rgbt <0.25, 0.25, 0.25, 0> matrix <1, 0, -0, 0, 0, -1, 0, 5500000, -0, 0, -2750000, -0> } finish { ambient 0.3 diffuse 0.7 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
