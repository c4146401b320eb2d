#include "drt/render/path_integrator.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "drt/accel/occluders.h"
#include "drt/render/scattering.h"
#include "drt/sampling/cdf_pick.h"
#include "drt/util/rng.h"

namespace drt {

namespace {

// The path integrator's sampler dimensions: each scattering event (depth d, 0 at the camera ray's
// hit) has its own, so a sampler stratifies every bounce on its own. They lie apart from the
// distributed integrator's (sampler.h); a light's dimension at a depth is light(d, i).
namespace path_dim {
constexpr std::uint32_t kBase = 0x40000000;
enum : std::uint32_t { kLightPick, kLobe, kScatter, kFresnel, kRoulette, kLight, kPerEvent };
constexpr std::uint32_t at(int depth, std::uint32_t kind) {
    return kBase + static_cast<std::uint32_t>(depth) * kPerEvent + kind;
}
constexpr std::uint32_t light(int depth, std::size_t index) {
    return at(depth, kLight) + (static_cast<std::uint32_t>(index) << 16);
}
}  // namespace path_dim

// Veach's power heuristic (exponent 2) for a sample of density `own` against one of `other`,
// both already multiplied by their expected sample counts; written as a ratio so that a huge
// density (a small, distant emitter) cannot overflow.
double power_heuristic(double own, double other) {
    if (!(other > 0)) return 1;
    const double r = other / own;
    return 1 / (1 + r * r);
}

}  // namespace

PathIntegrator::PathIntegrator(const Scene& scene, const RenderPlan& plan, const Bvh& bvh,
                               const Sampler& sampler, Strategy strategy, const PhotonMaps* photons)
    : scene_(scene),
      plan_(plan),
      bvh_(bvh),
      sampler_(sampler),
      strategy_(strategy),
      photons_(photons),
      camera_(scene.camera()) {
    for (const auto& light : scene.lights) {
        any_visible_light_ = any_visible_light_ || light->visible();
        if (!light->is_point()) area_lights_.push_back(light.get());
    }
    expected_emitter_rays_.assign(plan.emitters.size(), 0.0);
    for (std::size_t i = 0; i < plan.emitters.size(); ++i) {
        expected_emitter_rays_[i] = plan.emitter_rays[i];
    }
    // Shared rays: each picks emitter k with probability P_k, so N rays sample it N·P_k times.
    const auto& cdf = plan.light_pick_cdf;
    for (std::size_t j = 0; plan.shared_rays > 0 && j < plan.area_emitters.size(); ++j) {
        const std::size_t k = area_lights_.size() + j;
        const double p = cdf[k] - (k == 0 ? 0.0 : cdf[k - 1]);
        expected_emitter_rays_[plan.area_emitters[j]] += plan.shared_rays * p;
    }
}

void PathIntegrator::sample_pixel(int x, int y, const PixelSample& s, std::span<Color> out,
                                  RayCounts& counts) const {
    const CameraRays rays(camera_, sampler_, plan_, x, y, s, out.size());
    PixelSample sample = s;
    for (std::size_t i = 0; i < out.size(); ++i, ++sample.index) {
        ++counts.camera;
        out[i] = radiance(rays.at(i, sample), sample, counts);
        // The opt-in clamp (biased): the whole sample scaled, so that its colour is kept.
        const double clamp = scene_.settings.clamp;
        if (clamp > 0 && luminance(out[i]) > clamp) out[i] = out[i] * (clamp / luminance(out[i]));
    }
}

Color PathIntegrator::radiance(const Ray& camera_ray, const PixelSample& s,
                               RayCounts& counts) const {
    const Effects& e = plan_.effects;
    const int max_depth = scene_.settings.max_depth;
    Color result;
    Color throughput{1, 1, 1};
    Ray ray = camera_ray;
    // Whether the ray was scattered by a diffuse part: then an emitter it meets was also sampled
    // by next-event estimation from `from`, and `scatter_density` is the density with which this
    // direction was chosen (the part's pick probability included).
    bool after_diffuse = false;
    bool diffuse_seen = false;  // a diffuse event anywhere before
    Vec3 from;
    double scatter_density = 0;
    Leaving leaving;  // the triangle the ray leaves from
    for (int depth = 0;; ++depth) {
        const auto hit = bvh_.intersect(ray, {0, kInfinity}, leaving);
        // The thesis's visible lights are seen as in the distributed integrator; light from them
        // reaches diffuse surfaces by shadow rays alone.
        if (any_visible_light_ && !after_diffuse) {
            if (const Light* seen =
                    first_visible_light(scene_.lights, ray, hit ? hit->t : kInfinity)) {
                return result + throughput * seen->intensity();
            }
        }
        if (!hit && !scene_.environment) return result + throughput * scene_.background;
        if (!hit) {
            // The environment was also sampled by next-event estimation after a diffuse event.
            double weight = 1;
            const auto emitter = plan_.emitters.environment_index();
            if (after_diffuse && emitter && strategy_ == Strategy::kLightOnly) {
                weight = 0;
            } else if (after_diffuse && emitter && strategy_ == Strategy::kMis) {
                const double light =
                    expected_emitter_rays_[*emitter] * scene_.environment->pdf(ray.dir);
                weight = power_heuristic(scatter_density, light);
            }
            return result + throughput * scene_.environment->radiance(ray.dir) * weight;
        }

        const Material& m = hit->object->material();
        const SurfaceHit surface = surface_of(ray, *hit, depth, camera_, scene_.settings.samples);
        const auto [outside, geometric, shading, above] = facing_normals(surface, ray.dir);

        if (m.emits()) {
            double weight = 1;
            const auto emitter =
                after_diffuse ? plan_.emitters.index_of(hit->object) : std::optional<std::size_t>{};
            if (photons_ && diffuse_seen && !after_diffuse &&
                plan_.emitters.index_of(hit->object)) {
                weight = 0;  // diffuse, then only reflective or transparent events: a caustic
            } else if (emitter && strategy_ == Strategy::kLightOnly) {
                weight = 0;
            } else if (emitter && strategy_ == Strategy::kMis) {
                const double light = expected_emitter_rays_[*emitter] *
                                     plan_.emitters.pdf(*emitter, from, surface.point,
                                                        surface.normal, hit->primitive, ray.time);
                weight = power_heuristic(scatter_density, light);
            }
            result += throughput * m.emission * weight;
        }
        if (depth >= max_depth) return result;

        // Each part is picked in proportion to its weight and then carries its own over the
        // pick's probability.
        const Color diffuse_colour = m.diffuse * surface.kd;
        const auto [diffuse_weight, reflect_weight, transmit_weight] = m.part_weights(surface.kd);
        const double total = diffuse_weight + reflect_weight + transmit_weight;
        if (!(total > 0)) return result;
        const double diffuse_pick = diffuse_weight / total;

        if (diffuse_weight > 0) {
            Color light =
                next_event(surface.light_point, above, shading, shadow_leaving(surface, *hit),
                           ray.time, s, depth, diffuse_pick, counts);
            if (photons_) light += photons_->caustic(s.seed, s.pass(), surface.point, geometric);
            result += throughput * diffuse_colour * light;
        }

        // A material of one part (most are) needs no pick: 0 lands in that part as any u would,
        // and a sample not drawn changes no other, since each is a function of its dimension.
        const bool one_part =
            (diffuse_weight > 0) + (reflect_weight > 0) + (transmit_weight > 0) == 1;
        const double pick =
            one_part ? 0.0 : sampler_.get_1d(s, path_dim::at(depth, path_dim::kLobe)) * total;
        const std::uint32_t scatter_dimension = path_dim::at(depth, path_dim::kScatter);
        Vec3 dir;
        if (pick < diffuse_weight) {
            dir = cosine_direction(shading, sampler_.get_2d(s, scatter_dimension));
            const double cosine = lit_cosine(dir, shading, geometric);
            if (cosine == 0) return result;  // below the surface: no light comes from there
            throughput *= diffuse_colour / diffuse_pick;
            after_diffuse = true;
            diffuse_seen = true;
            from = surface.light_point;
            scatter_density = diffuse_pick * cosine / kPi;
            ++counts.diffuse;
        } else if (pick < diffuse_weight + reflect_weight) {
            const double sigma = e.glossy_reflection ? m.sigma() : 0.0;
            dir = perturbed(reflect_above(ray.dir, shading, geometric), sigma, +1, geometric, s,
                            scatter_dimension);
            throughput *= m.reflective * m.ks / (reflect_weight / total);
            after_diffuse = false;
            ++counts.reflection;
        } else {
            const double sigma = m.sigma();
            const double eta = outside ? 1.0 / m.index : m.index;
            const double cos_i = std::max(0.0, -dot(ray.dir, shading));
            const double fresnel = fresnel_dielectric(cos_i, eta);
            // Reflected with probability F, refracted otherwise: F and 1 − F cancel.
            throughput *= m.transmit * m.kt / (transmit_weight / total);
            after_diffuse = false;
            if (sampler_.get_1d(s, path_dim::at(depth, path_dim::kFresnel)) < fresnel) {
                dir = perturbed(reflect_above(ray.dir, shading, geometric),
                                e.glossy_reflection ? sigma : 0.0, +1, geometric, s,
                                scatter_dimension);
                ++counts.reflection;
            } else {
                const auto through = refract_below(ray.dir, shading, geometric, eta);
                if (!through) return result;
                dir = perturbed(*through, e.glossy_refraction ? sigma : 0.0, -1, geometric, s,
                                scatter_dimension);
                ++counts.refraction;
            }
        }

        if (depth + 1 >= kRouletteStart) {
            const double survival = std::min(1.0, max_component(throughput));
            if (!(survival > 0)) return result;
            if (survival < 1) {
                if (sampler_.get_1d(s, path_dim::at(depth, path_dim::kRoulette)) >= survival) {
                    return result;
                }
                throughput = throughput / survival;
            }
        }
        ray = spawn_ray(surface.point, geometric, dir, ray.time);
        leaving = Bvh::leaving(*hit);
    }
}

Vec3 PathIntegrator::perturbed(const Vec3& ideal, double sigma, double side, const Vec3& geometric,
                               const PixelSample& s, std::uint32_t dimension) const {
    if (!(sigma > 0)) return ideal;
    return perturb_on_side(ideal, sigma, side, geometric, sampler_.get_2d(s, dimension),
                           [&](int attempt) {
                               const std::uint64_t h =
                                   hash_of(s.seed, s.pixel, s.index, dimension, s.path, 0, attempt);
                               return Vec2{to_unit(h), to_unit(mix64(h))};
                           });
}

Color PathIntegrator::light_ray(const Light& light, const LightSample& ls, const Vec3& origin,
                                Leaving leaving, const Vec3& geometric, const Vec3& shading,
                                double time, const Occluders& occluders, RayCounts& counts) const {
    const double cosine = lit_cosine(ls.dir, shading, geometric);
    if (cosine == 0) return {};
    ++counts.shadow;
    if (occluders.occluded(bvh_, {origin, ls.dir, time}, {0, ls.distance}, leaving)) return {};
    return light.intensity() * cosine;
}

Color PathIntegrator::emitter_ray(std::size_t emitter, const std::optional<EmitterSample>& drawn,
                                  const Vec3& origin, Leaving leaving, const Vec3& geometric,
                                  const Vec3& shading, double time, double diffuse_pick,
                                  const Occluders& occluders, RayCounts& counts) const {
    const auto reached = reach_emitter(plan_.emitters, bvh_, occluders, emitter, drawn, origin,
                                       leaving, geometric, shading, time, counts);
    if (!reached) return {};
    const auto& [sample, cosine, point_light] = *reached;
    if (point_light) return sample.radiance * cosine;
    const double weight = strategy_ == Strategy::kMis
                              ? power_heuristic(expected_emitter_rays_[emitter] * sample.pdf,
                                                diffuse_pick * cosine / kPi)
                              : 1.0;
    return sample.radiance * (cosine * weight / (kPi * sample.pdf));
}

Color PathIntegrator::next_event(const Vec3& point, const Vec3& geometric, const Vec3& shading,
                                 Leaving leaving, double time, const PixelSample& s, int depth,
                                 double diffuse_pick, RayCounts& counts) const {
    const Vec3 origin = spawn_ray(point, geometric, geometric, time).origin;
    const bool emitters = strategy_ != Strategy::kScatterOnly;
    constexpr int kChunk = 16;
    std::array<Vec2, kChunk> points;
    std::array<LightSample, kChunk> samples;
    Color sum;
    for (std::size_t i = 0; i < scene_.lights.size(); ++i) {
        const int rays = plan_.shadow_rays[i];
        if (rays == 0) continue;
        const Light& light = *scene_.lights[i];
        // What can block this point's rays to the light, found once for all of them, as the
        // distributed integrator finds it (occluders.h): the answers are the tree's.
        const Occluders occluders =
            worth_culling(rays, bvh_) ? Occluders(bvh_, origin, light.extent(), time) : Occluders{};
        // The points come a chunk at a time, so that what a set shares (its key, the light's
        // cone) is worked out once, as in the distributed integrator: the same numbers as one
        // at a time (sampler.h, light.h).
        const std::uint32_t dimension = path_dim::light(depth, i);
        Color light_sum;
        for (int first = 0; first < rays; first += kChunk) {
            const auto n = static_cast<std::size_t>(std::min(kChunk, rays - first));
            sampler_.get_2d_for_rays(s, dimension, rays, first, std::span(points).first(n));
            light.sample(point, std::span<const Vec2>(points).first(n),
                         std::span(samples).first(n));
            for (std::size_t j = 0; j < n; ++j) {
                light_sum += light_ray(light, samples[j], origin, leaving, geometric, shading, time,
                                       occluders, counts);
            }
        }
        sum += light_sum / rays;
    }
    for (std::size_t i = 0; emitters && i < plan_.emitters.size(); ++i) {
        const int rays = plan_.emitter_rays[i];
        if (rays == 0) continue;
        const std::uint32_t dimension = path_dim::light(depth, scene_.lights.size() + i);
        if (rays == 1) {  // the common case, without a set's arrays
            sum += emitter_ray(
                i, plan_.emitters.sample(i, point, sampler_.get_2d(s, dimension), time), origin,
                leaving, geometric, shading, time, diffuse_pick, Occluders{}, counts);
            continue;
        }
        const Occluders occluders = emitter_occluders(plan_.emitters, bvh_, i, rays, origin, time);
        Color emitter_sum;
        for_each_emitter_sample(plan_.emitters, sampler_, s, dimension, i, rays, point, time,
                                [&](const std::optional<EmitterSample>& drawn) {
                                    emitter_sum +=
                                        emitter_ray(i, drawn, origin, leaving, geometric, shading,
                                                    time, diffuse_pick, occluders, counts);
                                });
        sum += emitter_sum / rays;
    }
    if (plan_.shared_rays > 0) {
        // Each ray picks a light or an emitter in proportion to power and is divided by the
        // pick's probability, as in the distributed integrator.
        const int rays = plan_.shared_rays;
        for (int j = 0; j < rays; ++j) {
            Vec2 u = sampler_.get_2d_for_ray(s, path_dim::at(depth, path_dim::kLightPick), j, rays);
            const auto [k, p, rest] = pick_from_cdf(plan_.light_pick_cdf, u.x);
            u.x = rest;
            if (k < area_lights_.size()) {
                const Light& light = *area_lights_[k];
                sum += light_ray(light, light.sample(point, u), origin, leaving, geometric, shading,
                                 time, Occluders{}, counts) /
                       (p * rays);
            } else if (emitters) {
                const std::size_t emitter = plan_.area_emitters[k - area_lights_.size()];
                sum += emitter_ray(emitter, plan_.emitters.sample(emitter, point, u, time), origin,
                                   leaving, geometric, shading, time, diffuse_pick, Occluders{},
                                   counts) /
                       (p * rays);
            }
        }
    }
    return sum;
}

}  // namespace drt
