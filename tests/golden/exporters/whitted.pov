#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb <0.15, 0.15, 0.15> }
background { color rgb <0.35, 0.55, 0.85> }
camera { perspective location <0, 1.6, -6.5> direction <0, -0.1221552013, 0.9925110109> right <-0.9705872914, 0, -0> up <-0, 0.7224889303, 0.0889217145> }
light_source { <-4, 6, -5> color rgb <0.7, 0.7, 0.7> }
light_source { <5, 5, -2> color rgb <0.5, 0.475, 0.425> }
polygon { 5, <-8, 0, 10>, <8, 0, 10>, <8, 0, -6>, <-8, 0, -6>, <-8, 0, 10> texture { pigment { checker color rgbt <0.95, 0.85, 0.1, 0> color rgbt <0.85, 0.1, 0.1, 0> matrix <1, 0, -0, 0, 0, -1, 0, 6500000, -0, 0, -3250000, -0> } finish { ambient 0.3 diffuse 0.8 phong 0.1 phong_size 20 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
sphere { <-1.3, 1, 1.2>, 1 texture { pigment { color rgbt <0.9, 0.9, 0.9, 0> } finish { ambient 0.05 diffuse 0.1 phong 0.6 phong_size 200 reflection 0.8 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
sphere { <0.55, 0.75, -1>, 0.75 texture { pigment { color rgbt <1, 1, 1, 0.85> } finish { ambient 0 diffuse 0.3333333333 phong 0.7 phong_size 300 reflection 0.1 } } interior { ior 1.5 } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
sphere { <1.9, 0.6, 1>, 0.6 texture { pigment { color rgbt <0.2, 0.45, 0.9, 0> } finish { ambient 0.2 diffuse 0.8 phong 0.5 phong_size 60 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
