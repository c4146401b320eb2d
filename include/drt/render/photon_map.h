// Caustics from photon maps, progressively (Knaus & Zwicker 2011, "Progressive photon mapping: a
// probabilistic approach"). Pass k of a render is the camera sample index k of every pixel: it
// has its own photon map of Count photons, a pure function of (seed, k), traced from the
// Falloff-1 lights and emitting spheres and meshes (picked by power) through reflective and
// transparent events only and stored where they first reach a diffuse part. Photons are aimed
// at the reflective and transparent objects (a photon first meeting anything else would store
// nothing), their power divided by the density of that aim. A sample gathers from
// its pass's map within the radius r_k, r_k² = r_1² · Π_{j<k} (j + α)/(j + 1) with α = 2/3, so the
// mean over a pixel's samples converges to the exact caustic as Samples grows, as stochastic
// progressive photon mapping's shrinking radius does. Maps are built when a sample first asks for
// them, by one thread while others needing it wait, and kept for the render (render_limits.h
// bounds their memory). The estimate is in the units of the thesis's sum of lights (irradiance
// over π), which the diffuse part multiplies by diffuse·kd.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "drt/accel/bvh.h"
#include "drt/render/render_plan.h"
#include "drt/scene/scene.h"

namespace drt {

// r_k² / r_1² for pass k (0-based): Π_{j=1..k} (j + α)/(j + 1), about k^(α−1) for large k.
double photon_radius2_factor(std::uint32_t pass);

// One stored photon: where it landed, the power it carries (in the units above, times π r²) and
// the direction it arrived along.
struct Photon {
    float position[3];
    float power[3];
    float dir[3];
};

// One pass's photons, in photon order, and a hash grid of cells 2r across over them.
class PhotonPass {
  public:
    PhotonPass() = default;
    PhotonPass(std::vector<Photon> photons, double radius);

    // Caustic light at `point` of a surface whose normal `normal` faces the viewer: the photons
    // within the radius that arrived on that side and lie near its tangent plane.
    Color estimate(const Vec3& point, const Vec3& normal) const;
    double radius() const { return radius_; }

  private:
    std::size_t bucket(std::int64_t x, std::int64_t y, std::int64_t z) const;

    std::vector<Photon> photons_;        // sorted by bucket
    std::vector<std::uint32_t> starts_;  // bucket b's photons are [starts_[b], starts_[b + 1])
    double radius_ = 0, cell_ = 1;
};

class PhotonMaps {
  public:
    // The photon sources and the first pass's radius come from the scene and its plan (whose
    // effects must call for caustics); both and the BVH must outlive the maps.
    PhotonMaps(const Scene& scene, const RenderPlan& plan, const Bvh& bvh);

    // Caustic light at `point` (normal facing the viewer) for a camera sample of pass `pass` of
    // a render of seed `seed`. Safe to call from several threads at once.
    Color caustic(std::uint64_t seed, std::uint32_t pass, const Vec3& point,
                  const Vec3& normal) const;
    // The pass's map, built if it was not yet.
    std::shared_ptr<const PhotonPass> pass(std::uint64_t seed, std::uint32_t pass) const;
    // Photons traced so far, over every pass built.
    std::uint64_t traced() const { return traced_.load(); }

    // The photons of pass `pass` as stored, in photon order (before any grid).
    std::vector<Photon> trace(std::uint64_t seed, std::uint32_t pass) const;

  private:
    struct Source {
        std::size_t emitter;
        double pick;  // its probability
    };
    // A direction from `from` towards one of the targets, and its density per solid angle.
    struct Aim {
        Vec3 dir;
        double pdf;
    };
    Aim aim(const Vec3& from, Vec2 u, double pick) const;
    struct Slot {
        std::once_flag built;
        PhotonPass pass;
    };
    // Photon i of a pass: stored where it first reaches a diffuse part after at least one
    // reflective or transparent event, or not at all.
    bool trace_one(std::uint64_t key, Photon& out) const;

    const Scene& scene_;
    const RenderPlan& plan_;
    const Bvh& bvh_;
    int count_ = 0;
    double radius_ = 0;
    std::vector<Source> sources_;
    std::vector<double> source_cdf_;
    // Balls around every reflective or transparent object (radius infinite: a plane or a moving
    // object, aimed at over the whole sphere of directions): a caustic photon's first event is
    // on one of them, so photons are sent only into the cones they subtend.
    std::vector<Ball> targets_;
    mutable std::mutex mutex_;
    mutable std::map<std::pair<std::uint64_t, std::uint32_t>, std::shared_ptr<Slot>> slots_;
    mutable std::atomic<std::uint64_t> traced_{0};
};

// The first pass's radius drt takes without a Radius attribute: 1/100 of the diagonal of the box
// around the scene's spheres and meshes at time 0 (1 if there are none).
double default_photon_radius(const Scene& scene);
// The first pass's radius: the scene's <Photons Radius>, or the default.
double first_photon_radius(const Scene& scene);

}  // namespace drt
