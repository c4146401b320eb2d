#include "drt/accel/mesh.h"

#include "drt/geometry/triangle_batch.h"
#include "drt/util/limits.h"

#include <immintrin.h>
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "drt/util/huge_pages.h"

namespace drt {

namespace {

// sin and cos of an angle in degrees, exact at multiples of 90 degrees, so that a quarter turn
// maps a float vertex onto float coordinates instead of leaving 6e-17 crumbs.
SinCos sincos_degrees(double degrees) {
    const double turns = degrees / 90;
    if (turns == std::round(turns)) {
        switch (static_cast<long long>(std::fmod(std::round(turns), 4.0) + 4) % 4) {
            case 0:
                return {0, 1};
            case 1:
                return {1, 0};
            case 2:
                return {0, -1};
            default:
                return {-1, 0};
        }
    }
    const double radians = degrees * (kPi / 180);
    return {std::sin(radians), std::cos(radians)};
}

Vec3 rotate_x(const Vec3& v, SinCos r) {
    return {v.x, v.y * r.cos - v.z * r.sin, v.y * r.sin + v.z * r.cos};
}
Vec3 rotate_y(const Vec3& v, SinCos r) {
    return {v.x * r.cos + v.z * r.sin, v.y, v.z * r.cos - v.x * r.sin};
}
Vec3 rotate_z(const Vec3& v, SinCos r) {
    return {v.x * r.cos - v.y * r.sin, v.x * r.sin + v.y * r.cos, v.z};
}

// The rotation of a MeshTransform, its sines and cosines worked out once for all vertices.
struct Rotation {
    SinCos x, y, z;

    explicit Rotation(const Vec3& degrees)
        : x(sincos_degrees(degrees.x)),
          y(sincos_degrees(degrees.y)),
          z(sincos_degrees(degrees.z)) {}
    Vec3 operator()(const Vec3& v) const { return rotate_z(rotate_y(rotate_x(v, x), y), z); }
};

Vec3 to_vec3(const std::array<float, 3>& f) {
    return {f[0], f[1], f[2]};
}

// The angle at corner a of triangle a, b, c.
double corner_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 u = b - a, v = c - a;
    return std::atan2(length(cross(u, v)), dot(u, v));
}

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
        below[k] = rounded_down(o - drift);
        above[k] = rounded_up(o + drift);
        inv_dir[k] = start[k] = end[k] = 0;
    }

    // The children whose boxes the ray meets inside [near, far] (bit k for child k), and where
    // it enters each. kFlat: whether any axis may be flat (a rare ray, tested apart so that the
    // common one runs without branches). The 8-wide test with AVX, else two 4-wide ones: the
    // same operations lane by lane, so every build visits the same boxes in the same order.
    template <bool kFlat>
    int hits(const float (&box)[2][3][8], float near, float far, float (&entry)[8]) const {
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

    // x rounded to a float no smaller (no larger): the next float up from a conversion that
    // went down, on the bits rather than by a call of nextafter.
    static float rounded_up(double x) {
        const auto f = static_cast<float>(x);
        return f < x ? next_up(f) : f;
    }
    static float rounded_down(double x) {
        const auto f = static_cast<float>(x);
        return f > x ? -next_up(-f) : f;
    }
    // (f < x for a double x: f is not +∞ and not NaN.)
    static float next_up(float f) {
        if (f == 0) return std::numeric_limits<float>::denorm_min();
        const auto bits = std::bit_cast<std::uint32_t>(f);
        return std::bit_cast<float>(f > 0 ? bits + 1 : bits - 1);
    }
};

// The traversal tests up to four triangles of a leaf at once (triangle_batch.h), for about what
// one box test costs: a subtree of this many triangles or fewer is visited as one leaf.
constexpr std::uint32_t kCollapsedLeaf = 4;
// A node pushes at most seven children besides the one it visits next, and no path is longer
// than 64 nodes.
constexpr int kStackSize = 7 * 64 + 1;

}  // namespace

Vec3 MeshTransform::apply(const Vec3& v) const {
    return rotate(v * scale);
}

Vec3 MeshTransform::rotate(const Vec3& v) const {
    return Rotation(rotate_degrees)(v);
}

