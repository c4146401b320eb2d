#include "drt/accel/mesh_build.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "drt/accel/triangle_mesh.h"
#include "drt/util/rng.h"
#include "test_math.h"
#include "test_meshes.h"

namespace drt {
namespace {

using Triangle = std::array<std::uint32_t, 3>;

struct Soup {
    std::vector<Float3> positions;
    std::vector<Triangle> triangles;
};

Soup soup_of(const testing::TestMesh& mesh) {
    Soup s;
    for (const Vec3& v : mesh.vertices)
        s.positions.push_back(
            {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)});
    s.triangles = mesh.triangles;
    return s;
}

// Small triangles of every size and orientation scattered unevenly through a box, some of them
// at the very same place: unlike a sphere's, its splits are far from the middle.
Soup scattered(std::uint32_t n) {
    Soup s;
    using testing::unit;
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint64_t key = i % 7 == 0 ? 7 : i;  // every seventh at one place
        const double size = 0.001 + 0.2 * unit(key, 0) * unit(key, 1);
        const double cx = unit(key, 2) * unit(key, 2) * 10, cy = unit(key, 3), cz = unit(key, 4);
        for (int k = 0; k < 3; ++k) {
            s.positions.push_back({static_cast<float>(cx + size * unit(key, 5 + 3 * k)),
                                   static_cast<float>(cy + size * unit(key, 6 + 3 * k)),
                                   static_cast<float>(cz + size * unit(key, 7 + 3 * k))});
        }
        s.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    return s;
}

std::uint64_t fingerprint(const BinaryTree& tree) {
    std::uint64_t h = hash_of(tree.nodes.size(), tree.order.size());
    for (const BinaryNode& node : tree.nodes) {
        std::uint32_t words[8];
        std::memcpy(words, &node, sizeof words);
        for (const std::uint32_t w : words) h = hash_combine(h, w);
    }
    for (const std::uint32_t t : tree.order) h = hash_combine(h, t);
    return h;
}

// Every triangle in exactly one leaf, each box the smallest around what is below it, leaves of
// at most 8 triangles, and no path longer than the traversal's stack allows.
void expect_well_formed(const Soup& soup, const BinaryTree& tree) {
    ASSERT_EQ(tree.order.size(), soup.triangles.size());
    std::vector<std::uint32_t> sorted = tree.order;
    std::ranges::sort(sorted);
    for (std::uint32_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i);

    std::uint32_t in_leaves = 0;
    int deepest = 0;
    struct Visit {
        std::uint32_t node;
        int depth;
    };
    std::vector<Visit> stack{{0, 1}};
    while (!stack.empty()) {
        const auto [index, depth] = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, depth);
        const BinaryNode& node = tree.nodes.at(index);
        Float3 lo{}, hi{};
        const auto first = [&](const Float3& l, const Float3& h) { lo = l, hi = h; };
        const auto grow = [&](const Float3& l, const Float3& h) {
            for (int a = 0; a < 3; ++a)
                lo[a] = std::min(lo[a], l[a]), hi[a] = std::max(hi[a], h[a]);
        };
        if (node.count > 0) {
            ASSERT_LE(node.count, 8u);
            in_leaves += node.count;
            for (std::uint32_t i = node.offset; i < node.offset + node.count; ++i) {
                const Triangle& t = soup.triangles[tree.order.at(i)];
                for (int k = 0; k < 3; ++k) {
                    const Float3& p = soup.positions[t[k]];
                    if (i == node.offset && k == 0) first(p, p);
                    grow(p, p);
                }
            }
        } else {
            const BinaryNode& a = tree.nodes.at(index + 1);
            const BinaryNode& b = tree.nodes.at(node.offset);
            ASSERT_GT(node.offset, index + 1);
            first(a.lo, a.hi);
            grow(b.lo, b.hi);
            stack.push_back({index + 1, depth + 1});
            stack.push_back({node.offset, depth + 1});
        }
        EXPECT_EQ(node.lo, lo) << "node " << index;
        EXPECT_EQ(node.hi, hi) << "node " << index;
    }
    EXPECT_EQ(in_leaves, soup.triangles.size());
    EXPECT_LE(deepest, 40 + 32);
}

