#include "drt/accel/triangle_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "drt/geometry/collinear.h"
#include "drt/util/huge_pages.h"
#include "drt/util/limits.h"

namespace drt {

namespace {

// The angle at corner a of triangle a, b, c.
double corner_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 u = b - a, v = c - a;
    return std::atan2(length(cross(u, v)), dot(u, v));
}

// A placed vertex in a mesh's own coordinates; not finite if it does not fit in a float.
Float3 to_local(const Vec3& placed, const Vec3& origin) {
    const Vec3 v = placed - origin;
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

bool finite(const Float3& f) {
    return std::isfinite(f[0]) && std::isfinite(f[1]) && std::isfinite(f[2]);
}

// Whether corners rounded to single precision lie on a line.
bool flattened(const Float3& a, const Float3& b, const Float3& c) {
    const Vec3 p = to_vec3(a);
    return cross(to_vec3(b) - p, to_vec3(c) - p) == Vec3{};
}

}  // namespace

bool TriangleMesh::holds(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& origin) {
    const Float3 fa = to_local(a, origin), fb = to_local(b, origin), fc = to_local(c, origin);
    return finite(fa) && finite(fb) && finite(fc) && !flattened(fa, fb, fc);
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
    origin_ = transform.origin ? *transform.origin : box.empty() ? Vec3{} : box.centre();

    // A vertex is a position, or with smooth shading a position and the file's normal there:
    // one index buffer serves both.
    const bool file_normals =
        smooth && std::ranges::any_of(obj.normal_indices,
                                      [](std::uint32_t n) { return n != ObjMesh::kNoNormal; });
    std::vector<std::uint32_t> vertex_position;  // vertex -> position
    std::vector<std::uint32_t> vertex_normal;    // vertex -> file normal or kNoNormal
    std::vector<bool> vertex_turned;             // vertex -> its file normal is negated
    std::array<std::unordered_map<std::uint64_t, std::uint32_t>, 2> vertex_of;  // [turned]
    const auto vertex = [&](std::uint32_t p, std::uint32_t n, bool turned) {
        if (!file_normals) return p;
        turned = turned && n != ObjMesh::kNoNormal;
        const auto [it, added] = vertex_of[turned].try_emplace(
            (std::uint64_t{p} << 32) | n, static_cast<std::uint32_t>(vertex_position.size()));
        if (added) {
            vertex_position.push_back(p), vertex_normal.push_back(n);
            vertex_turned.push_back(turned);
        }
        return it->second;
    };
    // Whether a face's file normals point, summed, against its winding: the winding tells the
    // outside (as it does for a transparent material), and a shading normal on the other side
    // would leave the face lit by no light. Such a face's corners take their normals negated,
    // so that a file wound clockwise with outward normals shades as its mirror image would.
    // (Rotation and a positive scale keep the sign of the product.)
    const auto against_winding = [&](const std::uint32_t* p, const std::uint32_t* n) {
        Vec3 sum;
        for (int k = 0; k < 3; ++k) {
            if (n[k] != ObjMesh::kNoNormal) sum += obj.normals[n[k]];
        }
        const Vec3 &a = obj.positions[p[0]], &b = obj.positions[p[1]], &c = obj.positions[p[2]];
        return dot(sum, cross(b - a, c - a)) < 0;
    };
    if (!file_normals) {
        vertex_position.resize(placed.size());
        std::iota(vertex_position.begin(), vertex_position.end(), 0u);
    }

    const auto local = [&](std::uint32_t p) {
        const Float3 f = to_local(placed[p], origin_);
        if (!finite(f)) {
            throw std::domain_error("vertex " + std::to_string(p + 1) +
                                    " is beyond single precision (±3.4e38) once transformed");
        }
        return f;
    };
    std::vector<Float3> local_positions(placed.size());
    for (std::uint32_t p = 0; p < placed.size(); ++p) local_positions[p] = local(p);

    const std::size_t corners = obj.position_indices.size();
    triangles_.reserve(corners / 3);
    const bool parted = !obj.triangle_materials.empty();
    for (std::size_t c = 0; c < corners; c += 3) {
        const std::uint32_t* p = &obj.position_indices[c];
        // Zero area is the file's: rounding to float may move its corners off their line.
        if (collinear(obj.positions[p[0]], obj.positions[p[1]], obj.positions[p[2]])) {
            ++dropped_;
            continue;
        }
        if (flattened(local_positions[p[0]], local_positions[p[1]], local_positions[p[2]])) {
            ++collapsed_;
            continue;
        }
        const std::uint32_t* n = &obj.normal_indices[c];
        const bool turned = file_normals && against_winding(p, n);
        triangles_.push_back(
            {vertex(p[0], n[0], turned), vertex(p[1], n[1], turned), vertex(p[2], n[2], turned)});
        if (parted) parts_.push_back(obj.triangle_materials[c / 3]);
        if (!obj.texcoord_indices.empty()) {
            std::array<float, 6> uv{};
            for (std::size_t k = 0; k < 3; ++k) {
                const std::uint32_t i = obj.texcoord_indices[c + k];
                if (i == ObjMesh::kNoTexcoord) continue;
                uv[2 * k] = static_cast<float>(obj.texcoords[i].x);
                uv[2 * k + 1] = static_cast<float>(obj.texcoords[i].y);
            }
            texcoords_.push_back(uv);
        }
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
        if (std::ranges::find(vertex_turned, true) != vertex_turned.end()) turned_ = vertex_turned;
        for (std::size_t v = 0; v < normals_.size(); ++v) {
            Vec3 n = computed[vertex_position[v]];
            if (file_normals && vertex_normal[v] != ObjMesh::kNoNormal) {
                const Vec3 file_normal = obj.normals[vertex_normal[v]];
                const Vec3 given = rotation(vertex_turned[v] ? -file_normal : file_normal);
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

Vec3 TriangleMesh::geometric_normal(std::uint32_t triangle) const {
    if (!face_normals_.empty()) return face_normals_[triangle];
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
        const Vec3 n =
            turned_.empty() || !turned_[t[k]] ? to_vec3(normals_[t[k]]) : -to_vec3(normals_[t[k]]);
        lift -= n * (weights[k] * std::min(0.0, dot(p - vertices[k], n)));
    }
    return p + lift;
}

std::size_t TriangleMesh::bytes() const {
    return positions_.capacity() * sizeof(Float3) + normals_.capacity() * sizeof(Float3) +
           turned_.capacity() / 8 + triangles_.capacity() * sizeof(triangles_[0]) +
           texcoords_.capacity() * sizeof(texcoords_[0]) + corners_.capacity() * sizeof(float) +
           face_normals_.capacity() * sizeof(Vec3) + parts_.capacity() * sizeof(parts_[0]) +
           tree_.memory() + sizeof(*this);
}

void TriangleMesh::build_hierarchy(int threads) {
    if (triangles_.empty()) return;
    threads = worker_threads(threads);
    BinaryTree tree = build_binary_tree(positions_, triangles_, threads);
    tree_ = MeshTree(std::move(tree.nodes));
    std::vector<std::array<std::uint32_t, 3>> ordered;
    ordered.reserve(triangles_.size());
    prefer_huge_pages(ordered);
    for (const std::uint32_t t : tree.order) ordered.push_back(triangles_[t]);
    triangles_ = std::move(ordered);
    if (!texcoords_.empty()) {
        std::vector<std::array<float, 6>> uv_ordered;
        uv_ordered.reserve(texcoords_.size());
        for (const std::uint32_t t : tree.order) uv_ordered.push_back(texcoords_[t]);
        texcoords_ = std::move(uv_ordered);
    }
    if (!parts_.empty()) {
        std::vector<std::uint32_t> parts_ordered;
        parts_ordered.reserve(parts_.size());
        for (const std::uint32_t t : tree.order) parts_ordered.push_back(parts_[t]);
        parts_ = std::move(parts_ordered);
    }
    order_vertices_by_leaves();
    make_corner_arrays();
}

void TriangleMesh::make_corner_arrays() {
    const std::size_t count = triangles_.size();
    if (count > kCornerArrayLimit) return;
    stride_ = count + 3;
    corners_.assign(9 * stride_, 0.0f);
    for (std::size_t i = 0; i < stride_; ++i) {
        const auto& t = triangles_[std::min(i, count - 1)];
        for (int v = 0; v < 3; ++v) {
            for (int a = 0; a < 3; ++a)
                corners_[static_cast<std::size_t>(3 * v + a) * stride_ + i] = positions_[t[v]][a];
        }
    }
    // Worked out into a vector of their own first: geometric_normal reads face_normals_ once
    // it is filled.
    std::vector<Vec3> normals(count);
    for (std::uint32_t t = 0; t < count; ++t) normals[t] = geometric_normal(t);
    face_normals_ = std::move(normals);
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

}  // namespace drt
