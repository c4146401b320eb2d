#include "drt/render/pixel_integrator.h"

#include "drt/render/integrator.h"
#include "drt/render/path_integrator.h"

namespace drt {

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
