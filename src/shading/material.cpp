#include "drt/shading/material.h"

#include <cmath>

#include "drt/util/math.h"

namespace drt {

FresnelSP fresnel_dielectric_sp(double cos_i, double eta) {
    // Matched indices: no interface at all, exactly (also avoids 0/0 at grazing incidence).
    if (eta == 1.0) return {0.0, 0.0};
    cos_i = std::clamp(cos_i, 0.0, 1.0);
    const double sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) return {1.0, 1.0};
    const double cos_t = std::sqrt(1.0 - sin2_t);
    // With eta = n1/n2: r_s = (n1 cos_i - n2 cos_t)/(n1 cos_i + n2 cos_t), divided through by n2.
    const double rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const double rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return {rs * rs, rp * rp};
}

double fresnel_dielectric(double cos_i, double eta) {
    const FresnelSP f = fresnel_dielectric_sp(cos_i, eta);
    return 0.5 * (f.s + f.p);
}

std::optional<Vec3> refract(const Vec3& d, const Vec3& n, double eta) {
    if (eta == 1.0) return d;
    const double cos_i = -dot(d, n);
    const double sin2_t = eta * eta * std::max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) return std::nullopt;
    const double cos_t = std::sqrt(1.0 - sin2_t);
    return normalize(d * eta + n * (eta * cos_i - cos_t));
}

}  // namespace drt
