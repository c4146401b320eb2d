// How a ray traverses a TriangleMesh's tree (mesh_tree.h): the 8-wide box test, and a leaf's
// triangles four at a time through a float filter, then the watertight double test, which alone
// decides. Members of TriangleMesh, so that a query reaches tree and triangles through one
// pointer, as its inner loop wants.
#include "drt/accel/triangle_mesh.h"

#include <immintrin.h>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "drt/geometry/triangle_batch.h"
#include "drt/util/float_rounding.h"

namespace drt {

namespace {

// A ray as the wide box test takes it: in single precision, and still conservative, so that a
// box never misses a ray its triangle meets (the triangle test, in double, decides). Each slab
// distance is (plane − o)·(1/d) in float, with the origin o moved to a float on the side that
// can only make the ray enter sooner and leave later: for the near plane above o where 1/d ≥ 0
// (below where it is negative), for the far plane the other way. What is left is relative
// rounding (the subtraction, the product and 1/d rounded to float: (1 + u)³ on each distance),
// covered by widening the far end as for doubles (Pharr, Jakob & Humphreys, section 6.8.2 of
// the 4th edition), and the near planes need no min or max: which side is near is known per ray.
// An axis the ray does not move along (or so little that 1 / d overflows a float) is tested by
// where the origin is instead, since ±∞ · 0 would be NaN.
struct WideRay {
    float inv_dir[3];
    float start[3], end[3];    // the origin rounded for the near and for the far planes
    int near_side[3];          // 0: the near plane of axis k is the box's low side, 1: its high
    float below[3], above[3];  // a flat axis's origin, widened down and up
    int flat = 0;              // bit k: axis k is flat

    // `inv`: 1 / ray.dir, per axis.
    WideRay(const Ray& ray, Interval range, const double (&inv)[4]) {
        // The origin rounded to float, then moved out by at least one float step either way
        // (|f|·2^-23 is no less than the spacing of floats at f, and the smallest float covers
        // zero and the subnormals), without a branch: up ≥ origin ≥ down. An origin beyond the
        // floats makes one of them NaN (∞ − ∞), which the max and min of `hits` ignore.
        const __m128 f = _mm_movelh_ps(_mm_cvtpd_ps(_mm_setr_pd(ray.origin.x, ray.origin.y)),
                                       _mm_cvtpd_ps(_mm_set_sd(ray.origin.z)));
        const __m128 step =
            _mm_add_ps(_mm_mul_ps(_mm_and_ps(f, _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff))),
                                  _mm_set1_ps(0x1p-23f)),
                       _mm_set1_ps(std::numeric_limits<float>::denorm_min()));
        alignas(16) float up[4], down[4], inv_f[4];
        _mm_store_ps(up, _mm_add_ps(f, step));
        _mm_store_ps(down, _mm_sub_ps(f, step));
        _mm_store_ps(inv_f, _mm_movelh_ps(_mm_cvtpd_ps(_mm_load_pd(inv)),
                                          _mm_cvtpd_ps(_mm_load_sd(inv + 2))));
        for (int k = 0; k < 3; ++k) {
            near_side[k] = inv[k] < 0;
            inv_dir[k] = inv_f[k];
            start[k] = near_side[k] ? down[k] : up[k];
            end[k] = near_side[k] ? up[k] : down[k];
            if (!(std::abs(inv[k]) <= std::numeric_limits<float>::max())) make_flat(ray, range, k);
        }
    }

    void make_flat(const Ray& ray, Interval range, int k) {
        // No hit on a mesh of float coordinates is farther than this.
        const double reach = std::min(range.max, 1e39 + 2 * max_abs_component(ray.origin));
        const double o = ray.origin[k];
        flat |= 1 << k;
        const double drift = 2 * std::abs(o - static_cast<float>(o)) + std::abs(ray.dir[k]) * reach;
        below[k] = to_float_down(o - drift);
        above[k] = to_float_up(o + drift);
        inv_dir[k] = start[k] = end[k] = 0;
    }

