#include "drt/render/pixel_integrator.h"

#include "drt/render/integrator.h"
#include "drt/render/path_integrator.h"

namespace drt {

CameraRays::CameraRays(const Camera& camera, const Sampler& sampler, const RenderPlan& plan, int x,
                       int y, const PixelSample& s, std::size_t count)
    : camera_(camera),
      sampler_(sampler),
      plan_(plan),
      film_(count, Vec2{x + 0.5, y + 0.5}),
      lens_(count, Vec2{0.5, 0.5}) {
    if (plan.effects.antialiasing) {
        sampler.get_2d_run(s, dim::kPixel, film_);
        for (Vec2& f : film_) f = {x + f.x, y + f.y};
    }
    if (plan.effects.depth_of_field) sampler.get_2d_run(s, dim::kLens, lens_);
}

Ray CameraRays::at(std::size_t i, const PixelSample& sample) const {
    const double time =
        plan_.effects.motion_blur ? sampler_.get_1d(sample, dim::kTime) * plan_.shutter_end : 0.0;
    return camera_.generate_ray(film_[i], lens_[i], time);
}

std::unique_ptr<PixelIntegrator> make_integrator(const Scene& scene, const RenderPlan& plan,
                                                 const Bvh& bvh, const Sampler& sampler,
                                                 const PhotonMaps* photons) {
    if (scene.settings.integrator == IntegratorKind::kPath) {
        return std::make_unique<PathIntegrator>(scene, plan, bvh, sampler,
                                                PathIntegrator::Strategy::kMis, photons);
    }
    return std::make_unique<Integrator>(scene, plan, bvh, sampler, photons);
}

}  // namespace drt