TriangleMesh::TriangleMesh(const ObjMesh& obj, const MeshTransform& transform, bool smooth,
                           int build_threads) {
    take(obj, transform, smooth);
    build_hierarchy(build_threads);
}

TriangleMesh::TriangleMesh(ObjMesh&& obj, const MeshTransform& transform, bool smooth,
                           int build_threads) {
    take(obj, transform, smooth);
    // The file's arrays (in double) are larger than the mesh: gone before the hierarchy's
    // working arrays are made, they keep the peak down.
    obj = {};
    build_hierarchy(build_threads);
}

void TriangleMesh::take(const ObjMesh& obj, const MeshTransform& transform, bool smooth) {
    const Rotation rotation(transform.rotate_degrees);
    std::vector<Vec3> placed(obj.positions.size());
    Bounds box;
    for (std::size_t i = 0; i < placed.size(); ++i) {
        placed[i] = rotation(obj.positions[i] * transform.scale);
        box.grow(placed[i]);
    }
    origin_ = box.empty() ? Vec3{} : box.centre();

    // A vertex is a position, or with smooth shading a position and the file's normal there:
    // one index buffer serves both.
    const bool file_normals =
        smooth && std::ranges::any_of(obj.normal_indices,
                                      [](std::uint32_t n) { return n != ObjMesh::kNoNormal; });
    std::vector<std::uint32_t> vertex_position;  // vertex -> position
    std::vector<std::uint32_t> vertex_normal;    // vertex -> file normal or kNoNormal
    std::unordered_map<std::uint64_t, std::uint32_t> vertex_of;
    const auto vertex = [&](std::uint32_t p, std::uint32_t n) {
        if (!file_normals) return p;
        const auto [it, added] = vertex_of.try_emplace(
            (std::uint64_t{p} << 32) | n, static_cast<std::uint32_t>(vertex_position.size()));
        if (added) vertex_position.push_back(p), vertex_normal.push_back(n);
        return it->second;
    };
    if (!file_normals) {
        vertex_position.resize(placed.size());
        std::iota(vertex_position.begin(), vertex_position.end(), 0u);
    }

    const auto local = [&](std::uint32_t p) {
        const Vec3 v = placed[p] - origin_;
        const Float3 f{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
        if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2])) {
            throw std::domain_error("vertex " + std::to_string(p + 1) +
                                    " is beyond single precision (±3.4e38) once transformed");
        }
        return f;
    };
    std::vector<Float3> local_positions(placed.size());
    for (std::uint32_t p = 0; p < placed.size(); ++p) local_positions[p] = local(p);

    const std::size_t corners = obj.position_indices.size();
    triangles_.reserve(corners / 3);
    for (std::size_t c = 0; c < corners; c += 3) {
        const std::uint32_t* p = &obj.position_indices[c];
        const Vec3 a = to_vec3(local_positions[p[0]]), b = to_vec3(local_positions[p[1]]),
                   d = to_vec3(local_positions[p[2]]);
        if (cross(b - a, d - a) == Vec3{}) {
            ++dropped_;
            continue;
        }
        const std::uint32_t* n = &obj.normal_indices[c];
        triangles_.push_back({vertex(p[0], n[0]), vertex(p[1], n[1]), vertex(p[2], n[2])});
    }

    if (file_normals) {
        positions_.resize(vertex_position.size());
        for (std::size_t v = 0; v < positions_.size(); ++v)
            positions_[v] = local_positions[vertex_position[v]];
    } else {
        positions_ = std::move(local_positions);
    }
    const std::vector<Float3>& by_position = file_normals ? local_positions : positions_;

    if (smooth) {
        // Angle-weighted face normals (Thürmer & Wüthrich 1998): unlike area weights they do not
        // change when a neighbouring face is split in two.
        std::vector<Vec3> computed(placed.size());
        for (const auto& t : triangles_) {
            const std::array<std::uint32_t, 3> p{vertex_position[t[0]], vertex_position[t[1]],
                                                 vertex_position[t[2]]};
            const Vec3 a = to_vec3(by_position[p[0]]), b = to_vec3(by_position[p[1]]),
                       c = to_vec3(by_position[p[2]]);
            const Vec3 n = normalize(cross(b - a, c - a));
            computed[p[0]] += n * corner_angle(a, b, c);
            computed[p[1]] += n * corner_angle(b, c, a);
            computed[p[2]] += n * corner_angle(c, a, b);
        }
        normals_.resize(positions_.size());
        for (std::size_t v = 0; v < normals_.size(); ++v) {
            Vec3 n = computed[vertex_position[v]];
            if (file_normals && vertex_normal[v] != ObjMesh::kNoNormal) {
                const Vec3 given = rotation(obj.normals[vertex_normal[v]]);
                if (max_abs_component(given) > 0) n = given;
            }
            // A normal that cancelled out stays zero; shading falls back to the face's.
            const double m = max_abs_component(n);
            if (m > 0) n = normalize(n / m);
            normals_[v] = {static_cast<float>(n.x), static_cast<float>(n.y),
                           static_cast<float>(n.z)};
        }
    }
}

