// Watertight ray–triangle intersection (Woop, Benthin & Wald, JCGT 2013, as in pbrt-v4): the ray
// is moved to the origin and sheared to run along +z, and each triangle is tested in 2-D by the
// signs of its three edge functions. Two triangles evaluate a shared edge from the same sheared
// vertices in opposite order, which gives exactly the negated value (a - b rounds to -(b - a)),
// so a ray can neither slip between them nor hit only one of two that face it alike; a ray
// exactly on the edge hits both at the same point. Woop et al. recompute zero edge functions in
// double; drt computes in double throughout and accepts zeros, which keeps the test conservative.
#pragma once

#include <cmath>
#include <limits>
#include <optional>

#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

// A point of a triangle as weights of its vertices: p = b0·p0 + b1·p1 + b2·p2, b0 + b1 + b2 = 1.
struct Barycentrics {
    double b0, b1, b2;
};

struct TriangleHit {
    double t;
    Barycentrics b;
};

// The per-ray part of the test, computed once and shared by every triangle the ray meets.
struct ShearedRay {
    explicit ShearedRay(const Ray& ray);

    // The axes alone: kz that of the direction's largest component, kx and ky in the order
    // that keeps every triangle's winding.
    struct Axes {
        int kx, ky, kz;
    };
    static Axes axes_of(const Vec3& d) {
        const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
        const int kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
        const int kx = kz == 2 ? 0 : kz + 1, ky = kx == 2 ? 0 : kx + 1;
        // Looking down a negative axis mirrors the plane; swapping x and y mirrors it back, so
        // that every triangle keeps its winding.
        if (d[kz] < 0) return {ky, kx, kz};
        return {kx, ky, kz};
    }

    Vec3 origin;
    int kx, ky, kz;     // the axis of the direction's largest component is kz
    double sx, sy, sz;  // shear taking the direction to (0, 0, 1)
};

namespace detail {
// γ(n) = n u / (1 - n u), u the unit round-off: a bound on the relative error of n operations
// (Higham 2002, as pbrt uses it).
constexpr double gamma(int n) {
    constexpr double u = std::numeric_limits<double>::epsilon() * 0.5;
    return n * u / (1 - n * u);
}
}  // namespace detail

// Nearest intersection inside `range` with the triangle p0, p1, p2 (either side). A degenerate
// triangle, or a sliver no ray can meet at a well-defined point, is missed; the result is never
// NaN. Hits closer than the rounding error of t itself are missed too, so that a ray leaving the
// triangle does not meet it again. Inline because a BVH runs it for every triangle a ray reaches.
inline std::optional<TriangleHit> intersect_triangle(const ShearedRay& ray, const Vec3& p0,
                                                     const Vec3& p1, const Vec3& p2,
                                                     Interval range) {
    const Vec3 a = p0 - ray.origin, b = p1 - ray.origin, c = p2 - ray.origin;
    const double az = a[ray.kz], bz = b[ray.kz], cz = c[ray.kz];
    const double ax = a[ray.kx] - ray.sx * az, ay = a[ray.ky] - ray.sy * az;
    const double bx = b[ray.kx] - ray.sx * bz, by = b[ray.ky] - ray.sy * bz;
    const double cx = c[ray.kx] - ray.sx * cz, cy = c[ray.ky] - ray.sy * cz;

    // Twice the signed areas of the sub-triangles the ray's foot makes with each edge. Written
    // so that NaN (from an overflow) fails both comparisons below.
    const double e0 = cx * by - cy * bx;
    const double e1 = ax * cy - ay * cx;
    const double e2 = bx * ay - by * ax;
    const bool inside = (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
    if (!inside) return std::nullopt;
    const double det = e0 + e1 + e2;
    if (det == 0) return std::nullopt;

    const double inv_det = 1 / det;
    const double zt0 = ray.sz * az, zt1 = ray.sz * bz, zt2 = ray.sz * cz;
    const double t = (e0 * zt0 + e1 * zt1 + e2 * zt2) * inv_det;
    if (!range.surrounds(t)) return std::nullopt;

    // A conservative bound on the rounding error of t, following the error analysis in
    // Pharr, Jakob & Humphreys, Physically Based Rendering (3rd ed., section 3.9.6): a hit within
    // it of the origin may be the triangle the ray has just left.
    using detail::gamma;
    const double max_z = std::max({std::abs(zt0), std::abs(zt1), std::abs(zt2)});
    const double max_x = std::max({std::abs(ax), std::abs(bx), std::abs(cx)});
    const double max_y = std::max({std::abs(ay), std::abs(by), std::abs(cy)});
    const double max_e = std::max({std::abs(e0), std::abs(e1), std::abs(e2)});
    const double delta_z = gamma(3) * max_z;
    const double delta_x = gamma(5) * (max_x + max_z);
    const double delta_y = gamma(5) * (max_y + max_z);
    const double delta_e = 2 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    const double delta_t =
        3 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * std::abs(inv_det);
    if (t <= delta_t) return std::nullopt;
    return TriangleHit{t, {e0 * inv_det, e1 * inv_det, e2 * inv_det}};
}

inline std::optional<TriangleHit> intersect_triangle(const Ray& ray, const Vec3& p0, const Vec3& p1,
                                                     const Vec3& p2, Interval range) {
    return intersect_triangle(ShearedRay(ray), p0, p1, p2, range);
}

}  // namespace drt
