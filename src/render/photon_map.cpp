#include "drt/render/photon_map.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "drt/accel/triangle_mesh.h"
#include "drt/render/scattering.h"
#include "drt/sampling/cdf_pick.h"
#include "drt/scene/light.h"
#include "drt/util/rng.h"

namespace drt {

namespace {

// α of the radius rule: each pass keeps this share of the previous pass's photons' statistics.
constexpr double kPhotonAlpha = 2.0 / 3.0;

// Keeps the photons' random numbers apart from every camera sample's.
constexpr std::uint64_t kPhotonStream = 0x70686f746f6eULL;

// A photon's numbers: the emission's first, then kPerEvent for each event along its path.
enum : std::uint32_t { kSource, kTime, kEmitA, kEmitB, kEmitC, kEmitD, kSide, kFirstEvent = 8 };
enum : std::uint32_t { kLobe, kFresnel, kRoulette, kScatter, kPerEvent = 8 };

// A photon counts for a gather point only within this share of the radius of its tangent plane:
// the disc a density estimate assumes, which keeps light from leaking round corners.
constexpr double kSlab = 0.5;

double unit(std::uint64_t key, std::uint32_t j) {
    return to_unit(hash_combine(key, j));
}

// As the integrators perturb a direction: redrawn until it leaves on the `side` of the surface.
Vec3 perturbed(const Vec3& ideal, double sigma, double side, const Vec3& geometric,
               std::uint64_t key, std::uint32_t dimension) {
    if (!(sigma > 0)) return ideal;
    const auto draw = [&](int attempt) {
        const std::uint64_t h = hash_combine(key, (std::uint64_t{dimension} << 8) | attempt);
        return Vec2{to_unit(h), to_unit(mix64(h))};
    };
    return perturb_on_side(ideal, sigma, side, geometric, draw(0), draw);
}

std::int64_t cell_of(double x, double cell) {
    // Clamped, so that a tiny radius far from the origin cannot overflow the conversion.
    return static_cast<std::int64_t>(std::clamp(std::floor(x / cell), -1e18, 1e18));
}

}  // namespace

double photon_radius2_factor(std::uint32_t pass) {
    double factor = 1;
    for (std::uint32_t j = 1; j <= pass; ++j) factor *= (j + kPhotonAlpha) / (j + 1.0);
    return factor;
}

double default_photon_radius(const Scene& scene) {
    // The box where caustics form: the objects that bend light and catch it. An emitter (a
    // Falloff-1 sphere light, an emitting mesh) lights the scene from wherever it is, often far
    // off, and would make the radius too wide to show any caustic; it counts only when the scene
    // has nothing else. A plane, unbounded, has an empty box here and never counts.
    std::vector<Bounds> boxes;  // per object, at time 0
    for (const auto& object : scene.objects) {
        Bounds box;
        const Shapes shapes = object->shapes();
        for (const SphereShape& s : shapes.spheres) {
            const Vec3 c = s.path->at(0);
            const Vec3 r{s.radius, s.radius, s.radius};
            box.grow(c - r).grow(c + r);
        }
        for (const MeshShape& m : shapes.meshes) {
            if (m.bounds.empty()) continue;
            const Vec3 origin = m.path->at(0);
            box.grow(origin + m.bounds.lo).grow(origin + m.bounds.hi);
        }
        boxes.push_back(box);
    }
    const auto emits = [&](std::size_t i) { return scene.objects[i]->material().emits(); };
    bool lit_objects = false;
    for (std::size_t i = 0; i < boxes.size(); ++i) lit_objects |= !emits(i) && !boxes[i].empty();
    Bounds bounds;
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        if (!(lit_objects && emits(i))) bounds.grow(boxes[i]);
    }
    if (bounds.empty()) return 1;
    const double diagonal = length(bounds.extent());
    return diagonal > 0 ? diagonal / 100 : 1;
}

// --- one pass ---

std::size_t PhotonPass::bucket(std::int64_t x, std::int64_t y, std::int64_t z) const {
    const auto h = static_cast<std::uint64_t>(x) * 73856093ULL ^
                   static_cast<std::uint64_t>(y) * 19349663ULL ^
                   static_cast<std::uint64_t>(z) * 83492791ULL;
    return static_cast<std::size_t>(mix64(h) & (starts_.size() - 2));
}