    // The children whose boxes the ray meets inside [near, far] (bit k for child k), and where
    // it enters each. kFlat: whether any axis may be flat (a rare ray, tested apart so that the
    // common one runs without branches). The 8-wide test with AVX, else two 4-wide ones: the
    // same operations lane by lane, so every build visits the same boxes in the same order.
    template <bool kFlat>
    int hits(const float (&box)[2][3][MeshTree::kWidth], float near, float far,
             float (&entry)[8]) const {
#ifdef __AVX__
        __m256 enter = _mm256_set1_ps(near), leave = _mm256_set1_ps(far);
        __m256 inside = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
        for (int k = 0; k < 3; ++k) {
            if (kFlat && (flat >> k & 1)) {
                const __m256 l = _mm256_load_ps(box[0][k]), h = _mm256_load_ps(box[1][k]);
                inside = _mm256_and_ps(
                    inside, _mm256_and_ps(_mm256_cmp_ps(l, _mm256_set1_ps(above[k]), _CMP_LE_OQ),
                                          _mm256_cmp_ps(h, _mm256_set1_ps(below[k]), _CMP_GE_OQ)));
                continue;
            }
            const __m256 inv = _mm256_set1_ps(inv_dir[k]);
            const __m256 t0 = _mm256_mul_ps(
                _mm256_sub_ps(_mm256_load_ps(box[near_side[k]][k]), _mm256_set1_ps(start[k])), inv);
            const __m256 t1 = _mm256_mul_ps(
                _mm256_sub_ps(_mm256_load_ps(box[1 - near_side[k]][k]), _mm256_set1_ps(end[k])),
                inv);
            enter = _mm256_max_ps(t0, enter);
            leave = _mm256_min_ps(t1, leave);
        }
        _mm256_store_ps(entry, enter);
        return _mm256_movemask_ps(_mm256_and_ps(
            inside,
            _mm256_cmp_ps(enter, _mm256_mul_ps(leave, _mm256_set1_ps(kWiden)), _CMP_LE_OQ)));
#else
        int mask = 0;
        for (int half = 0; half < 8; half += 4) {
            __m128 enter = _mm_set1_ps(near), leave = _mm_set1_ps(far);
            __m128 inside = _mm_castsi128_ps(_mm_set1_epi32(-1));
            for (int k = 0; k < 3; ++k) {
                if (kFlat && (flat >> k & 1)) {
                    const __m128 l = _mm_load_ps(box[0][k] + half),
                                 h = _mm_load_ps(box[1][k] + half);
                    inside = _mm_and_ps(inside, _mm_and_ps(_mm_cmple_ps(l, _mm_set1_ps(above[k])),
                                                           _mm_cmpge_ps(h, _mm_set1_ps(below[k]))));
                    continue;
                }
                const __m128 inv = _mm_set1_ps(inv_dir[k]);
                const __m128 t0 = _mm_mul_ps(
                    _mm_sub_ps(_mm_load_ps(box[near_side[k]][k] + half), _mm_set1_ps(start[k])),
                    inv);
                const __m128 t1 = _mm_mul_ps(
                    _mm_sub_ps(_mm_load_ps(box[1 - near_side[k]][k] + half), _mm_set1_ps(end[k])),
                    inv);
                enter = _mm_max_ps(t0, enter);
                leave = _mm_min_ps(t1, leave);
            }
            _mm_store_ps(entry + half, enter);
            mask |= _mm_movemask_ps(_mm_and_ps(
                        inside, _mm_cmple_ps(enter, _mm_mul_ps(leave, _mm_set1_ps(kWiden)))))
                    << half;
        }
        return mask;
#endif
    }

    // The relative rounding of the slab distances ((1 + u)³ on each end, u = 2^-24) and of
    // this product, with room to spare.
    static constexpr float kWiden = 1 + 0x1p-19f;
};

// A node pushes at most seven children besides the one it visits next, and no path is longer
// than 64 nodes.
constexpr int kStackSize = 7 * 64 + 1;

}  // namespace