Vec3 TriangleMesh::position(std::uint32_t vertex) const {
    return to_vec3(positions_[vertex]);
}

std::array<Vec3, 3> TriangleMesh::corners(std::uint32_t triangle) const {
    const auto& t = triangles_[triangle];
    return {position(t[0]), position(t[1]), position(t[2])};
}

Vec3 TriangleMesh::geometric_normal(std::uint32_t triangle) const {
    const auto [a, b, c] = corners(triangle);
    const Vec3 n = cross(b - a, c - a);
    // Scaled first: the cross product of a tiny triangle can underflow when squared.
    return normalize(n / max_abs_component(n));
}

Vec3 TriangleMesh::shading_normal(std::uint32_t triangle, const Barycentrics& b) const {
    if (normals_.empty()) return geometric_normal(triangle);
    const auto& t = triangles_[triangle];
    const Vec3 n = to_vec3(normals_[t[0]]) * b.b0 + to_vec3(normals_[t[1]]) * b.b1 +
                   to_vec3(normals_[t[2]]) * b.b2;
    // Opposite normals at the corners can cancel: the face's own normal is then the answer.
    if (!(dot(n, n) > 1e-12)) return geometric_normal(triangle);
    return normalize(n);
}

Vec3 TriangleMesh::lifted(std::uint32_t triangle, const Barycentrics& b) const {
    const auto& t = triangles_[triangle];
    const auto [p0, p1, p2] = corners(triangle);
    const Vec3 p = p0 * b.b0 + p1 * b.b1 + p2 * b.b2;
    // Each corner's tangent plane lifts the point onto it where the point is below it; the
    // lifts are blended by the barycentrics, which gives a smooth surface through the corners.
    Vec3 lift;
    const double weights[3] = {b.b0, b.b1, b.b2};
    const Vec3 vertices[3] = {p0, p1, p2};
    for (int k = 0; k < 3; ++k) {
        const Vec3 n = to_vec3(normals_[t[k]]);
        lift -= n * (weights[k] * std::min(0.0, dot(p - vertices[k], n)));
    }
    return p + lift;
}

Bounds TriangleMesh::bounds() const {
    if (nodes_.empty()) return {};
    return {to_vec3(lo_), to_vec3(hi_)};
}

std::size_t TriangleMesh::bytes() const {
    return positions_.capacity() * sizeof(Float3) + normals_.capacity() * sizeof(Float3) +
           triangles_.capacity() * sizeof(triangles_[0]) + nodes_.capacity() * sizeof(Node) +
           sizeof(*this);
}

void TriangleMesh::build_hierarchy(int threads) {
    if (triangles_.empty()) return;
    threads = worker_threads(threads);
    BinaryTree tree = build_binary_tree(positions_, triangles_, threads);
    lo_ = tree.nodes[0].lo;
    hi_ = tree.nodes[0].hi;
    filter_fits_ = true;
    for (int a = 0; a < 3; ++a) {
        filter_fits_ = filter_fits_ &&
                       std::max(std::abs(lo_[a]), std::abs(hi_[a])) <= FloatShearedRay::kLargest;
    }
    collapse_small_subtrees(tree.nodes);
    // Each wide node takes the place of at least three binary ones (but a root that is a leaf).
    nodes_.reserve(tree.nodes.size() / 3 + 1);
    prefer_huge_pages(nodes_);
    widen(tree.nodes, 0);
    nodes_.shrink_to_fit();
    std::vector<std::array<std::uint32_t, 3>> ordered;
    ordered.reserve(triangles_.size());
    prefer_huge_pages(ordered);
    for (const std::uint32_t t : tree.order) ordered.push_back(triangles_[t]);
    triangles_ = std::move(ordered);
    order_vertices_by_leaves();
}