PhotonPass::PhotonPass(std::vector<Photon> photons, double radius)
    : radius_(radius), cell_(2 * radius) {
    std::size_t buckets = 1;
    while (buckets < photons.size()) buckets *= 2;
    starts_.assign(buckets + 1, 0);
    std::vector<std::size_t> of(photons.size());
    for (std::size_t i = 0; i < photons.size(); ++i) {
        const float* p = photons[i].position;
        of[i] = bucket(cell_of(p[0], cell_), cell_of(p[1], cell_), cell_of(p[2], cell_));
        ++starts_[of[i] + 1];
    }
    for (std::size_t b = 1; b < starts_.size(); ++b) starts_[b] += starts_[b - 1];
    // In photon order within each bucket: the same map on any number of threads.
    std::vector<std::uint32_t> next(starts_.begin(), starts_.end() - 1);
    photons_.resize(photons.size());
    for (std::size_t i = 0; i < photons.size(); ++i) photons_[next[of[i]]++] = photons[i];
}

Color PhotonPass::estimate(const Vec3& point, const Vec3& normal) const {
    if (photons_.empty()) return {};
    const double r2 = radius_ * radius_;
    const Vec3 r{radius_, radius_, radius_};
    const Vec3 lo = point - r, hi = point + r;
    const std::int64_t x0 = cell_of(lo.x, cell_), x1 = cell_of(hi.x, cell_);
    const std::int64_t y0 = cell_of(lo.y, cell_), y1 = cell_of(hi.y, cell_);
    const std::int64_t z0 = cell_of(lo.z, cell_), z1 = cell_of(hi.z, cell_);
    // 2 cells a side (they are 2r across; 3 where rounding puts an end on a cell's border);
    // two cells may share a bucket, which is then read once.
    std::array<std::size_t, 27> seen{};
    std::size_t seen_count = 0;
    double sum[3] = {0, 0, 0};
    for (std::int64_t x = x0; x <= x1; ++x) {
        for (std::int64_t y = y0; y <= y1; ++y) {
            for (std::int64_t z = z0; z <= z1; ++z) {
                const std::size_t b = bucket(x, y, z);
                const auto end = seen.begin() + static_cast<std::ptrdiff_t>(seen_count);
                if (std::find(seen.begin(), end, b) != end || seen_count == seen.size()) continue;
                seen[seen_count++] = b;
                for (std::uint32_t i = starts_[b]; i < starts_[b + 1]; ++i) {
                    const Photon& p = photons_[i];
                    const Vec3 d{p.position[0] - point.x, p.position[1] - point.y,
                                 p.position[2] - point.z};
                    if (dot(d, d) >= r2) continue;
                    if (std::abs(dot(d, normal)) > kSlab * radius_) continue;
                    if (p.dir[0] * normal.x + p.dir[1] * normal.y + p.dir[2] * normal.z >= 0) {
                        continue;  // arrived on the other side
                    }
                    sum[0] += p.power[0], sum[1] += p.power[1], sum[2] += p.power[2];
                }
            }
        }
    }
    const double area = kPi * r2;
    return Color{sum[0], sum[1], sum[2]} / area;
}

double first_photon_radius(const Scene& scene) {
    const auto& photons = scene.settings.photons;
    return photons && photons->radius > 0 ? photons->radius : default_photon_radius(scene);
}

// --- the passes ---

PhotonMaps::PhotonMaps(const Scene& scene, const RenderPlan& plan, const Bvh& bvh)
    : scene_(scene), plan_(plan), bvh_(bvh) {
    const PhotonSettings settings = scene.settings.photons.value_or(PhotonSettings{});
    count_ = settings.count;
    radius_ = first_photon_radius(scene);
    double total = 0;
    for (std::size_t i = 0; i < plan.emitters.size(); ++i) {
        const Emitters::Emitter& e = plan.emitters[i];
        if (e.kind == Emitters::Kind::kEnvironment || !(e.power > 0)) continue;
        sources_.push_back({i, e.power});
        total += e.power;
    }
    double running = 0;
    for (Source& s : sources_) {
        s.pick /= total;
        running += s.pick;
        source_cdf_.push_back(running);
    }
    if (!source_cdf_.empty()) source_cdf_.back() = 1.0;
    for (const auto& object : scene.objects) {
        const Material& m = object->material();
        if (!m.reflects() && !m.transmits()) continue;
        const Shapes shapes = object->shapes();
        const bool whole = object->moves() || !shapes.planes.empty();
        for (const SphereShape& s : shapes.spheres) {
            targets_.push_back({s.path->at(0), whole ? kInfinity : s.radius});
        }
        for (const MeshShape& mesh : shapes.meshes) {
            const Bounds b = mesh.bounds;
            if (b.empty()) continue;
            targets_.push_back(
                {mesh.path->at(0) + b.centre(), whole ? kInfinity : length(b.extent()) / 2});
        }
        if (!shapes.planes.empty()) targets_.push_back({{}, kInfinity});
    }
}