template <bool kAnyHit, bool kAlpha>
TriangleMesh::Answer<kAnyHit> TriangleMesh::traverse(const Ray& ray, Interval range,
                                                     std::uint32_t leaving,
                                                     std::uint64_t* tests) const {
    if (tree_.empty()) return {};
    // The per-ray set-up is a good part of a ray's cost: the double-precision sheared ray of the
    // watertight test (two more divisions) is made only once a triangle passes the float
    // filter; the filter's shear is the same to within what its bounds allow for.
    alignas(16) double inv[4];
    _mm_store_pd(inv, _mm_div_pd(_mm_set1_pd(1), _mm_setr_pd(ray.dir.x, ray.dir.y)));
    inv[2] = 1 / ray.dir.z;
    // A mesh of one leaf (up to eight triangles) has a root whose one box is the mesh's, which
    // the scene's BVH has mostly tested already: its triangles are tested at once, without the
    // wide ray. The box test only saves triangle tests, so no answer changes.
    const MeshTree::Node& root = tree_.node(0);
    const bool one_leaf = root.children == 1 && root.count[0] > 0;
    std::optional<WideRay> wide;
    if (!one_leaf) wide.emplace(ray, range, inv);
    const ShearedRay::Axes axes = ShearedRay::axes_of(ray.dir);
    const FloatShearedRay filter(ray.origin, axes, ray.dir[axes.kx] * inv[axes.kz],
                                 ray.dir[axes.ky] * inv[axes.kz], inv[axes.kz]);
    std::optional<ShearedRay> sheared;
    const bool use_filter = filter.usable() && tree_.filter_fits();
    const std::array<int, 3> order_of_axes{axes.kx, axes.ky, axes.kz};
    // The filter's near end must not be negative (triangle_batch.h); a negative range start
    // (never used by the renderer) leaves the near end to the double test.
    const float filter_near =
        range.min >= 0 ? to_float_down(range.min) : -std::numeric_limits<float>::infinity();
    // The corners of triangles first .. first + lanes - 1 in the filter's axis order; lanes past
    // the leaf's end hold other triangles and are masked off. From a small mesh's corner arrays,
    // else gathered through the index buffer (lanes past the end repeat the leaf's last).
    const auto load = [&](std::uint32_t first, std::uint32_t lanes) {
        TriangleBatch batch;
        if (!corners_.empty()) {
            for (int v = 0; v < 3; ++v) {
                for (int a = 0; a < 3; ++a) {
                    batch.corners[v][a] = _mm_loadu_ps(
                        &corners_[static_cast<std::size_t>(3 * v + order_of_axes[a]) * stride_ +
                                  first]);
                }
            }
            return batch;
        }
        std::array<const std::array<std::uint32_t, 3>*, 4> t{};
        for (std::uint32_t k = 0; k < 4; ++k) t[k] = &triangles_[first + std::min(k, lanes - 1)];
        for (int v = 0; v < 3; ++v) {
            const Float3 &p0 = positions_[(*t[0])[v]], &p1 = positions_[(*t[1])[v]],
                         &p2 = positions_[(*t[2])[v]], &p3 = positions_[(*t[3])[v]];
            for (int a = 0; a < 3; ++a) {
                const int k = order_of_axes[a];
                batch.corners[v][a] = _mm_setr_ps(p0[k], p1[k], p2[k], p3[k]);
            }
        }
        return batch;
    };
    const float near = to_float_down(range.min);
    float far = to_float_up(range.max);
    // Within the range, for the filter's proof of a hit (FloatShearedRay::classify).
    const float certain_low = range.min > 0 ? to_float_up(range.min) : 0;
    const float certain_high = to_float_down(range.max);
    // The nearest hit so far (kept by a nearest-hit query only), made into the answer only on
    // return: an optional built up field by field and copied out at the end stalls every ray
    // on store forwarding.
    struct Nearest {
        std::uint32_t triangle = std::numeric_limits<std::uint32_t>::max();  // none yet
        double t = 0;
        Barycentrics b{};
    };
    struct Nothing {};
    std::conditional_t<kAnyHit, Nothing, Nearest> best;
    // Children still to visit (a node, or a leaf's triangles), with where the ray enters their
    // boxes: one that a nearer hit has since put out of range is skipped. The nearest child of
    // a node is visited next without going through the stack; the others are pushed farthest
    // first.
    struct Pending {
        std::uint32_t child;
        std::uint32_t count;
        float entry;
    };
    std::array<Pending, kStackSize> stack;
    int top = 0;
    Pending current = one_leaf ? Pending{root.child[0], root.count[0], near} : Pending{0, 0, near};
    const bool flat = wide && wide->flat != 0;
    while (true) {
        if (current.count > 0) {
            // Four triangles at a time through the float filter; those it cannot rule out, in
            // order, through the double test, which alone decides (triangle_batch.h).
            const std::uint32_t end = current.child + current.count;
            for (std::uint32_t first = current.child; first < end; first += 4) {
                const auto lanes = std::min<std::uint32_t>(4, end - first);
                if (tests) *tests += lanes;
                int maybe = (1 << lanes) - 1;
                if (leaving - first < lanes) maybe &= ~(1 << (leaving - first));
                if constexpr (kAnyHit) {
                    // A triangle the filter proves the double test would hit answers the
                    // query without that test, which every blocked ray would otherwise run.
                    if (use_filter) {
                        const auto verdict = filter.classify(load(first, lanes), filter_near, far,
                                                             certain_low, certain_high);
                        if (!kAlpha && (verdict.certain & maybe)) return true;
                        maybe &= verdict.maybe;
                    }
                } else if (use_filter) {
                    maybe &= filter.maybe_hits(load(first, lanes), filter_near, far);
                }
                for (; maybe != 0; maybe &= maybe - 1) {
                    const std::uint32_t i = first + std::countr_zero(static_cast<unsigned>(maybe));
                    const auto [a, b, c] = corners(i);
                    if (!sheared) sheared.emplace(ray);
                    if (const auto hit = intersect_triangle(*sheared, a, b, c, range)) {
                        if constexpr (kAlpha) {
                            if (!opaque(i, hit->b)) continue;
                        }
                        if constexpr (kAnyHit) {
                            return true;
                        } else {
                            best = {i, hit->t, hit->b};
                            range.max = hit->t;
                            far = to_float_up(range.max);
                        }
                    }
                }
            }
        } else {
            const MeshTree::Node& node = tree_.node(current.child);
            alignas(32) float entry[MeshTree::kWidth];
            const int mask = (flat ? wide->hits<true>(node.box, near, far, entry)
                                   : wide->hits<false>(node.box, near, far, entry)) &
                             ((1 << node.children) - 1);
            if (mask != 0 && kAnyHit) {
                // Any hit will do, and whichever is found first gives the same answer: the
                // children in their order, without sorting them. Nor is where they are entered
                // kept: the range never shrinks before the query ends, so none is skipped.
                const int c = std::countr_zero(static_cast<unsigned>(mask));
                for (int m = mask & (mask - 1); m != 0; m &= m - 1) {
                    const int k = std::countr_zero(static_cast<unsigned>(m));
                    stack[top++] = {node.child[k], node.count[k], 0};
                }
                current = {node.child[c], node.count[c], 0};
                continue;
            }
            if (mask != 0) {
                // The children met, nearest first; among equal entries the last child first:
                // the order decides which of two hits at the same t is kept, so it is fixed.
                // One child or two, the common case, in that order without the general sort.
                int c = std::countr_zero(static_cast<unsigned>(mask));
                const int rest = mask & (mask - 1);
                if (rest != 0 && (rest & (rest - 1)) == 0) {
                    int d = std::countr_zero(static_cast<unsigned>(rest));
                    if (entry[d] <= entry[c]) std::swap(c, d);
                    stack[top++] = {node.child[d], node.count[d], entry[d]};
                } else if (rest != 0) {
                    std::array<int, MeshTree::kWidth> order{};
                    int n = 0;
                    for (int m = mask; m != 0; m &= m - 1) {
                        const int e = std::countr_zero(static_cast<unsigned>(m));
                        int k = n++;
                        for (; k > 0 && entry[order[k - 1]] >= entry[e]; --k)
                            order[k] = order[k - 1];
                        order[k] = e;
                    }
                    for (int k = n - 1; k > 0; --k) {
                        const int e = order[k];
                        stack[top++] = {node.child[e], node.count[e], entry[e]};
                    }
                    c = order[0];
                }
                current = {node.child[c], node.count[c], entry[c]};
                // The nearest child's other cache lines are fetched while its first is tested:
                // on a large mesh most nodes come from memory.
                if (current.count == 0) {
                    const auto* next = reinterpret_cast<const char*>(&tree_.node(current.child));
                    _mm_prefetch(next + 64, _MM_HINT_T0);
                    _mm_prefetch(next + 128, _MM_HINT_T0);
                    _mm_prefetch(next + 192, _MM_HINT_T0);
                }
                continue;
            }
        }
        do {
            if (top == 0) {
                if constexpr (kAnyHit) {
                    return false;
                } else {
                    if (best.triangle == Nearest{}.triangle) return std::nullopt;
                    return MeshHit{best.t, best.triangle, best.b};
                }
            }
            current = stack[--top];
        } while (!kAnyHit && current.entry > far * WideRay::kWiden);
    }
}