void TriangleMesh::order_vertices_by_leaves() {
    constexpr auto kUnseen = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> renumbered(positions_.size(), kUnseen);
    std::uint32_t next = 0;
    for (auto& t : triangles_) {
        for (std::uint32_t& v : t) {
            if (renumbered[v] == kUnseen) renumbered[v] = next++;
            v = renumbered[v];
        }
    }
    for (std::uint32_t& r : renumbered) {
        if (r == kUnseen) r = next++;  // a vertex of dropped triangles only
    }
    const auto permuted = [&](const std::vector<Float3>& from) {
        std::vector<Float3> to(from.size());
        for (std::size_t v = 0; v < from.size(); ++v) to[renumbered[v]] = from[v];
        return to;
    };
    positions_ = permuted(positions_);
    if (!normals_.empty()) normals_ = permuted(normals_);
}

void TriangleMesh::collapse_small_subtrees(std::vector<BinaryNode>& binary) {
    // A node's children come after it (the first right after), so one pass from the end sees
    // every subtree before its root. A subtree's triangles are one run of the leaf order.
    std::vector<std::uint32_t> first(binary.size()), size(binary.size());
    for (std::size_t n = binary.size(); n-- > 0;) {
        BinaryNode& node = binary[n];
        if (node.count > 0) {
            first[n] = node.offset;
            size[n] = node.count;
            continue;
        }
        first[n] = first[n + 1];
        size[n] = size[n + 1] + size[node.offset];
        if (size[n] <= kCollapsedLeaf) node = {node.lo, node.hi, first[n], size[n]};
    }
}

std::uint32_t TriangleMesh::widen(const std::vector<BinaryNode>& binary, std::uint32_t node) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back({});
    // The node's binary children, then, while there is room, the inner one of largest surface
    // area replaced by its two children: what a wide node saves is the most boxes entered.
    std::array<std::uint32_t, kWidth> kids{};
    int n = 0;
    if (binary[node].count > 0) {
        kids[n++] = node;  // the whole tree is one leaf
    } else {
        kids[n++] = node + 1;
        kids[n++] = binary[node].offset;
    }
    const auto area = [&](std::uint32_t k) {
        return Bounds{to_vec3(binary[k].lo), to_vec3(binary[k].hi)}.surface_area();
    };
    while (n < kWidth) {
        int open = -1;
        for (int k = 0; k < n; ++k) {
            if (binary[kids[k]].count == 0 && (open < 0 || area(kids[k]) > area(kids[open])))
                open = k;
        }
        if (open < 0) break;
        const std::uint32_t opened = kids[open];
        kids[open] = opened + 1;
        kids[n++] = binary[opened].offset;
    }
    // Unused slots keep boxes at +∞ on both sides, which no ray enters, but `children` is what
    // the traversal reads.
    for (int a = 0; a < 3; ++a) {
        for (int k = 0; k < kWidth; ++k) {
            nodes_[index].box[0][a][k] = nodes_[index].box[1][a][k] =
                std::numeric_limits<float>::infinity();
        }
    }
    nodes_[index].children = static_cast<std::uint32_t>(n);
    for (int k = 0; k < n; ++k) {
        const BinaryNode& child = binary[kids[k]];
        for (int a = 0; a < 3; ++a) {
            nodes_[index].box[0][a][k] = child.lo[a];
            nodes_[index].box[1][a][k] = child.hi[a];
        }
        // (widen appends to nodes_: no reference into it is held across the call.)
        const std::uint32_t target = child.count > 0 ? child.offset : widen(binary, kids[k]);
        nodes_[index].child[k] = target;
        nodes_[index].count[k] = static_cast<std::uint16_t>(child.count);
    }
    return index;
}

