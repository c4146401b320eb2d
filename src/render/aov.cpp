#include "drt/render/aov.h"

#include <algorithm>
#include <stdexcept>

#include "drt/render/scattering.h"

namespace drt {

namespace {

struct AovName {
    Aov aov;
    std::string_view name;
};
constexpr AovName kNames[] = {
    {Aov::kAlbedo, "albedo"}, {Aov::kNormal, "normal"}, {Aov::kDepth, "depth"}};

std::size_t channels_of(Aov aov) {
    return aov == Aov::kDepth ? 1 : 3;
}

}  // namespace

std::vector<Aov> parse_aovs(std::string_view list) {
    std::vector<Aov> aovs;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = list.find(',', start);
        const std::string_view item = list.substr(start, comma - start);
        const auto known = std::find_if(std::begin(kNames), std::end(kNames),
                                        [&](const AovName& n) { return n.name == item; });
        if (known == std::end(kNames)) {
            throw std::invalid_argument("unknown AOV '" + std::string(item) +
                                        "' (known: albedo, normal, depth)");
        }
        if (std::find(aovs.begin(), aovs.end(), known->aov) != aovs.end()) {
            throw std::invalid_argument("AOV '" + std::string(item) + "' named twice");
        }
        aovs.push_back(known->aov);
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return aovs;
}

std::vector<std::string> aov_channel_names(std::span<const Aov> aovs) {
    std::vector<std::string> names;
    for (const Aov aov : aovs) {
        switch (aov) {
            case Aov::kAlbedo:
                names.insert(names.end(), {"albedo.R", "albedo.G", "albedo.B"});
                break;
            case Aov::kNormal:
                names.insert(names.end(), {"normal.X", "normal.Y", "normal.Z"});
                break;
            case Aov::kDepth:
                names.emplace_back("depth.Z");
                break;
        }
    }
    return names;
}

std::size_t aov_channel_count(std::span<const Aov> aovs) {
    std::size_t n = 0;
    for (const Aov aov : aovs) n += channels_of(aov);
    return n;
}

AovTracer::AovTracer(const Scene& scene, const RenderPlan& plan, const Bvh& bvh,
                     const Sampler& sampler)
    : scene_(scene), plan_(plan), bvh_(bvh), sampler_(sampler), camera_(scene.camera()) {
    for (const auto& light : scene.lights) {
        any_visible_light_ = any_visible_light_ || light->visible();
    }
}

void AovTracer::pixel_mean(int x, int y, const PixelSample& s, std::span<const Aov> aovs,
                           std::span<float> out) const {
    // The camera points exactly as the integrators' sample_pixel draws them.
    const Effects& e = plan_.effects;
    std::vector<Vec2> film(s.count, Vec2{x + 0.5, y + 0.5});
    if (e.antialiasing) {
        sampler_.get_2d_run(s, dim::kPixel, film);
        for (Vec2& f : film) f = {x + f.x, y + f.y};
    }
    std::vector<Vec2> lens(s.count, Vec2{0.5, 0.5});
    if (e.depth_of_field) sampler_.get_2d_run(s, dim::kLens, lens);
    Color albedo;
    Vec3 normal;
    double depth = 0;
    PixelSample sample = s;
    for (std::size_t i = 0; i < film.size(); ++i, ++sample.index) {
        const double time =
            e.motion_blur ? sampler_.get_1d(sample, dim::kTime) * plan_.shutter_end : 0.0;
        const Ray ray = camera_.generate_ray(film[i], lens[i], time);
        const auto hit = bvh_.intersect(ray, {0, kInfinity});
        if (!hit) continue;
        if (any_visible_light_) {
            const bool light_first =
                std::any_of(scene_.lights.begin(), scene_.lights.end(), [&](const auto& light) {
                    return light->visible() && light->intersect(ray, {0, hit->t}).has_value();
                });
            if (light_first) continue;
        }
        const SurfaceHit surface = surface_of(ray, *hit, 0, camera_, scene_.settings.samples);
        // Facing the camera as the integrators face it: the side the ray arrives on, and the
        // geometric normal where a bump tilted the shading normal past the viewer.
        const Vec3 shading = facing_normals(surface, ray.dir).shading;
        const Material& m = hit->object->material();
        if (m.has_diffuse()) albedo += m.diffuse * surface.kd;
        normal = normal + shading;
        depth += hit->t;  // camera rays have unit directions
    }
    const double n = static_cast<double>(film.size());
    std::size_t c = 0;
    for (const Aov aov : aovs) {
        switch (aov) {
            case Aov::kAlbedo:
                out[c++] = static_cast<float>(albedo.r / n);
                out[c++] = static_cast<float>(albedo.g / n);
                out[c++] = static_cast<float>(albedo.b / n);
                break;
            case Aov::kNormal:
                out[c++] = static_cast<float>(normal.x / n);
                out[c++] = static_cast<float>(normal.y / n);
                out[c++] = static_cast<float>(normal.z / n);
                break;
            case Aov::kDepth:
                out[c++] = static_cast<float>(depth / n);
                break;
        }
    }
}

}  // namespace drt