namespace {

// The cone of directions from `from` towards `ball`: its axis, 1 − cos of its half-angle and
// its solid angle, the whole sphere from inside the ball or for an infinite one.
struct Cone {
    Vec3 axis;
    double cos_max, solid_angle;
};
Cone cone_towards(const Ball& ball, const Vec3& from) {
    if (!(ball.radius < kInfinity)) return {{0, 0, 1}, -1, 4 * kPi};
    const Vec3 to = ball.centre - from;
    const double d2 = dot(to, to);
    const double r2 = ball.radius * ball.radius;
    if (d2 <= r2 * (1 + 1e-9)) return {{0, 0, 1}, -1, 4 * kPi};
    const double one_minus_cos = sphere_cone_one_minus_cos(d2, ball.radius);
    return {to / std::sqrt(d2), 1 - one_minus_cos, 2 * kPi * one_minus_cos};
}

}  // namespace

PhotonMaps::Aim PhotonMaps::aim(const Vec3& from, Vec2 u, double pick) const {
    // A target picked in proportion to its solid angle, then a direction uniform in its cone:
    // the density of a direction is (the cones holding it) / (their solid angles' sum).
    double total = 0;
    for (const Ball& b : targets_) total += cone_towards(b, from).solid_angle;
    double running = 0;
    std::size_t chosen = targets_.size() - 1;
    for (std::size_t i = 0; i < targets_.size(); ++i) {
        running += cone_towards(targets_[i], from).solid_angle;
        if (pick * total < running) {
            chosen = i;
            break;
        }
    }
    const Cone c = cone_towards(targets_[chosen], from);
    const Vec3 dir = normalize(Frame::around(c.axis).to_world(sample_cone(u, c.cos_max)));
    int holding = 0;
    for (const Ball& b : targets_) {
        const Cone other = cone_towards(b, from);
        holding += other.cos_max <= -1 || dot(dir, other.axis) >= other.cos_max ? 1 : 0;
    }
    return {dir, std::max(holding, 1) / total};
}

std::shared_ptr<const PhotonPass> PhotonMaps::pass(std::uint64_t seed, std::uint32_t pass) const {
    std::shared_ptr<Slot> slot;
    {
        const std::lock_guard lock(mutex_);
        // A render asks for one seed at a time (a goal's rounds follow each other): the maps of
        // another are not needed again.
        if (!slots_.empty() && slots_.begin()->first.first != seed) {
            std::erase_if(slots_, [&](const auto& entry) { return entry.first.first != seed; });
        }
        auto& entry = slots_[{seed, pass}];
        if (!entry) entry = std::make_shared<Slot>();
        slot = entry;
    }
    std::call_once(slot->built, [&] {
        slot->pass =
            PhotonPass(trace(seed, pass), radius_ * std::sqrt(photon_radius2_factor(pass)));
        traced_ += static_cast<std::uint64_t>(count_);
    });
    return {slot, &slot->pass};
}

Color PhotonMaps::caustic(std::uint64_t seed, std::uint32_t pass_index, const Vec3& point,
                          const Vec3& normal) const {
    return pass(seed, pass_index)->estimate(point, normal);
}

std::vector<Photon> PhotonMaps::trace(std::uint64_t seed, std::uint32_t pass) const {
    std::vector<Photon> photons;
    if (sources_.empty()) return photons;
    for (int i = 0; i < count_; ++i) {
        Photon p;
        if (trace_one(hash_of(seed, kPhotonStream, pass, i), p)) photons.push_back(p);
    }
    return photons;
}