template <bool kAnyHit>
TriangleMesh::Answer<kAnyHit> TriangleMesh::traverse(const Ray& ray, Interval range,
                                                     std::uint64_t* tests) const {
    if (nodes_.empty()) return {};
    // The per-ray set-up is a good part of a ray's cost: the double-precision sheared ray of the
    // watertight test (two more divisions) is made only once a triangle passes the float
    // filter; the filter's shear is the same to within what its bounds allow for.
    alignas(16) double inv[4];
    _mm_store_pd(inv, _mm_div_pd(_mm_set1_pd(1), _mm_setr_pd(ray.dir.x, ray.dir.y)));
    inv[2] = 1 / ray.dir.z;
    const WideRay wide(ray, range, inv);
    const ShearedRay::Axes axes = ShearedRay::axes_of(ray.dir);
    const FloatShearedRay filter(ray.origin, axes, ray.dir[axes.kx] * inv[axes.kz],
                                 ray.dir[axes.ky] * inv[axes.kz], inv[axes.kz]);
    std::optional<ShearedRay> sheared;
    const bool use_filter = filter.usable() && filter_fits_;
    const std::array<int, 3> order_of_axes{axes.kx, axes.ky, axes.kz};
    // The filter's near end must not be negative (triangle_batch.h); a negative range start
    // (never used by the renderer) leaves the near end to the double test.
    const float filter_near =
        range.min >= 0 ? WideRay::rounded_down(range.min) : -std::numeric_limits<float>::infinity();
    // Corners of triangles first .. first + lanes - 1 in the filter's axis order; lanes past
    // the leaf's end repeat its last triangle and are masked off.
    const auto gather = [&](std::uint32_t first, std::uint32_t lanes) {
        std::array<const std::array<std::uint32_t, 3>*, 4> t{};
        for (std::uint32_t k = 0; k < 4; ++k) t[k] = &triangles_[first + std::min(k, lanes - 1)];
        TriangleBatch batch;
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
    const float near = WideRay::rounded_down(range.min);
    float far = WideRay::rounded_up(range.max);
    // Within the range, for the filter's proof of a hit (FloatShearedRay::classify).
    const float certain_low = range.min > 0 ? WideRay::rounded_up(range.min) : 0;
    const float certain_high = WideRay::rounded_down(range.max);
    // The nearest hit so far (kept by a nearest-hit query only), made into the answer only on
    // return: an optional built up field by field and copied out at the end stalled every ray
    // on store forwarding, 8 % of a query.
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
    Pending current{0, 0, near};
    const bool flat = wide.flat != 0;
    while (true) {
        if (current.count > 0) {
            // Four triangles at a time through the float filter; those it cannot rule out, in
            // order, through the double test, which alone decides (triangle_batch.h).
            const std::uint32_t end = current.child + current.count;
            for (std::uint32_t first = current.child; first < end; first += 4) {
                const auto lanes = std::min<std::uint32_t>(4, end - first);
                if (tests) *tests += lanes;
                int maybe = (1 << lanes) - 1;
                if constexpr (kAnyHit) {
                    // A triangle the filter proves the double test would hit answers the
                    // query without that test (the double test was 9 % of a shadow ray's time
                    // on average, run once for each blocked ray).
                    if (use_filter) {
                        const auto verdict = filter.classify(gather(first, lanes), filter_near, far,
                                                             certain_low, certain_high);
                        if (verdict.certain & maybe) return true;
                        maybe &= verdict.maybe;
                    }
                } else if (use_filter) {
                    maybe &= filter.maybe_hits(gather(first, lanes), filter_near, far);
                }
                for (; maybe != 0; maybe &= maybe - 1) {
                    const std::uint32_t i = first + std::countr_zero(static_cast<unsigned>(maybe));
                    const auto [a, b, c] = corners(i);
                    if (!sheared) sheared.emplace(ray);
                    if (const auto hit = intersect_triangle(*sheared, a, b, c, range)) {
                        if constexpr (kAnyHit) {
                            return true;
                        } else {
                            best = {i, hit->t, hit->b};
                            range.max = hit->t;
                            far = WideRay::rounded_up(range.max);
                        }
                    }
                }
            }
        } else {
            const Node& node = nodes_[current.child];
            alignas(32) float entry[kWidth];
            const int mask = (flat ? wide.hits<true>(node.box, near, far, entry)
                                   : wide.hits<false>(node.box, near, far, entry)) &
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
                // The children met, nearest first; among equal entries the last child first,
                // the order in which earlier versions visited them. One child or two (the
                // later one first on a tie) in the same order without the general sort:
                // camera rays 4 % faster.
                int c = std::countr_zero(static_cast<unsigned>(mask));
                const int rest = mask & (mask - 1);
                if (rest != 0 && (rest & (rest - 1)) == 0) {
                    int d = std::countr_zero(static_cast<unsigned>(rest));
                    if (entry[d] <= entry[c]) std::swap(c, d);
                    stack[top++] = {node.child[d], node.count[d], entry[d]};
                } else if (rest != 0) {
                    std::array<int, kWidth> order{};
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
                // The nearest child's other cache lines are fetched while its first is tested
                // (on a mesh of a million triangles most nodes come from memory).
                if (current.count == 0) {
                    const auto* next = reinterpret_cast<const char*>(&nodes_[current.child]);
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

std::optional<MeshHit> TriangleMesh::intersect(const Ray& ray, Interval range) const {
    return traverse<false>(ray, range);
}

bool TriangleMesh::occluded(const Ray& ray, Interval range) const {
    return traverse<true>(ray, range);
}

std::uint64_t TriangleMesh::triangle_tests(const Ray& ray, Interval range, bool any_hit) const {
    std::uint64_t tests = 0;
    if (any_hit) {
        traverse<true>(ray, range, &tests);
    } else {
        traverse<false>(ray, range, &tests);
    }
    return tests;
}

namespace {

std::vector<Vec3> shifted(std::vector<Vec3> points, const Vec3& by) {
    for (Vec3& p : points) p += by;
    return points;
}

}  // namespace

Mesh::Mesh(std::shared_ptr<const TriangleMesh> mesh, const std::vector<Vec3>& translations,
           const Material& material, SurfaceDetail detail)
    : Object(material, std::move(detail)),
      mesh_(std::move(mesh)),
      path_(shifted(translations, mesh_->origin())) {}

std::optional<Hit> Mesh::intersect(const Ray& ray, Interval range) const {
    const auto hit = mesh_->intersect(ray_in_mesh(ray, path_.at(ray.time)), range);
    if (!hit) return std::nullopt;
    return Hit{hit->t, this, hit->triangle, {hit->b.b1, hit->b.b2}};
}

Object::SurfaceCoordinates Mesh::locate(const Ray& ray, const Hit& hit, SurfaceHit& surface) const {
    const Vec3 origin = path_.at(ray.time);
    const auto [a, b, c] = mesh_->corners(hit.primitive);
    const Barycentrics w{1 - hit.uv.x - hit.uv.y, hit.uv.x, hit.uv.y};
    // From the barycentrics rather than ray.at(t): on the triangle's plane to rounding in the
    // mesh's own coordinates, whatever distance the ray came from.
    surface.point = origin + (a * w.b0 + b * w.b1 + c * w.b2);
    surface.normal = mesh_->geometric_normal(hit.primitive);
    surface.shading_normal = mesh_->shading_normal(hit.primitive, w);
    if (mesh_->smooth()) {
        surface.light_point = origin + mesh_->lifted(hit.primitive, w);
        surface.light_normal = surface.shading_normal;
    } else {
        surface.light_point = surface.point;
        surface.light_normal = surface.normal;
    }
    // Textures and bumps stay where the mesh is at time 0, the present: world coordinates for
    // a mesh that does not move.
    const Vec3 fixed = surface.point - (origin - path_.at(0));
    return {fixed, fixed};
}

SurfaceUv Mesh::surface_uv(const Ray&, const Hit& hit, const SurfaceHit&) const {
    const auto [a, b, c] = mesh_->corners(hit.primitive);
    return {hit.uv, b - a, c - a};
}

}  // namespace drt
