#include "drt/sampling/sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sampler_checks.h"

namespace drt {
namespace {

using testing::correlation;
using testing::in_unit;

TEST(Sampler, MakeSamplerKnowsExactlyItsNames) {
    const std::vector<std::string> names = sampler_names();
    ASSERT_EQ(names.size(), 3u);
    for (const std::string& name : names) {
        const std::unique_ptr<Sampler> sampler = make_sampler(name);
        ASSERT_NE(sampler, nullptr) << name;
        EXPECT_EQ(sampler->name(), name);
    }
    EXPECT_EQ(make_sampler("random")->name(), "random");
    EXPECT_EQ(make_sampler("stratified")->name(), "stratified");
    EXPECT_EQ(make_sampler("sobol")->name(), "sobol");
    EXPECT_EQ(make_sampler(""), nullptr);
    EXPECT_EQ(make_sampler("Stratified"), nullptr);
    EXPECT_EQ(make_sampler("halton"), nullptr);
    EXPECT_EQ(make_sampler("Sobol"), nullptr);
}

// Every coordinate of a sample takes part: changing any one of seed, pixel, index, dimension or
// branch changes the numbers (a coordinate left out of a key would repeat numbers across pixels,
// samples or rays).
TEST(Sampler, EveryCoordinateOfASampleChangesItsNumbers) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        const PixelSample s{12345, 678, 3, 16, 0};
        PixelSample seed = s, pixel = s, index = s;
        ++seed.seed, ++pixel.pixel, ++index.index;
        const PixelSample branch = s.branch(1, 0);
        const std::uint32_t d = dim::bounce(1, dim::kGlossReflect);
        for (const PixelSample& other : {seed, pixel, index, branch}) {
            EXPECT_NE(sampler->get_1d(s, d), sampler->get_1d(other, d)) << name;
            EXPECT_NE(sampler->get_2d(s, d).x, sampler->get_2d(other, d).x) << name;
            EXPECT_NE(sampler->get_2d_in_set(s, d, 2, 5).y,
                      sampler->get_2d_in_set(other, d, 2, 5).y)
                << name;
        }
        EXPECT_NE(sampler->get_1d(s, d), sampler->get_1d(s, d + 1)) << name;
        EXPECT_NE(sampler->get_2d(s, d).x, sampler->get_2d(s, d + 1).x) << name;
        EXPECT_NE(sampler->get_2d_in_set(s, d, 2, 5).x, sampler->get_2d_in_set(s, d + 1, 2, 5).x)
            << name;
    }
}

TEST(Sampler, SetsAtOnceEqualPointsOneByOne) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        for (const std::uint32_t k : {1u, 3u, 8u, 10u}) {
            const PixelSample s{9, 40, 5, 16};
            std::vector<Vec2> points(k - k / 3);
            sampler->get_2d_set(s, dim::light(0, 1), k, k / 3, points);
            for (std::uint32_t j = k / 3; j < k; ++j) {
                const Vec2 p = sampler->get_2d_in_set(s, dim::light(0, 1), j, k);
                EXPECT_EQ(points[j - k / 3].x, p.x) << name << " k " << k << " j " << j;
                EXPECT_EQ(points[j - k / 3].y, p.y) << name << " k " << k << " j " << j;
            }
        }
    }
}

TEST(Sampler, RunsAtOnceEqualPointsOneByOne) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        for (const std::uint32_t count : {1u, 7u, 82u, 100u, 1000u}) {
            const PixelSample first{9, 40, count / 4, count, 77};
            std::vector<Vec2> points(count - count / 4);
            sampler->get_2d_run(first, dim::kPixel, points);
            PixelSample s = first;
            for (const Vec2& point : points) {
                const Vec2 p = sampler->get_2d(s, dim::kPixel);
                EXPECT_EQ(point.x, p.x) << name << " count " << count << " index " << s.index;
                EXPECT_EQ(point.y, p.y) << name << " count " << count << " index " << s.index;
                ++s.index;
            }
        }
    }
}

// RunPoints in the order a renderer asks: sample by sample, each asking for several dimensions
// on several branches, some only now and then, more pairs than it remembers, and samples from
// outside the run.
TEST(Sampler, RunPointsAreExactlyGet2dsInAnyOrder) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        const PixelSample first{3, 123, 16, 48};
        RunPoints run(*sampler, first, 24);
        int asked = 0;
        for (std::uint32_t index = 10; index < 48; ++index) {
            for (std::uint32_t d = 0; d < 40; ++d) {
                const std::uint32_t dimension = dim::bounce(static_cast<int>(d % 8), d / 8);
                if ((index * 7 + d) % (d < 20 ? 1 : 5) != 0) continue;
                PixelSample s = first;
                s.index = index;
                s.path = first.branch(d % 3, d).path;
                const Vec2 expected = sampler->get_2d(s, dimension);
                const Vec2 got = run.get_2d(s, dimension);
                EXPECT_EQ(got.x, expected.x) << name << " index " << index << " d " << d;
                EXPECT_EQ(got.y, expected.y) << name << " index " << index << " d " << d;
                ++asked;
            }
        }
        EXPECT_GT(asked, 900);
        // Another pixel, seed or count is not the run's.
        for (PixelSample other : {PixelSample{3, 124, 20, 48}, PixelSample{4, 123, 20, 48},
                                  PixelSample{3, 123, 20, 47}}) {
            const Vec2 expected = sampler->get_2d(other, dim::bounce(0, 2));
            const Vec2 got = run.get_2d(other, dim::bounce(0, 2));
            EXPECT_EQ(got.x, expected.x) << name;
            EXPECT_EQ(got.y, expected.y) << name;
        }
    }
}

