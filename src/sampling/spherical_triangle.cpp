#include "drt/sampling/spherical_triangle.h"

#include <algorithm>
#include <cmath>

namespace drt {

SphericalTriangle spherical_triangle(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    SphericalTriangle t;
    t.a = normalize(p0);
    t.b = normalize(p1);
    t.c = normalize(p2);
    t.triple = std::abs(dot(t.a, cross(t.b, t.c)));
    const double below = 1 + dot(t.a, t.b) + dot(t.b, t.c) + dot(t.c, t.a);
    // atan2 keeps the quadrant: past a hemisphere's worth of half-angle `below` turns negative.
    t.area = 2 * std::atan2(t.triple, below);
    return t;
}

Vec3 sample_spherical_triangle(const SphericalTriangle& t, Vec2 u) {
    const Vec3& a = t.a;
    const Vec3& b = t.b;
    // The angle α at a is the one between the planes of the arcs a-b and a-c; its sine follows
    // from (a×b)×(a×c) = (a·(b×c))·a, so no inverse cosine is needed, nor α itself: only the
    // sine and cosine of (sub-area − α).
    const Vec3 ab = cross(a, b), ac = cross(a, t.c);
    const double lengths = std::sqrt(dot(ab, ab) * dot(ac, ac));
    const double cos_alpha = std::clamp(dot(ab, ac) / lengths, -1.0, 1.0);
    const double sin_alpha = t.triple / lengths;
    const double sub_area = u.x * t.area;
    const double sin_sub = std::sin(sub_area), cos_sub = std::cos(sub_area);
    const double s = sin_sub * cos_alpha - cos_sub * sin_alpha;  // sin(sub-area − α)
    const double r = cos_sub * cos_alpha + sin_sub * sin_alpha;  // cos(sub-area − α)
    const double p = r - cos_alpha;
    const double q_numerator = s + sin_alpha * dot(a, b);
    // The cosine of the arc from a to the sub-triangle's third corner c', on the arc a-c.
    const double cos_ac = std::clamp(((q_numerator * r - p * s) * cos_alpha - q_numerator) /
                                         ((q_numerator * s + p * r) * sin_alpha),
                                     -1.0, 1.0);
    // c − (c·a)a as (a×c)×a, without the cancellation when c is near a.
    const Vec3 towards_c = normalize(cross(ac, a));
    const Vec3 c_sub = a * cos_ac + towards_c * std::sqrt((1 - cos_ac) * (1 + cos_ac));
    // Uniform in area along the arc from b to c' is uniform in the cosine of the angle from b;
    // 1 − b·c' is taken as |c' − b|²/2, which a short arc keeps exactly.
    const Vec3 chord = c_sub - b;
    const double one_minus_z = u.y * 0.5 * dot(chord, chord);
    const double z = 1 - one_minus_z;
    const Vec3 towards_c_sub = cross(cross(b, c_sub), b);
    const double away = dot(towards_c_sub, towards_c_sub);
    if (!(away > 0)) return b;  // c' is b (or opposite it): the arc is a point
    // towards_c_sub is orthogonal to b, so the sum is a unit vector without normalising.
    return b * z + towards_c_sub * std::sqrt(positive_part(one_minus_z * (2 - one_minus_z)) / away);
}

}  // namespace drt
