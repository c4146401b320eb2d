// Rendering a scene inside a test: from XML, on two threads, and the image's mean.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "drt/render/renderer.h"
#include "drt/scene/scene_loader.h"

namespace drt::testing {

inline Scene from_xml(const std::string& xml) {
    return load_scene_from_string(xml, "test.xml").scene;
}

// Two threads, so that every render in a test also crosses threads.
inline RenderResult render_with(const Scene& scene, int threads = 2) {
    RenderOptions options;
    options.threads = threads;
    return render(scene, options);
}

inline Color image_mean(const Image& image) {
    Color sum;
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) sum += image.at(x, y);
    }
    return sum / (double(image.width) * image.height);
}

// Each channel within `tolerance` of the expected value, relatively.
inline void expect_relative(const Color& got, const Color& expected, double tolerance,
                            const std::string& what) {
    EXPECT_NEAR(got.r, expected.r, tolerance * expected.r) << what;
    EXPECT_NEAR(got.g, expected.g, tolerance * expected.g) << what;
    EXPECT_NEAR(got.b, expected.b, tolerance * expected.b) << what;
}

}  // namespace drt::testing
