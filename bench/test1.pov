// POV-Ray 3.7 twin of scenes/thesis/test1.xml, for bench/race.sh: the same room, camera,
// materials and lights, at matched work. Render with
//   povray +Ibench/test1.pov +W800 +H600 +AM1 +A0.0 +R9 +WT2 -D
// +AM1 +A0.0 +R9 supersamples every pixel with a 9 x 9 jittered grid after its centre ray: 82
// camera rays per pixel, against drt --spp 82. Each light is a 3 x 3 jittered, non-adaptive
// area light (9 shadow rays), against drt's ShadowRays 18 shared by two equal lights.
#version 3.7;

global_settings {
  assumed_gamma 1.0
  // MaxDepth 8 bounces after the camera ray; POV-Ray counts the camera ray as level 1.
  max_trace_level 9
  // No adaptive depth control: drt traces every branch to MaxDepth, and so does this.
  adc_bailout 0
  ambient_light rgb 1
}

// The thesis's pixel-plane camera for an 800 x 600 image: eye at (400, 300, -800), the image
// plane z = 0 covering x 0..800 and y 0..600 (POV-Ray is left-handed with y up, like drt).
camera {
  perspective
  location <400, 300, -800>
  direction <0, 0, 800>
  right <800, 0, 0>
  up <0, 600, 0>
}

background { rgb 0 }

// A sphere light of radius 40 seen from a shading point is close to a disc of diameter 80
// facing it: circular + orient.
#macro RoundLight(P)
  light_source {
    P
    color rgb 0.6
    area_light <80, 0, 0>, <0, 0, 80>, 3, 3
    jitter
    circular
    orient
  }
#end
RoundLight(<250, 520, 300>)
RoundLight(<560, 520, 500>)

// drt's Lambert part: diffuse * kd * (ambient 0.02 + lights), no highlight.
#macro Lambert(C)
  texture { pigment { rgb C } finish { ambient 0.02 diffuse 1 specular 0 phong 0 } }
#end

// Floor: BlueLambert under a checker of cells 100 with k2 = 0.9.
plane {
  y, 0
  texture {
    pigment { checker rgb <0.2, 0.3, 0.8> rgb <0.9, 0.9, 0.9> scale 100 }
    finish { ambient 0.02 diffuse 1 specular 0 phong 0 }
  }
}
plane { -y, -600 Lambert(<0.8, 0.8, 0.8>) }   // ceiling
plane { x, 0 Lambert(<0.7, 0.15, 0.1>) }      // left wall, RedLambert
plane { -x, -800 Lambert(<0.8, 0.8, 0.8>) }   // right wall
plane { -z, -800 Lambert(<0.8, 0.8, 0.8>) }   // back wall

sphere { <250, 130, 550>, 130 Lambert(<0.85, 0.7, 0.2>) }

// Glass: transmit 1, kt (0.1, 0.8, 0.8), index 1.6, Fresnel reflection and refraction.
sphere {
  <530, 120, 300>, 120
  texture {
    pigment { rgbf <0.1, 0.8, 0.8, 1> }
    finish { ambient 0 diffuse 0 specular 0 phong 0 reflection { 0, 1 fresnel on } conserve_energy }
  }
  interior { ior 1.6 }
}
