// Four triangles tested against one ray at once, in single precision, as a filter in front of
// the double-precision watertight test of triangle.h (the way Woop, Benthin & Wald 2013 fall
// back to double near an edge, and Embree tests four triangles at a time).
//
// The filter computes the same sheared edge functions and the same t as intersect_triangle,
// but in float, with a bound on how far each float value can be from the one the double test
// gets. A triangle is ruled out only where the bounds prove the double test would miss it: two
// edge functions of certainly opposite signs, or a t certainly outside the range. Everything
// else (a ray within rounding of an edge or a vertex, of the range's ends, or a float overflow,
// whose NaN fails every comparison that would rule a triangle out) goes on to the double test,
// which decides. So the hits, their t and their barycentrics are bit for bit those of
// testing every triangle in double, and the mesh stays watertight. The same bounds read the
// other way prove a hit (edge functions certainly of one sign, t certainly inside the range and
// past the double test's own error bound for t): an any-hit query can answer from that alone.
//
// The bounds, with u = 2^-24 the unit round-off of float, and per triangle X, Y, Z the largest
// |sheared x|, |sheared y| and |z| of its corners relative to the ray's origin:
// - origin rounded to float: off by at most `err` on each axis; a corner relative to it by
//   err + u·|coordinate|, at most err + u·(max(X, Y) + Z) since |unsheared x| ≤ X + Z;
// - sheared coordinate x - sx·z (|sx| ≤ 1, sx rounded to float): off by δ = 2·err +
//   6u·(max(X, Y) + Z), which covers the two corner errors, sx's rounding, the product's and
//   the difference's;
// - edge function cx·by - cy·bx: off by E = 2δ·(X + Y + δ) + 5u·X·Y (each product's factors
//   off by δ, then three roundings of magnitude ≤ 2XY);
// - det = e0 + e1 + e2: off by 3E + 3u·Σ|e|; T = e0·az + e1·bz + e2·cz: off by
//   δ·(Σ|e| + 3E) + 3E·Z + 5u·Σ|e|·Z; t·|det| = sz·T·sign(det): off by |sz|·δT + 2u·|sz·T|.
// Each bound is taken 1 % larger (and 2^-100 larger, for underflow), which covers its own
// rounding in float and the double test's own rounding (2^-29 of the float one).
#pragma once

#include <immintrin.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "drt/geometry/triangle.h"
#include "drt/util/ray.h"

namespace drt {

// Four triangles' corners: corners[v][a] holds corner v's coordinate along the ray's axis a
// (FloatShearedRay::axis) for each triangle, in the mesh's own coordinates.
struct TriangleBatch {
    __m128 corners[3][3];
};

// The per-ray part of the filter: the ShearedRay's axes, origin and shear in float.
class FloatShearedRay {
  public:
    explicit FloatShearedRay(const ShearedRay& ray)
        : FloatShearedRay(ray.origin, {ray.kx, ray.ky, ray.kz}, ray.sx, ray.sy, ray.sz) {}
    // From the ray's origin, axes and shear, where the shear may also be off from the
    // ShearedRay's by a few units of double rounding (d[kx] · (1 / d[kz]) for d[kx] / d[kz]):
    // the bounds' 1 % margin covers that.
    FloatShearedRay(const Vec3& origin, ShearedRay::Axes axes, double sx, double sy, double sz)
        : kx_(axes.kx), ky_(axes.ky), kz_(axes.kz) {
        const std::array<double, 3> o{origin[kx_], origin[ky_], origin[kz_]};
        double err = 0;
        for (int k = 0; k < 3; ++k) {
            const auto f = static_cast<float>(o[k]);
            origin_[k] = _mm_set1_ps(f);
            err = std::max(err, std::abs(o[k] - f));
            // Beyond this, products of coordinates could overflow before their bounds do.
            if (!(std::abs(f) <= kLargest)) usable_ = false;
        }
        // (|sx|, |sy| ≤ 1 exactly; a product in place of the quotient may round just past 1.)
        const auto fx = std::clamp(static_cast<float>(sx), -1.0f, 1.0f),
                   fy = std::clamp(static_cast<float>(sy), -1.0f, 1.0f),
                   fz = static_cast<float>(sz);
        if (!std::isfinite(fz) || fz == 0 || !(std::abs(fx) <= 1) || !(std::abs(fy) <= 1))
            usable_ = false;
        sx_ = _mm_set1_ps(fx);
        sy_ = _mm_set1_ps(fy);
        sz_ = _mm_set1_ps(fz);
        // (Rounded up: err is exact in double, and at most 2^-24 of the origin.)
        twice_err_ = _mm_set1_ps(static_cast<float>(2 * err) * (1 + 0x1p-20f));
    }

