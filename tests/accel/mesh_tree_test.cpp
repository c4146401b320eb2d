#include "drt/accel/mesh_tree.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "drt/accel/mesh_build.h"
#include "test_meshes.h"

namespace drt {
namespace {

struct Built {
    std::vector<Float3> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    BinaryTree binary;
};

Built built(const testing::TestMesh& mesh) {
    Built b;
    for (const Vec3& v : mesh.vertices)
        b.positions.push_back(
            {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)});
    b.triangles = mesh.triangles;
    b.binary = build_binary_tree(b.positions, b.triangles, 1);
    return b;
}

// Every triangle of the leaf order in exactly one leaf, under boxes that hold it all the way
// down; slots past a node's children have boxes no ray enters.
TEST(MeshTree, EveryTriangleIsInOneLeafUnderBoxesThatHoldIt) {
    const Built b = built(testing::icosphere(4));
    const MeshTree tree(b.binary.nodes);
    ASSERT_FALSE(tree.empty());
    std::vector<int> seen(b.triangles.size(), 0);
    struct Pending {
        std::uint32_t node;
        Bounds box;
    };
    std::vector<Pending> stack{{0, tree.bounds()}};
    int nodes = 0;
    while (!stack.empty()) {
        const Pending p = stack.back();
        stack.pop_back();
        const MeshTree::Node& node = tree.node(p.node);
        ++nodes;
        ASSERT_GE(node.children, 1u);
        ASSERT_LE(node.children, 8u);
        for (int k = 0; k < MeshTree::kWidth; ++k) {
            const Bounds box{{node.box[0][0][k], node.box[0][1][k], node.box[0][2][k]},
                             {node.box[1][0][k], node.box[1][1][k], node.box[1][2][k]}};
            if (k >= static_cast<int>(node.children)) {
                EXPECT_EQ(box.lo.x, std::numeric_limits<float>::infinity());
                EXPECT_EQ(box.hi.z, std::numeric_limits<float>::infinity());
                continue;
            }
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(box.lo[a], p.box.lo[a]);
                EXPECT_LE(box.hi[a], p.box.hi[a]);
            }
            if (node.count[k] == 0) {
                stack.push_back({node.child[k], box});
                continue;
            }
            EXPECT_LE(node.count[k], 8u);
            for (std::uint32_t i = node.child[k]; i < node.child[k] + node.count[k]; ++i) {
                const std::uint32_t t = b.binary.order[i];
                ++seen[t];
                for (const std::uint32_t v : b.triangles[t]) {
                    for (int a = 0; a < 3; ++a) {
                        EXPECT_GE(b.positions[v][a], box.lo[a]);
                        EXPECT_LE(b.positions[v][a], box.hi[a]);
                    }
                }
            }
        }
    }
    for (std::size_t t = 0; t < seen.size(); ++t) EXPECT_EQ(seen[t], 1) << "triangle " << t;
    // Eight children a node where the tree is full: far fewer nodes than binary ones.
    EXPECT_LT(nodes * 5, static_cast<int>(b.binary.nodes.size()));
    EXPECT_EQ(tree.bytes().size(), nodes * sizeof(MeshTree::Node));
}

TEST(MeshTree, BoundsAreThoseOfEveryTriangleAndAnEmptyTreeHasNone) {
    const Built b = built(testing::icosphere(2, 3, {1, 2, 3}));
    const MeshTree tree(b.binary.nodes);
    Bounds expected;
    for (const Float3& p : b.positions) expected.grow(to_vec3(p));
    EXPECT_EQ(tree.bounds().lo, expected.lo);
    EXPECT_EQ(tree.bounds().hi, expected.hi);
    EXPECT_NEAR(expected.lo.x, -2, 0.1);
    EXPECT_TRUE(tree.filter_fits());
    const MeshTree none;
    EXPECT_TRUE(none.empty());
    EXPECT_TRUE(none.bounds().empty());
    EXPECT_EQ(none.memory(), 0u);
}

TEST(MeshTree, CoordinatesTooLargeForTheFloatFilterAreFlagged) {
    const Built b = built(testing::icosphere(1, 1e30));
    EXPECT_FALSE(MeshTree(b.binary.nodes).filter_fits());
}

}  // namespace
}  // namespace drt
