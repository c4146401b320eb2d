// A triangle mesh placed in the scene as an Object.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "drt/accel/triangle_mesh.h"
#include "drt/geometry/motion.h"
#include "drt/geometry/object.h"
#include "drt/util/math.h"
#include "drt/util/ray.h"

namespace drt {

// A mesh in the scene: a TriangleMesh translated by T, and moving like a sphere when given more
// translations (T at time 0, the present, then one per time unit into the past). Both sides of
// every triangle are seen; the winding tells outside from inside. Given a part, the object is
// only the triangles of that part (TriangleMesh::parts), and the mesh's other parts are other
// objects.
class Mesh final : public Object {
  public:
    Mesh(std::shared_ptr<const TriangleMesh> mesh, const std::vector<Vec3>& translations,
         const Material& material, SurfaceDetail detail = {},
         std::uint32_t part = MeshShape::kWhole);

    std::optional<Hit> intersect(const Ray& ray, Interval range) const override;
    Shapes shapes() const override {
        return {{}, {}, {MeshShape{mesh_.get(), &path_, part_, bounds_}}};
    }
    double motion_end() const override { return path_.end(); }

    const TriangleMesh& mesh() const { return *mesh_; }
    // The object's part of the mesh (MeshShape::kWhole: all of it).
    std::uint32_t part() const { return part_; }
    // Where the mesh's own origin is at each time.
    const MotionPath& path() const { return path_; }

  protected:
    SurfaceCoordinates locate(const Ray& ray, const Hit& hit, SurfaceHit& surface) const override;
    // The file's `vt` interpolated over the hit triangle where the mesh kept them, else the
    // triangle's own (u, v): the barycentrics (b1, b2) of the hit.
    SurfaceUv surface_uv(const Ray& ray, const Hit& hit, const SurfaceHit& surface) const override;

  private:
    std::shared_ptr<const TriangleMesh> mesh_;
    MotionPath path_;
    std::uint32_t part_;
    Bounds bounds_;  // of the part's triangles, in the mesh's coordinates
};

}  // namespace drt
