// An image prepared for filtered lookups at texture coordinates: a pyramid of box-filtered
// levels, each half the size of the one before, read bilinearly and blended between the two
// levels around a footprint's width (trilinear filtering, Williams 1983), several times along
// a long footprint (anisotropic filtering).
#pragma once

#include <cstdint>
#include <vector>

#include "drt/io/image.h"
#include "drt/util/color.h"
#include "drt/util/math.h"

namespace drt {

class MipMap {
  public:
    // Level 0 is `image` itself; each further level halves both sides (rounding down, never
    // below 1) with a box filter weighted by exact texel overlap, down to one texel.
    explicit MipMap(const Image& image);

    // Bytes a pyramid over a width x height image takes, for the memory budget before building.
    static std::uint64_t bytes_for(int width, int height);
    std::uint64_t bytes() const;

    int width() const { return levels_.front().width; }
    int height() const { return levels_.front().height; }
    int level_count() const { return static_cast<int>(levels_.size()); }

    // Texture coordinates follow OBJ: (0, 0) is the image's bottom-left corner, v grows upwards,
    // texel (i, j) of a w x h level (j counted from the bottom) has its centre at
    // ((i + ½)/w, (j + ½)/h), and the image repeats outside [0, 1]².
    Color texel(int level, int i, int j) const;
    Color bilinear(int level, Vec2 uv) const;
    // Trilinear: the footprint's `width` in texture coordinates (the larger side of the area one
    // sample stands for) picks the level whose texels are that wide; 0 reads level 0.
    Color filtered(Vec2 uv, double width) const;
    // Anisotropic: a footprint spanned by the steps `dx` and `dy` is read as up to
    // kMaxAnisotropy trilinear probes of the shorter step's width, spread evenly along the
    // longer step (as graphics hardware does), so that a surface seen at a grazing angle is
    // blurred along the view only, not across it too.
    Color filtered(Vec2 uv, Vec2 dx, Vec2 dy) const;
    static constexpr int kMaxAnisotropy = 16;

  private:
    struct Level {
        int width, height;
        std::vector<float> rgb;  // rows bottom to top
    };
    std::vector<Level> levels_;
};

}  // namespace drt
