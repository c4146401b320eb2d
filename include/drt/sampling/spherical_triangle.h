// Directions uniformly distributed over the solid angle a triangle subtends from a point: the
// spherical triangle its corners project to on the unit sphere about that point, sampled by
// Arvo's mapping ("Stratified sampling of spherical triangles", SIGGRAPH 1995), which carries
// the unit square onto it continuously, so that a stratified point set stays stratified.
#pragma once

#include "drt/util/math.h"

namespace drt {

// The spherical triangle with unit corners a, b, c as seen from its sphere's centre.
struct SphericalTriangle {
    Vec3 a, b, c;
    double triple;  // |a · (b × c)|
    double area;    // its solid angle in steradians, in [0, 2π]
};

// The spherical triangle of the corners p0, p1, p2 given relative to the viewpoint (none may be
// at it). Its area is Van Oosterom and Strackee's tan(Ω/2) = |a·(b×c)| / (1 + a·b + b·c + c·a),
// which keeps its digits for a small triangle where α + β + γ − π would cancel.
SphericalTriangle spherical_triangle(const Vec3& p0, const Vec3& p1, const Vec3& p2);

// The direction for u in the unit square: u.x chooses the sub-triangle of area u.x·area that
// ends at a point on the arc from a to c, u.y the point on the arc from b to it, both uniform in
// area. Numerically sound for areas away from 0 and 2π (the caller decides where to stop, see
// emitters.cpp): at 0 the angle at a, at 2π its sine, is lost to rounding.
Vec3 sample_spherical_triangle(const SphericalTriangle& t, Vec2 u);

}  // namespace drt