bool PhotonMaps::trace_one(std::uint64_t key, Photon& out) const {
    const auto u = [key](std::uint32_t j) { return unit(key, j); };
    const std::size_t k = pick_from_cdf(source_cdf_, u(kSource)).index;
    const Source& source = sources_[k];
    const Emitters::Emitter& e = plan_.emitters[source.emitter];
    const double time = plan_.effects.motion_blur ? u(kTime) * plan_.shutter_end : 0.0;
    if (targets_.empty()) return false;
    // The estimate is in the units of the sum of lights, irradiance over π: a photon carries
    // its share of the flux over π. A point light of intensity I (I/r² at r) has 4π·I; a
    // surface of radiance L sends L·cos θ·area/π per unit solid angle.
    const double share = 1 / (double(count_) * source.pick);
    Color power;
    Ray ray;
    switch (e.kind) {
        case Emitters::Kind::kPoint: {
            const Aim a = aim(e.position, {u(kEmitC), u(kEmitD)}, u(kSide));
            power = e.radiance * (share / a.pdf);
            ray = {e.position, a.dir, time};
            break;
        }
        case Emitters::Kind::kSphere: {
            const Vec3 n = sample_cone({u(kEmitA), u(kEmitB)}, -1.0);
            const Vec3 point = e.path->at(time) + n * e.radius;
            const Aim a = aim(point, {u(kEmitC), u(kEmitD)}, u(kSide));
            const double cosine = dot(n, a.dir);
            if (!(cosine > 0)) return false;  // its inside: not traced
            power = e.radiance * (share * cosine * e.area / (kPi * a.pdf));
            ray = spawn_ray(point, n, a.dir, time);
            break;
        }
        case Emitters::Kind::kTriangles: {
            const auto [t, p, v] = pick_from_cdf(e.area_cdf, u(kEmitA));
            // The emitter's own triangles: for a part of a shared mesh, not the mesh's t-th.
            const Emitters::Emitter::Triangle& triangle = e.triangles[t];
            const auto& c = triangle.corners;
            const double su = std::sqrt(v);
            const double b1 = 1 - su, b2 = u(kEmitB) * su;
            const Vec3 point = e.path->at(time) + (c[0] * (1 - b1 - b2) + c[1] * b1 + c[2] * b2);
            const Vec3 face = triangle.normal;
            const Aim a = aim(point, {u(kEmitC), u(kEmitD)}, u(kSide));
            const double cosine = std::abs(dot(face, a.dir));  // both sides emit
            if (!(cosine > 0)) return false;
            power = e.radiance * (share * cosine * e.area / (kPi * a.pdf));
            ray = spawn_ray(point, face, a.dir, time);
            break;
        }
        case Emitters::Kind::kEnvironment:
            return false;
    }

    const Effects& effects = plan_.effects;
    const double start = max_component(power);
    const int max_depth = scene_.settings.max_depth;
    Leaving leaving;  // the triangle the ray leaves from, after the first event
    for (int events = 0;; ++events) {
        const auto hit = bvh_.intersect(ray, {0, kInfinity}, leaving);
        if (!hit) return false;
        const Material& m = hit->object->material();
        const SurfaceHit surface = hit->object->surface_at(ray, *hit);
        const FacingNormals facing = facing_normals(surface, ray.dir);
        const bool outside = facing.outside;
        const Vec3 &geometric = facing.geometric, &shading = facing.shading;

        // The parts are picked as the path integrator picks them; a diffuse pick stores the
        // photon (divided by the pick's probability) and ends it.
        const auto [diffuse_weight, reflect_weight, transmit_weight] = m.part_weights(surface.kd);
        const double total = diffuse_weight + reflect_weight + transmit_weight;
        if (!(total > 0)) return false;
        const std::uint32_t base = kFirstEvent + static_cast<std::uint32_t>(events) * kPerEvent;
        const double pick = u(base + kLobe) * total;
        if (pick < diffuse_weight) {
            if (events == 0) return false;  // direct light: the shadow rays' part
            const Color stored = power / (diffuse_weight / total);
            out = {{float(surface.point.x), float(surface.point.y), float(surface.point.z)},
                   {float(stored.r), float(stored.g), float(stored.b)},
                   {float(ray.dir.x), float(ray.dir.y), float(ray.dir.z)}};
            return true;
        }
        if (events >= max_depth) return false;
        Vec3 dir;
        if (pick < diffuse_weight + reflect_weight) {
            const double sigma = effects.glossy_reflection ? m.sigma() : 0.0;
            dir = perturbed(reflect_above(ray.dir, shading, geometric), sigma, +1, geometric, key,
                            base + kScatter);
            power *= m.reflective * m.ks / (reflect_weight / total);
        } else {
            const double eta = outside ? 1.0 / m.index : m.index;
            const double cos_i = std::max(0.0, -dot(ray.dir, shading));
            const double fresnel = fresnel_dielectric(cos_i, eta);
            power *= m.transmit * m.kt / (transmit_weight / total);
            if (u(base + kFresnel) < fresnel) {
                const double sigma = effects.glossy_reflection ? m.sigma() : 0.0;
                dir = perturbed(reflect_above(ray.dir, shading, geometric), sigma, +1, geometric,
                                key, base + kScatter);
            } else {
                const auto through = refract_below(ray.dir, shading, geometric, eta);
                if (!through) return false;
                const double sigma = effects.glossy_refraction ? m.sigma() : 0.0;
                dir = perturbed(*through, sigma, -1, geometric, key, base + kScatter);
            }
        }
        if (events + 1 >= kRouletteStart) {
            const double survival = std::min(1.0, max_component(power) / start);
            if (!(survival > 0)) return false;
            if (survival < 1) {
                if (u(base + kRoulette) >= survival) return false;
                power = power / survival;
            }
        }
        ray = spawn_ray(surface.point, geometric, dir, time);
        leaving = Bvh::leaving(*hit);
    }
}

}  // namespace drt
