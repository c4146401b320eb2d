// Image comparison for regression tests: error measures and a false-colour difference image.
#pragma once

#include <string>

#include "drt/io/image.h"

namespace drt {

struct Comparison {
    double rmse = 0;          // over all pixels and channels of the stored values
    double psnr = 0;          // 20 log10(1 / rmse), infinite for equal images
    double ssim = 1;          // mean structural similarity of the luminance, 1 for equal images
    double max_abs = 0;       // largest absolute channel difference, NaN if any is NaN
    long long nonfinite = 0;  // channel values that are NaN or infinite, in either image
};

// Throws ImageError when the sizes differ. A NaN anywhere makes rmse, psnr and max_abs NaN, so
// that no tolerance can accept it.
Comparison compare_images(const Image& a, const Image& b);

// A measure as drt compare prints it (6 significant digits, "inf", "nan"); reports show the same.
std::string format_measure(double value);

// drt compare's line: "rmse=<x> psnr=<y> ssim=<z> max=<w> nonfinite=<n>".
std::string comparison_fields(const Comparison& c);

// A display colour for t in [0, 1]: black, blue, green, yellow, red at equal steps, stored
// linear so that it shows as such once written to an 8-bit (sRGB-encoded) file.
Color false_colour(double t);

// Per-pixel error as a false-colour image (black = equal, through blue and green to red = large).
Image difference_image(const Image& a, const Image& b);

}  // namespace drt