std::optional<MeshHit> TriangleMesh::intersect(const Ray& ray, Interval range,
                                               std::uint32_t leaving) const {
    return alpha_ ? traverse<false, true>(ray, range, leaving)
                  : traverse<false>(ray, range, leaving);
}

bool TriangleMesh::occluded(const Ray& ray, Interval range, std::uint32_t leaving) const {
    return alpha_ ? traverse<true, true>(ray, range, leaving) : traverse<true>(ray, range, leaving);
}

bool TriangleMesh::opaque(std::uint32_t triangle, const Barycentrics& b) const {
    Vec2 uv{0, 0};
    if (has_texcoords()) {
        const std::array<Vec2, 3> c = corner_texcoords(triangle);
        uv = {b.b0 * c[0].x + b.b1 * c[1].x + b.b2 * c[2].x,
              b.b0 * c[0].y + b.b1 * c[1].y + b.b2 * c[2].y};
    }
    return alpha_->bilinear(0, uv).r >= 0.5;
}

std::uint64_t TriangleMesh::triangle_tests(const Ray& ray, Interval range, bool any_hit) const {
    std::uint64_t tests = 0;
    if (any_hit) {
        traverse<true>(ray, range, kNoTriangle, &tests);
    } else {
        traverse<false>(ray, range, kNoTriangle, &tests);
    }
    return tests;
}

}  // namespace drt