    // Whether the filter can be trusted for this ray: false for an origin or direction beyond
    // what its float bounds cover, and then every triangle goes to the double test.
    bool usable() const { return usable_; }
    // Corner coordinates are taken in the ray's order: sheared x, sheared y, then z.
    int axis(int k) const { return k == 0 ? kx_ : (k == 1 ? ky_ : kz_); }

    // Bit k set unless triangle k certainly misses inside [near, far] (near ≥ 0 or -∞; far may
    // be +∞). The corners' magnitudes must not exceed kLargest.
    int maybe_hits(const TriangleBatch& batch, float near, float far) const {
        return test<false>(batch, near, far, 0, 0).maybe;
    }

    // maybe_hits, and beside it `certain`: bit k set only where the double test certainly hits
    // triangle k inside a range that [low, high] lies within (low ≥ the range's start, high ≤
    // its end; low may be 0 for a range that starts at or below 0). A query that asks only
    // whether anything is hit can answer from it alone.
    struct Verdict {
        int maybe, certain;
    };
    Verdict classify(const TriangleBatch& batch, float near, float far, float low,
                     float high) const {
        return test<true>(batch, near, far, low, high);
    }

    // Coordinates of larger magnitude, in the mesh or in the ray's origin, turn the filter off.
    static constexpr float kLargest = 1e15f;

