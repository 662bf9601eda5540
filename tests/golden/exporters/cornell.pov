#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 adc_bailout 0.001 ambient_light rgb <0, 0, 0> }
background { color rgb <0, 0, 0> }
camera { perspective location <278, 273, -800> direction <0, -0, 1> right <-0.952380952, 0, -0> up <-0, 0.714285714, -0> }
light_source { <321.3333333, 548, 244.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
light_source { <278, 548, 244.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
light_source { <234.6666667, 548, 244.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
light_source { <321.3333333, 548, 279.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
light_source { <278, 548, 279.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
light_source { <234.6666667, 548, 279.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
light_source { <321.3333333, 548, 314.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
light_source { <278, 548, 314.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
light_source { <234.6666667, 548, 314.5> color rgb <790959.4205, 412664.5871, 105383.9374> fade_distance 0.08 fade_power 2 }
polygon { 5, <343, 548, 227>, <343, 548, 332>, <213, 548, 332>, <213, 548, 227>, <343, 548, 227> pigment { color rgb <1, 1, 1> } finish { ambient 0 diffuse 0 emission rgb <20.97123, 10.941249, 2.794114> } no_shadow }
polygon { 5, <552.8, 0, 0>, <0, 0, 0>, <0, 0, 559.2>, <549.6, 0, 559.2>, <552.8, 0, 0> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <556, 548.8, 0>, <556, 548.8, 559.2>, <0, 548.8, 559.2>, <0, 548.8, 0>, <556, 548.8, 0> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <549.6, 0, 559.2>, <0, 0, 559.2>, <0, 548.8, 559.2>, <556, 548.8, 559.2>, <549.6, 0, 559.2> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <0, 0, 559.2>, <0, 0, 0>, <0, 548.8, 0>, <0, 548.8, 559.2>, <0, 0, 559.2> texture { pigment { color rgbt <0.118688, 0.383065, 0.023686, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <552.8, 0, 0>, <549.6, 0, 559.2>, <556, 548.8, 559.2>, <556, 548.8, 0>, <552.8, 0, 0> texture { pigment { color rgbt <0.451356, 0.035616, 0.011564, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <130, 165, 65>, <82, 165, 225>, <240, 165, 272>, <290, 165, 114>, <130, 165, 65> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <290, 0, 114>, <290, 165, 114>, <240, 165, 272>, <240, 0, 272>, <290, 0, 114> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <130, 0, 65>, <130, 165, 65>, <290, 165, 114>, <290, 0, 114>, <130, 0, 65> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <82, 0, 225>, <82, 165, 225>, <130, 165, 65>, <130, 0, 65>, <82, 0, 225> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <240, 0, 272>, <240, 165, 272>, <82, 165, 225>, <82, 0, 225>, <240, 0, 272> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <423, 330, 247>, <265, 330, 296>, <314, 330, 456>, <472, 330, 406>, <423, 330, 247> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <423, 0, 247>, <423, 330, 247>, <472, 330, 406>, <472, 0, 406>, <423, 0, 247> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <472, 0, 406>, <472, 330, 406>, <314, 330, 456>, <314, 0, 456>, <472, 0, 406> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <314, 0, 456>, <314, 330, 456>, <265, 330, 296>, <265, 0, 296>, <314, 0, 456> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
polygon { 5, <265, 0, 296>, <265, 330, 296>, <423, 330, 247>, <423, 0, 247>, <265, 0, 296> texture { pigment { color rgbt <0.738615, 0.735408, 0.7506, 0> } finish { ambient 0 diffuse 1 } } matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0> }
