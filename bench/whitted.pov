// POV-Ray 3.7 equivalent of scenes/whitted.toml (benchmark: bench/povray_whitted.py).
// Same camera, lights (no falloff), materials and geometry.  POV-Ray is left-handed; the
// negative `right` vector makes it right-handed like the workbench, so coordinates are copied
// unchanged.  `angle` is the horizontal field of view: 2 atan(tan(40/2 deg) * 640/480).
#version 3.7;
global_settings {
  assumed_gamma 1.0
  max_trace_level 5
  adc_bailout 1/255
  ambient_light rgb <0.15, 0.15, 0.15>
}
background { color rgb <0.35, 0.55, 0.85> }
camera {
  perspective
  location <0.0, 1.6, -6.5>
  up y
  right -x * image_width / image_height
  angle 51.77400875924256
  look_at <0.0, 0.8, 0.0>
}
light_source { <-4.0, 6.0, -5.0> color rgb <1.0, 1.0, 1.0> * 0.7 }
light_source { <5.0, 5.0, -2.0> color rgb <1.0, 0.95, 0.85> * 0.5 }

// floor: 16 x 16 rectangle centred at (0, 0, 2), checker of period 1
polygon {
  5, <-8.0, 0.0, -6.0>, <8.0, 0.0, -6.0>, <8.0, 0.0, 10.0>, <-8.0, 0.0, 10.0>, <-8.0, 0.0, -6.0>
  pigment { checker color rgb <0.95, 0.85, 0.1> color rgb <0.85, 0.1, 0.1> }
  finish { ambient 0.3 diffuse 0.8 phong 0.1 phong_size 20 }
}
sphere {
  <-1.3, 1.0, 1.2>, 1.0
  pigment { color rgb <0.9, 0.9, 0.9> }
  finish { ambient 0.05 diffuse 0.1 phong 0.6 phong_size 200 reflection 0.8 }
}
sphere {
  <0.55, 0.75, -1.0>, 0.75
  pigment { color rgbt <1.0, 1.0, 1.0, 0.85> }
  finish { ambient 0.0 diffuse 0.05 phong 0.7 phong_size 300 reflection 0.1 }
  interior { ior 1.5 }
}
sphere {
  <1.9, 0.6, 1.0>, 0.6
  pigment { color rgb <0.2, 0.45, 0.9> }
  finish { ambient 0.2 diffuse 0.8 phong 0.5 phong_size 60 }
}