  private:
    template <bool kCertain>
    Verdict test(const TriangleBatch& batch, float near, float far, float low, float high) const {
        const auto& corners = batch.corners;
        const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
        const auto abs = [&](__m128 v) { return _mm_and_ps(v, abs_mask); };
        const auto max3 = [](__m128 a, __m128 b, __m128 c) {
            return _mm_max_ps(a, _mm_max_ps(b, c));
        };
        __m128 x[3], y[3], z[3];
        for (int v = 0; v < 3; ++v) {
            z[v] = _mm_sub_ps(corners[v][2], origin_[2]);
            x[v] = _mm_sub_ps(_mm_sub_ps(corners[v][0], origin_[0]), _mm_mul_ps(sx_, z[v]));
            y[v] = _mm_sub_ps(_mm_sub_ps(corners[v][1], origin_[1]), _mm_mul_ps(sy_, z[v]));
        }
        const __m128 e0 = _mm_sub_ps(_mm_mul_ps(x[2], y[1]), _mm_mul_ps(y[2], x[1]));
        const __m128 e1 = _mm_sub_ps(_mm_mul_ps(x[0], y[2]), _mm_mul_ps(y[0], x[2]));
        const __m128 e2 = _mm_sub_ps(_mm_mul_ps(x[1], y[0]), _mm_mul_ps(y[1], x[0]));

        const __m128 u = _mm_set1_ps(0x1p-24f);
        const __m128 margin = _mm_set1_ps(1.01f), tiny = _mm_set1_ps(0x1p-100f);
        const auto widened = [&](__m128 bound) {
            return _mm_add_ps(_mm_mul_ps(bound, margin), tiny);
        };
        const __m128 big_x = max3(abs(x[0]), abs(x[1]), abs(x[2]));
        const __m128 big_y = max3(abs(y[0]), abs(y[1]), abs(y[2]));
        const __m128 big_z = max3(abs(z[0]), abs(z[1]), abs(z[2]));
        const __m128 delta = widened(
            _mm_add_ps(twice_err_, _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(6), u),
                                              _mm_add_ps(_mm_max_ps(big_x, big_y), big_z))));
        const __m128 xy = _mm_mul_ps(big_x, big_y);
        const __m128 edge_err = widened(_mm_add_ps(
            _mm_mul_ps(_mm_add_ps(delta, delta), _mm_add_ps(_mm_add_ps(big_x, big_y), delta)),
            _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(5), u), xy)));

        // Two edge functions of certainly opposite signs: the ray passes outside.
        const __m128 minus_err = _mm_sub_ps(_mm_setzero_ps(), edge_err);
        const __m128 negative =
            _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(e0, minus_err), _mm_cmplt_ps(e1, minus_err)),
                      _mm_cmplt_ps(e2, minus_err));
        const __m128 positive =
            _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(e0, edge_err), _mm_cmpgt_ps(e1, edge_err)),
                      _mm_cmpgt_ps(e2, edge_err));
        const __m128 outside = _mm_and_ps(negative, positive);

        // t = sz·T / det, compared as t·|det| against the ends of the range times |det|.
        const __m128 sum_e = _mm_add_ps(_mm_add_ps(abs(e0), abs(e1)), abs(e2));
        const __m128 det = _mm_add_ps(_mm_add_ps(e0, e1), e2);
        const __m128 det_err =
            widened(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(3), edge_err),
                               _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(3), u), sum_e)));
        const __m128 t_sum = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e0, z[0]), _mm_mul_ps(e1, z[1])),
                                        _mm_mul_ps(e2, z[2]));
        const __m128 three_edge_err = _mm_mul_ps(_mm_set1_ps(3), edge_err);
        // (Σ|e|·Z first: where T could overflow, so does its bound, and the NaN rules nothing out.)
        const __m128 t_sum_err = widened(
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(delta, _mm_add_ps(sum_e, three_edge_err)),
                                  _mm_mul_ps(three_edge_err, big_z)),
                       _mm_mul_ps(_mm_mul_ps(sum_e, big_z), _mm_mul_ps(_mm_set1_ps(5), u))));
        const __m128 sign_of_det = _mm_and_ps(det, _mm_castsi128_ps(_mm_set1_epi32(INT32_MIN)));
        const __m128 scaled = _mm_xor_ps(_mm_mul_ps(sz_, t_sum), sign_of_det);  // t·|det|
        const __m128 scaled_err = widened(
            _mm_add_ps(_mm_mul_ps(abs(sz_), t_sum_err), _mm_mul_ps(_mm_add_ps(u, u), abs(scaled))));
        const __m128 det_lo = _mm_sub_ps(abs(det), det_err);
        const __m128 det_hi = _mm_mul_ps(_mm_add_ps(abs(det), det_err), _mm_set1_ps(1 + 0x1p-20f));
        const __m128 round_down = _mm_set1_ps(1 - 0x1p-20f);
        // t ≥ far: the double test wants t < far. The sign of det must be certain.
        const __m128 beyond =
            _mm_and_ps(_mm_cmpgt_ps(det_lo, _mm_setzero_ps()),
                       _mm_cmpge_ps(_mm_mul_ps(_mm_sub_ps(scaled, scaled_err), round_down),
                                    _mm_mul_ps(_mm_set1_ps(far), det_hi)));
        // t ≤ near: the double test wants t > near.
        const __m128 behind = _mm_and_ps(
            _mm_cmpgt_ps(det_lo, _mm_setzero_ps()),
            _mm_cmple_ps(_mm_mul_ps(_mm_add_ps(scaled, scaled_err), _mm_set1_ps(1 + 0x1p-20f)),
                         _mm_mul_ps(_mm_set1_ps(near), _mm_mul_ps(det_lo, round_down))));
        const int maybe = ~_mm_movemask_ps(_mm_or_ps(outside, _mm_or_ps(beyond, behind))) & 0xf;
        if constexpr (!kCertain) {
            return {maybe, 0};
        } else {
            // The mirror image of the tests above: all three edge functions certainly of one
            // sign (so det is not 0 either), t certainly above `low` and below `high`.
            const __m128 one_sign = _mm_or_ps(
                _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(e0, edge_err), _mm_cmpgt_ps(e1, edge_err)),
                           _mm_cmpgt_ps(e2, edge_err)),
                _mm_and_ps(_mm_and_ps(_mm_cmplt_ps(e0, minus_err), _mm_cmplt_ps(e1, minus_err)),
                           _mm_cmplt_ps(e2, minus_err)));
            const __m128 t_det_lo = _mm_mul_ps(_mm_sub_ps(scaled, scaled_err), round_down);
            const __m128 above_low = _mm_cmpgt_ps(t_det_lo, _mm_mul_ps(_mm_set1_ps(low), det_hi));
            const __m128 below_high =
                _mm_cmplt_ps(_mm_mul_ps(_mm_add_ps(scaled, scaled_err), _mm_set1_ps(1 + 0x1p-20f)),
                             _mm_mul_ps(_mm_set1_ps(high), _mm_mul_ps(det_lo, round_down)));
            // The double test also misses a hit no farther than the rounding error of its own t,
            // delta_t = 3·(γ3·Me·Mz + δe·Mz + γ3·Mz·Me)·|1 / det| (triangle.h), with Mx, My, Mz
            // and Me the largest |sheared x|, |y|, |sz·z| and |edge function| in double and
            // δe = 2·(γ2·Mx·My + γ5·(My + Mz)·Mx + γ5·(Mx + Mz)·My). With every γ below 2^-50,
            // delta_t·|det| ≤ 6·2^-50·Mz·(Me + 3·Mx·My + Mz·(Mx + My)); the bound B below is
            // 2^-45·Mz·(...), over 5 times that, which covers the float rounding here and the
            // double test's, with each double value bounded by its float one plus its error
            // bound. Where |det| is known to within a quarter, det_hi < 2·det_lo, and
            // t·|det| > 4·B proves t > delta_t (and t > 0, so a range starting below 0 is met).
            const __m128 mx = _mm_add_ps(big_x, delta), my = _mm_add_ps(big_y, delta);
            const __m128 mz = _mm_mul_ps(_mm_mul_ps(abs(sz_), _mm_add_ps(big_z, delta)),
                                         _mm_set1_ps(1 + 0x1p-20f));
            const __m128 me = _mm_add_ps(max3(abs(e0), abs(e1), abs(e2)), edge_err);
            const __m128 t_err_bound = _mm_mul_ps(
                _mm_mul_ps(_mm_set1_ps(4 * 0x1p-45f), mz),
                _mm_add_ps(_mm_add_ps(me, _mm_mul_ps(_mm_set1_ps(3), _mm_mul_ps(mx, my))),
                           _mm_mul_ps(mz, _mm_add_ps(mx, my))));
            const __m128 det_known = _mm_cmplt_ps(_mm_mul_ps(_mm_set1_ps(4), det_err), abs(det));
            const __m128 past_own_error = _mm_cmpgt_ps(t_det_lo, t_err_bound);
            const __m128 certain =
                _mm_and_ps(_mm_and_ps(one_sign, det_known),
                           _mm_and_ps(_mm_and_ps(above_low, below_high), past_own_error));
            return {maybe, _mm_movemask_ps(certain)};
        }
    }

    int kx_, ky_, kz_;
    bool usable_ = true;
    __m128 origin_[3];
    __m128 sx_, sy_, sz_, twice_err_;
};

}  // namespace drt