TEST(MeshBuild, EveryTriangleIsInOneLeafUnderBoxesThatHoldIt) {
    for (const Soup& soup : {soup_of(testing::icosphere(4)), scattered(30000)}) {
        const BinaryTree tree = build_binary_tree(soup.positions, soup.triangles, 2);
        expect_well_formed(soup, tree);
    }
}

TEST(MeshBuild, OneTriangleIsALeaf) {
    const Soup soup = scattered(1);
    const BinaryTree tree = build_binary_tree(soup.positions, soup.triangles, 1);
    ASSERT_EQ(tree.nodes.size(), 1u);
    EXPECT_EQ(tree.nodes[0].count, 1u);
    expect_well_formed(soup, tree);
}

// Many triangles at one place cannot be told apart by their centres: they are split at the
// median into leaves of at most 8, not left in one large leaf.
TEST(MeshBuild, TrianglesAtOnePlaceAreSplitIntoSmallLeaves) {
    Soup soup;
    soup.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    soup.triangles.assign(100, {0, 1, 2});
    const BinaryTree tree = build_binary_tree(soup.positions, soup.triangles, 1);
    expect_well_formed(soup, tree);
}

// The same tree on any number of threads, on meshes large enough for subtrees to be built in
// parallel.
TEST(MeshBuild, BuildsTheSameTreeOnAnyNumberOfThreads) {
    for (const Soup& soup : {soup_of(testing::icosphere(6)), scattered(100000)}) {
        const std::uint64_t one = fingerprint(build_binary_tree(soup.positions, soup.triangles, 1));
        for (const int threads : {2, 3, 8})
            EXPECT_EQ(fingerprint(build_binary_tree(soup.positions, soup.triangles, threads)), one)
                << threads << " threads";
    }
}

// The tree decides which of two triangles at the same distance a ray finds, and so the last
// bits of images: a faster build must build the very same tree. These are the fingerprints of
// the trees of the build that bins along all three axes (the first build binned along the
// longest axis alone, in double).
TEST(MeshBuild, BuildsTheTreeItAlwaysHas) {
    const Soup sphere = soup_of(testing::icosphere(6));
    EXPECT_EQ(fingerprint(build_binary_tree(sphere.positions, sphere.triangles, 2)),
              16352173775989727779u);
    const Soup soup = scattered(100000);
    EXPECT_EQ(fingerprint(build_binary_tree(soup.positions, soup.triangles, 2)),
              8751624139181001828u);
}

// A mesh made from a file it may empty (the scene loader's, which lowers the peak memory) is the
// mesh made from one it keeps, with smooth normals from the file and computed ones.
TEST(MeshBuild, AMeshFromAnObjItEmptiesIsTheSameMesh) {
    ObjMesh obj = testing::obj_of(testing::icosphere(3));
    obj.normals = {{0, 0, 2}};
    obj.normal_indices[4] = 0;
    const MeshTransform turn{2, {10, 20, 30}};
    const TriangleMesh kept(obj, turn, true);
    const TriangleMesh emptied(std::move(obj), turn, true);
    EXPECT_TRUE(obj.positions.empty() && obj.position_indices.empty());
    EXPECT_EQ(emptied.origin(), kept.origin());
    EXPECT_TRUE(std::ranges::equal(emptied.positions(), kept.positions()));
    EXPECT_TRUE(std::ranges::equal(emptied.triangles(), kept.triangles()));
    EXPECT_TRUE(std::ranges::equal(emptied.hierarchy(), kept.hierarchy()));
    for (std::uint32_t t = 0; t < kept.triangle_count(); ++t)
        EXPECT_EQ(emptied.shading_normal(t, {0.2, 0.3, 0.5}),
                  kept.shading_normal(t, {0.2, 0.3, 0.5}));
}

}  // namespace
}  // namespace drt
