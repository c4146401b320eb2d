// POV-Ray 3.7 twin of scenes/caustics/test1-caustic.xml, for bench/caustic-race.sh: Test1's
// room, the ideal aqua glass sphere and a small light with inverse-square falloff whose caustic
// the sphere throws on the floor, estimated with POV-Ray's photon mapping (its `photons`
// block). Photon count and antialiasing come from the command line (bench/caustic-race.sh):
//   povray +Ibench/test1-caustic.pov +W200 +H150 Declare=Photons=200000 Declare=Dim=0.1 +AM1 +A0.0 +R3 -D
#version 3.7;

#ifndef (Photons) #declare Photons = 200000; #end
// Both lights times Dim (bench/caustic-race.sh renders at 0.1, so that the caustic's peak stays
// below 1 in POV-Ray's 16-bit output, which clips there; drt's scene is dimmed alike).
#ifndef (Dim) #declare Dim = 1; #end

global_settings {
  assumed_gamma 1.0
  max_trace_level 9
  adc_bailout 0
  ambient_light rgb 1
  photons { count Photons autostop 0 jitter 0.4 }
}

camera {
  perspective
  location <400, 300, -800>
  direction <0, 0, 800>
  right <800, 0, 0>
  up <0, 600, 0>
}

background { rgb 0 }

// The thesis light (Falloff 0), intensity 0.4, radius 40: a 3 x 3 jittered disc.
light_source {
  <250, 520, 300>
  color rgb 0.4 * Dim
  area_light <80, 0, 0>, <0, 0, 80>, 3, 3
  jitter circular orient
  photons { refraction off reflection off }
}

// drt's Falloff-1 light of intensity 4e4 and radius 10: POV-Ray's fade gives
// colour · 2 / (1 + d²) with fade_distance 1 and fade_power 2, which is 4e4 / d² for colour 2e4.
light_source {
  <620, 250, 560>
  color rgb 2e4 * Dim
  fade_distance 1 fade_power 2
  area_light <20, 0, 0>, <0, 0, 20>, 3, 3
  jitter circular orient
  photons { refraction on reflection on }
}

#macro Lambert(C)
  texture { pigment { rgb C } finish { ambient 0.02 diffuse 1 specular 0 phong 0 } }
#end

plane {
  y, 0
  texture {
    pigment { checker rgb <0.2, 0.3, 0.8> rgb <0.9, 0.9, 0.9> scale 100 }
    finish { ambient 0.02 diffuse 1 specular 0 phong 0 }
  }
}
plane { -y, -600 Lambert(<0.8, 0.8, 0.8>) }
plane { x, 0 Lambert(<0.7, 0.15, 0.1>) }
plane { -x, -800 Lambert(<0.8, 0.8, 0.8>) }
plane { -z, -800 Lambert(<0.8, 0.8, 0.8>) }

sphere { <250, 130, 550>, 130 Lambert(<0.85, 0.7, 0.2>) }

sphere {
  <530, 120, 300>, 120
  texture {
    pigment { rgbf <0.1, 0.8, 0.8, 1> }
    finish { ambient 0 diffuse 0 specular 0 phong 0 reflection { 0, 1 fresnel on } conserve_energy }
  }
  interior { ior 1.6 }
  photons { target reflection on refraction on collect off }
}