// Samplers remember per thread what a dimension of the pixel in hand derives from (its keys, a
// grid's shuffles): the numbers must not depend on which were asked for before, in particular
// not on another seed's, pixel's or branch's of the same dimension, or on another dimension
// that shares its slot (d and d + 64, branches that differ only in high bits).
TEST(Sampler, NumbersDoNotDependOnWhatWasAskedBefore) {
    struct Request {
        PixelSample s;
        std::uint32_t dim;
    };
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        for (const std::uint32_t count : {16u, 300u, 2048u}) {
            std::vector<Request> requests;
            for (const std::uint64_t seed : {1u, 2u}) {
                for (const std::uint32_t pixel : {5u, 6u}) {
                    for (const std::uint64_t path :
                         {std::uint64_t{0}, std::uint64_t{77}, std::uint64_t{1} << 40}) {
                        for (const std::uint32_t dim : {0u, 1u, 2u, 20u, 21u, 84u, 85u}) {
                            for (const std::uint32_t index : {0u, 1u, 7u, count - 1}) {
                                requests.push_back({{seed, pixel, index, count, path}, dim});
                            }
                        }
                    }
                }
            }
            const auto ask = [&](const Request& r) {
                const Vec2 p = sampler->get_2d(r.s, r.dim);
                return std::vector<double>{sampler->get_1d(r.s, r.dim), p.x, p.y};
            };
            std::vector<std::vector<double>> in_order;
            for (const Request& r : requests) in_order.push_back(ask(r));
            // Backwards, then in a stride that interleaves seeds, pixels, branches and dimensions,
            // twice over so that every remembered value is also asked for again.
            for (std::size_t i = requests.size(); i-- > 0;) {
                EXPECT_EQ(ask(requests[i]), in_order[i]) << name << " " << count << " " << i;
            }
            for (int pass = 0; pass < 2; ++pass) {
                for (std::size_t j = 0; j < requests.size(); ++j) {
                    const std::size_t i = j * 37 % requests.size();
                    EXPECT_EQ(ask(requests[i]), in_order[i]) << name << " " << count << " " << i;
                }
            }
        }
    }
}

TEST(Sampler, ValuesLieInTheHalfOpenUnitInterval) {
    for (const std::string& name : sampler_names()) {
        const auto sampler = make_sampler(name);
        for (const std::uint32_t count : {1u, 3u, 16u, 100u}) {
            for (std::uint32_t pixel = 0; pixel < 20; ++pixel) {
                for (std::uint32_t index = 0; index < count; ++index) {
                    const PixelSample s{7, pixel, index, count};
                    for (std::uint32_t d = 0; d < 24; ++d) {
                        ASSERT_TRUE(in_unit(sampler->get_1d(s, d))) << name;
                        const Vec2 p = sampler->get_2d(s, d);
                        ASSERT_TRUE(in_unit(p.x) && in_unit(p.y)) << name;
                        const Vec2 q = sampler->get_2d_in_set(s, d, index % 5, 5);
                        ASSERT_TRUE(in_unit(q.x) && in_unit(q.y)) << name;
                    }
                }
            }
        }
    }
}

TEST(SamplerIndependent, NumbersAreUniform) {
    const IndependentSampler sampler;
    std::vector<double> one, x, y, set;
    for (std::uint32_t i = 0; i < 20000; ++i) {
        const PixelSample s{99, i / 16, i % 16, 16};
        one.push_back(sampler.get_1d(s, 0));
        const Vec2 p = sampler.get_2d(s, 1);
        x.push_back(p.x), y.push_back(p.y);
        set.push_back(sampler.get_2d_in_set(s, 2, i % 3, 3).y);
    }
    EXPECT_TRUE(testing::uniform_by_ks(one));
    EXPECT_TRUE(testing::uniform_by_ks(x));
    EXPECT_TRUE(testing::uniform_by_ks(y));
    EXPECT_TRUE(testing::uniform_by_ks(set));
}

TEST(SamplerIndependent, DimensionsAreDecorrelated) {
    const IndependentSampler sampler;
    std::vector<double> d0, d1, x, y, time, set0, set1;
    for (std::uint32_t i = 0; i < 4096; ++i) {
        // Across the samples of one pixel and across pixels.
        const PixelSample s{3, i / 64, i % 64, 64};
        d0.push_back(sampler.get_1d(s, 0));
        d1.push_back(sampler.get_1d(s, 1));
        const Vec2 p = sampler.get_2d(s, dim::kPixel);
        x.push_back(p.x), y.push_back(p.y);
        time.push_back(sampler.get_1d(s, dim::kTime));
        set0.push_back(sampler.get_2d_in_set(s, 20, 0, 2).x);
        set1.push_back(sampler.get_2d_in_set(s, 20, 1, 2).x);
    }
    // The standard error of a correlation over 4096 pairs is 1/64 = 0.016. (A dimension number is
    // used either as 1-D or as 2-D, so get_1d(s, 0) and get_2d(s, 0).x need not differ.)
    EXPECT_LT(std::abs(correlation(d0, d1)), 0.06);
    EXPECT_LT(std::abs(correlation(x, y)), 0.06);
    EXPECT_LT(std::abs(correlation(time, x)), 0.06);
    EXPECT_LT(std::abs(correlation(set0, set1)), 0.06);
}

}  // namespace
}  // namespace drt
