// The thesis's material: a weighted sum of a Lambert part, a (glossy) mirror part and a
// (blurry) transparent part. One model covers every material the scene format can express, so
// it is a value type rather than a class hierarchy.
#pragma once

#include <algorithm>
#include <optional>
#include <string>

#include "drt/util/color.h"
#include "drt/util/math.h"

namespace drt {

struct Material {
    std::string name;
    double diffuse = 0;
    Color kd{0.8, 0.8, 0.8};
    double reflective = 0;
    Color ks{1, 1, 1};
    double transmit = 0;
    Color kt{1, 1, 1};
    double index = 1.5;
    std::optional<double> sharpness;  // n; absent = ideal mirror/refraction
    // ker keg keb: radiance emitted from both sides of every surface with this material.
    Color emission{0, 0, 0};

    // Below this angular spread a perturbed direction is indistinguishable from the ideal one.
    static constexpr double kIdealSigma = 1e-4;

    // Angular standard deviation of perturbed directions (radians), 0 when ideal.
    double sigma() const {
        if (!sharpness) return 0;
        const double s = 1.0 / *sharpness;
        return s < kIdealSigma ? 0 : s;
    }
    bool is_glossy() const { return sigma() > 0; }
    bool reflects() const { return reflective > 0 && !is_black(ks); }
    bool transmits() const { return transmit > 0 && !is_black(kt); }
    bool has_diffuse() const { return diffuse > 0; }
    bool emits() const { return !is_black(emission); }

    // What a path (or a photon) picks one part by, in proportion: each part's weight, the
    // luminance of what it passes on (`kd`: the diffuse colour at the point, textured or not);
    // 0 for a part the material does not have.
    struct PartWeights {
        double diffuse, reflect, transmit;
    };
    PartWeights part_weights(const Color& kd) const {
        return {has_diffuse() ? std::max(0.0, luminance(diffuse * kd)) : 0,
                reflects() ? std::max(0.0, reflective * luminance(ks)) : 0,
                transmits() ? std::max(0.0, transmit * luminance(kt)) : 0};
    }
};

// Fraction of unpolarised light reflected at a smooth interface (exact Fresnel equations).
// cos_i: cosine of the angle of incidence (>= 0); eta = n_incident / n_transmitted.
// Returns 1 under total internal reflection.
double fresnel_dielectric(double cos_i, double eta);

// Reflectance of s- and p-polarised light separately (for tests and for the curious).
struct FresnelSP {
    double s, p;
};
FresnelSP fresnel_dielectric_sp(double cos_i, double eta);

// Refracted direction of unit `d` through a surface with unit normal `n` facing the incoming
// side (dot(d, n) < 0), eta = n_incident / n_transmitted; nothing under total internal reflection.
std::optional<Vec3> refract(const Vec3& d, const Vec3& n, double eta);

}  // namespace drt
