#include "drt/render/integrator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <vector>

#include "drt/sampling/cdf_pick.h"
#include "drt/util/rng.h"

namespace drt {

namespace {

// The point of the unit square that Light::sample maps to the light's centre as seen from outside
// (cos θ = 1 in the cone): a light whose area is not sampled acts as a point there.
constexpr Vec2 kLightCentre{0, 0};

}  // namespace

Integrator::Integrator(const Scene& scene, const RenderPlan& plan, const Bvh& bvh,
                       const Sampler& sampler, const PhotonMaps* photons,
                       std::uint64_t whole_tree_rays)
    : scene_(scene),
      plan_(plan),
      bvh_(bvh),
      sampler_(sampler),
      photons_(photons),
      camera_(scene.camera()),
      whole_tree_rays_(whole_tree_rays) {
    for (const auto& light : scene.lights) {
        any_visible_light_ = any_visible_light_ || light->visible();
        if (!light->is_point()) area_lights_.push_back(light.get());
    }
    for (const auto& object : scene.objects) {
        if (object->material().emits() && !object->shapes().planes.empty()) {
            emitting_planes_.push_back(object.get());
        }
    }
}

void Integrator::sample_pixel(int x, int y, const PixelSample& s, std::span<Color> out,
                              RayCounts& counts) const {
    PixelWork work{counts, RunPoints(sampler_, s, static_cast<std::uint32_t>(out.size()))};
    const CameraRays rays(camera_, sampler_, plan_, x, y, s, out.size());
    PixelSample sample = s;
    for (std::size_t i = 0; i < out.size(); ++i, ++sample.index) {
        ++counts.camera;
        work.tree_rays = 0;
        out[i] = radiance(rays.at(i, sample), sample, 0, work);
    }
}

Color Integrator::radiance(const Ray& ray, const PixelSample& s, int depth,
                           RayCounts& counts) const {
    PixelWork work{counts, RunPoints(sampler_, s, 0)};
    return radiance(ray, s, depth, work);
}

Color Integrator::radiance(const Ray& ray, const PixelSample& s, int depth, PixelWork& work,
                           Leaving leaving, double throughput) const {
    const auto hit = bvh_.intersect(ray, {0, kInfinity}, leaving);
    if (any_visible_light_) {
        if (const Light* seen = first_visible_light(scene_.lights, ray, hit ? hit->t : kInfinity))
            return seen->intensity();
    }
    if (!hit) return scene_.environment ? scene_.environment->radiance(ray.dir) : scene_.background;

    const Material& m = hit->object->material();
    const SurfaceHit surface = surface_of(ray, *hit, depth, camera_, scene_.settings.samples);
    // Face both normals towards the incoming ray: planes are two-sided, and a ray inside a
    // sphere sees its inner side.
    const auto [outside, geometric, shading, above] = facing_normals(surface, ray.dir);
    const Leaving from_hit = Bvh::leaving(*hit);

    Color result = m.emission;  // seen from either side
    if (m.has_diffuse()) {
        Color light = scene_.ambient + direct_light(surface.light_point, above, shading,
                                                    shadow_leaving(surface, *hit), ray.time, s,
                                                    depth, work.counts);
        // Light through glass and off mirrors: shadow rays never pass them, so it is counted
        // here only.
        if (photons_) light += photons_->caustic(s.seed, s.pass(), surface.point, geometric);
        result += m.diffuse * surface.kd * light;
    }
    if (depth >= scene_.settings.max_depth) return result;  // deeper rays would contribute black

    const Facing at{surface.point, geometric, shading};
    const Scatterings rays = scatterings(ray.dir, m, at, outside);
    if (work.tree_rays >= whole_tree_rays_) {
        return result + one_branch(rays, m, ray.time, s, depth, work, at, from_hit, throughput);
    }
    if (rays.mirror) {
        const Color weight = m.reflective * m.ks;
        result += weight * scattered(at, from_hit, *rays.mirror, throughput * max_component(weight),
                                     ray.time, s, depth, work);
    }
    if (m.transmits()) {
        const double fresnel = rays.fresnel;
        const double weight = throughput * max_component(m.transmit * m.kt);
        Color glass;
        if (rays.glass_reflection) {
            glass += fresnel * scattered(at, from_hit, *rays.glass_reflection, weight * fresnel,
                                         ray.time, s, depth, work);
        }
        if (rays.refraction) {
            glass +=
                (1.0 - fresnel) * scattered(at, from_hit, *rays.refraction,
                                            weight * (1.0 - fresnel), ray.time, s, depth, work);
        }
        result += m.transmit * m.kt * glass;
    }
    return result;
}

Integrator::Scatterings Integrator::scatterings(const Vec3& dir, const Material& m,
                                                const Facing& at, bool outside) const {
    // The plan says whether directions are perturbed at all, the material by how much.
    const Effects& e = plan_.effects;
    const double sigma = m.sigma();
    Scatterings rays;
    if (m.reflects()) {
        rays.mirror = {reflect_above(dir, at.shading, at.geometric),
                       e.glossy_reflection ? sigma : 0.0, +1, dim::kGlossReflect, false};
    }
    if (m.transmits()) {
        // The medium outside every object is air (index 1), as in the thesis.
        const double eta = outside ? 1.0 / m.index : m.index;
        rays.fresnel = fresnel_dielectric(std::max(0.0, -dot(dir, at.shading)), eta);
        if (rays.fresnel > 0) {
            rays.glass_reflection = {reflect_above(dir, at.shading, at.geometric),
                                     e.glossy_reflection ? sigma : 0.0, +1, dim::kGlassReflect,
                                     false};
        }
        if (rays.fresnel < 1) {
            if (const auto through = refract_below(dir, at.shading, at.geometric, eta)) {
                rays.refraction = {*through, e.glossy_refraction ? sigma : 0.0, -1,
                                   dim::kGlossRefract, true};
            }
        }
    }
    return rays;
}

Color Integrator::one_branch(const Scatterings& rays, const Material& m, double time,
                             const PixelSample& s, int depth, PixelWork& work, const Facing& at,
                             Leaving leaving, double throughput) const {
    // The rays the whole tree would trace here, each with its weight.
    std::array<std::pair<Color, Scatter>, 3> branches;
    int count = 0;
    if (rays.mirror) branches[count++] = {m.reflective * m.ks, *rays.mirror};
    if (rays.glass_reflection) {
        branches[count++] = {m.transmit * m.kt * rays.fresnel, *rays.glass_reflection};
    }
    if (rays.refraction) {
        branches[count++] = {m.transmit * m.kt * (1.0 - rays.fresnel), *rays.refraction};
    }
    double total = 0;
    for (int i = 0; i < count; ++i) total += max_component(branches[i].first);
    if (!(total > 0)) return {};
    // Not a sampler dimension: past the bound is rare, and a hash of where in the tree the
    // pick is keeps it a pure function of (seed, pixel, sample, branch).
    constexpr std::uint64_t kPickSalt = 0x7472656570696b;
    double u = to_unit(hash_of(s.seed, s.pixel, s.index, s.path, depth, kPickSalt)) * total;
    int pick = 0;
    for (; pick + 1 < count && u >= max_component(branches[pick].first); ++pick) {
        u -= max_component(branches[pick].first);
    }
    const auto& [weight, how] = branches[pick];
    const double odds = max_component(weight) / total;
    return weight / odds * scattered(at, leaving, how, throughput * total, time, s, depth, work);
}

Color Integrator::scattered(const Facing& at, Leaving leaving, const Scatter& how,
                            double throughput, double time, const PixelSample& s, int depth,
                            PixelWork& work) const {
    const std::uint32_t dimension = dim::bounce(depth, how.kind);
    const int rays = how.sigma > 0 && depth == 0 ? scene_.settings.glossy_rays : 1;
    Color sum;
    for (int j = 0; j < rays; ++j) {
        // Past the bound every ray, a pending sibling's too, survives Russian roulette with its
        // throughput as the odds and is divided by them: a tree whose weights add up to at most 1
        // at each hit then traces about one chain of rays, whatever MaxDepth is.
        double survival = 1;
        if (work.tree_rays >= whole_tree_rays_ && throughput < 1) {
            constexpr std::uint64_t kRouletteSalt = 0x726f756c65747465;
            survival = throughput;
            const std::uint64_t h =
                hash_of(s.seed, s.pixel, s.index, dimension, s.path, j, kRouletteSalt);
            if (to_unit(h) >= survival) continue;
        }
        Vec3 dir = how.ideal;
        if (how.sigma > 0) {
            const Vec2 u = rays == 1 ? work.points.get_2d(s, dimension)
                                     : sampler_.get_2d_in_set(s, dimension, j, rays);
            dir =
                perturb_on_side(how.ideal, how.sigma, how.side, at.geometric, u, [&](int attempt) {
                    const std::uint64_t h =
                        hash_of(s.seed, s.pixel, s.index, dimension, s.path, j, attempt);
                    return Vec2{to_unit(h), to_unit(mix64(h))};
                });
        }
        ++(how.refraction ? work.counts.refraction : work.counts.reflection);
        ++work.tree_rays;
        const Color light =
            radiance(spawn_ray(at.point, at.geometric, dir, time), s.branch(how.kind, j), depth + 1,
                     work, leaving, throughput / survival);
        sum += survival == 1 ? light : light / survival;
    }
    return rays == 1 ? sum : sum / rays;
}

Color Integrator::light_ray(const Light& light, const LightSample& ls, const Vec3& origin,
                            Leaving leaving, const Vec3& geometric, const Vec3& shading,
                            double time, const Occluders& occluders, RayCounts& counts) const {
    const double cosine = lit_cosine(ls.dir, shading, geometric);
    if (cosine == 0) return {};  // no ray needed
    ++counts.shadow;
    if (occluders.occluded(bvh_, {origin, ls.dir, time}, {0, ls.distance}, leaving)) return {};
    return light.intensity() * cosine;
}

Color Integrator::emitter_ray(std::size_t emitter, const std::optional<EmitterSample>& drawn,
                              const Vec3& origin, Leaving leaving, const Vec3& geometric,
                              const Vec3& shading, double time, const Occluders& occluders,
                              RayCounts& counts) const {
    const auto reached = reach_emitter(plan_.emitters, bvh_, occluders, emitter, drawn, origin,
                                       leaving, geometric, shading, time, counts);
    if (!reached) return {};
    const auto& [sample, cosine, point_light] = *reached;
    // In the units of the thesis's sum of lights, which the diffuse part multiplies by
    // diffuse·kd: irradiance over π, estimated as radiance·cos/pdf.
    if (point_light) return sample.radiance * cosine;
    return sample.radiance * (cosine / (kPi * sample.pdf));
}

Color Integrator::direct_light(const Vec3& point, const Vec3& geometric, const Vec3& shading,
                               Leaving leaving, double time, const PixelSample& s, int depth,
                               RayCounts& counts) const {
    // Every shadow ray leaves on the geometric normal's side, so from the same spawned origin.
    const Vec3 origin = spawn_ray(point, geometric, geometric, time).origin;
    // Points and directions come a chunk at a time, so that what a set shares (its key, the
    // light's cone) is worked out once rather than once per ray.
    constexpr int kChunk = 16;
    std::array<Vec2, kChunk> points;
    std::array<LightSample, kChunk> samples;
    std::array<double, kChunk> cosines;
    Color sum;
    for (std::size_t i = 0; i < scene_.lights.size(); ++i) {
        const int rays = plan_.shadow_rays[i];
        if (rays == 0) continue;
        const Light& light = *scene_.lights[i];
        const std::uint32_t dimension = dim::light(depth, i);
        // What can block this point's rays to this light, found once for all of them when
        // worth_culling says so (occluders.h), which decides how they are shaded below.
        const Occluders occluders =
            worth_culling(rays, bvh_) ? Occluders(bvh_, origin, light.extent(), time) : Occluders{};
        Color light_sum;
        for (int first = 0; first < rays; first += kChunk) {
            const auto n = static_cast<std::size_t>(std::min(kChunk, rays - first));
            if (!plan_.effects.soft_shadows) {
                std::fill_n(points.begin(), n, kLightCentre);
            } else if (rays == 1) {
                points[0] = sampler_.get_2d(s, dimension);
            } else {
                sampler_.get_2d_set(s, dimension, static_cast<std::uint32_t>(rays),
                                    static_cast<std::uint32_t>(first), std::span(points).first(n));
            }
            const auto chunk = std::span<const Vec2>(points).first(n);
            if (occluders.every_ray_reaches()) {
                // Every ray reaches the light: only the cosines are needed.
                light.lit_cosines(point, shading, geometric, chunk, std::span(cosines).first(n));
                double cosine_sum = 0;
                for (std::size_t j = 0; j < n; ++j) {
                    cosine_sum += cosines[j];
                    counts.shadow += cosines[j] > 0;  // a ray is cast only for a lit direction
                }
                light_sum += light.intensity() * cosine_sum;
                continue;
            }
            light.sample(point, chunk, std::span(samples).first(n));
            for (std::size_t j = 0; j < n; ++j) {
                light_sum += light_ray(light, samples[j], origin, leaving, geometric, shading, time,
                                       occluders, counts);
            }
        }
        sum += rays == 1 ? light_sum : light_sum / rays;
    }
    for (std::size_t i = 0; i < plan_.emitters.size(); ++i) {
        const int rays = plan_.emitter_rays[i];
        if (rays == 0) continue;
        const std::uint32_t dimension = dim::light(depth, scene_.lights.size() + i);
        const Occluders occluders = emitter_occluders(plan_.emitters, bvh_, i, rays, origin, time);
        Color emitter_sum;
        for_each_emitter_sample(plan_.emitters, sampler_, s, dimension, i, rays, point, time,
                                [&](const std::optional<EmitterSample>& drawn) {
                                    emitter_sum += emitter_ray(i, drawn, origin, leaving, geometric,
                                                               shading, time, occluders, counts);
                                });
        sum += rays == 1 ? emitter_sum : emitter_sum / rays;
    }
    if (plan_.shared_rays > 0) {
        // Fewer rays than area lights: each ray picks one in proportion to power (stratified
        // over the rays), and its contribution is divided by the pick probability.
        const int rays = plan_.shared_rays;
        const std::uint32_t dimension = dim::bounce(depth, dim::kLightPick);
        for (int j = 0; j < rays; ++j) {
            Vec2 u = sampler_.get_2d_for_ray(s, dimension, j, rays);
            const auto [k, p, rest] = pick_from_cdf(plan_.light_pick_cdf, u.x);
            u.x = rest;
            if (k >= area_lights_.size()) {
                const std::size_t emitter = plan_.area_emitters[k - area_lights_.size()];
                sum += emitter_ray(emitter, plan_.emitters.sample(emitter, point, u, time), origin,
                                   leaving, geometric, shading, time, Occluders{}, counts) /
                       (p * rays);
                continue;
            }
            if (!plan_.effects.soft_shadows) u = kLightCentre;
            const Light& light = *area_lights_[k];
            sum += light_ray(light, light.sample(point, u), origin, leaving, geometric, shading,
                             time, Occluders{}, counts) /
                   (p * rays);
        }
    }
    if (!emitting_planes_.empty()) {
        sum += plane_light(origin, leaving, geometric, shading, time, s, depth, counts);
    }
    return sum;
}

Color Integrator::plane_light(const Vec3& origin, Leaving leaving, const Vec3& geometric,
                              const Vec3& shading, double time, const PixelSample& s, int depth,
                              RayCounts& counts) const {
    // Rays in cosine-weighted directions (density cos θ / π), each bringing what an emitting
    // plane it meets first emits: in direct_light's units (I · cos for a thesis light), a
    // direction of radiance L counts L · cos / (π · density) = L. Only planes count: every other
    // emitter is sampled above, so a ray that meets one adds nothing.
    const int rays = scene_.settings.shadow_rays;
    const std::uint32_t dimension = dim::light(depth, scene_.lights.size() + plan_.emitters.size());
    Color sum;
    for (int j = 0; j < rays; ++j) {
        const Vec2 u = sampler_.get_2d_for_ray(s, dimension, j, rays);
        const Vec3 dir = cosine_direction(shading, u);
        if (lit_cosine(dir, shading, geometric) == 0) continue;
        ++counts.shadow;
        const auto hit = bvh_.intersect({origin, dir, time}, {0, kInfinity}, leaving);
        if (hit && std::ranges::find(emitting_planes_, hit->object) != emitting_planes_.end()) {
            sum += hit->object->material().emission;
        }
    }
    return rays == 1 ? sum : sum / rays;
}

}  // namespace drt
