// Micro-benchmarks of the kernels every ray runs through: ray-sphere and ray-plane tests, the
// samplers' points, the spherical light's direction sampling and an emitting triangle's.
#include <benchmark/benchmark.h>

#include <array>
#include <vector>

#include "bench_world.h"
#include "drt/geometry/plane.h"
#include "drt/sampling/distribution_2d.h"
#include "drt/sampling/sampler.h"
#include "drt/scene/emitters.h"
#include "drt/scene/light.h"
#include "drt/scene/scene_loader.h"

namespace drt::bench {
namespace {

constexpr int kRays = 4096;  // cycled through, so the branch predictor cannot learn one ray

void BM_RaySphere(benchmark::State& state) {
    const RaySet set(kRays, false);
    const Vec3 centre{500, 500, 500};
    std::size_t i = 0, hits = 0;
    for (auto _ : state) {
        const auto t = intersect_sphere(centre, 200, set.rays[i], {0, kInfinity});
        hits += t.has_value();
        benchmark::DoNotOptimize(t);
        i = (i + 1) % kRays;
    }
    state.counters["hit_fraction"] = double(hits) / double(state.iterations());
}
BENCHMARK(BM_RaySphere);

void BM_RayPlane(benchmark::State& state) {
    const RaySet set(kRays, false);
    Material material;
    const Plane plane({0, 500, 0}, {0, 1, 0}, material);
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(plane.intersect(set.rays[i], {0, kInfinity}));
        i = (i + 1) % kRays;
    }
}
BENCHMARK(BM_RayPlane);

// A pixel's camera sample in 2-D (the antialiasing jitter), for each sampler.
void BM_Sample2d(benchmark::State& state, const char* name) {
    const auto sampler = make_sampler(name);
    PixelSample s{0, 0, 0, 100};
    for (auto _ : state) {
        benchmark::DoNotOptimize(sampler->get_2d(s, dim::kPixel));
        s.index = (s.index + 1) % s.count;
        s.pixel += s.index == 0;
    }
}
BENCHMARK_CAPTURE(BM_Sample2d, random, "random");
BENCHMARK_CAPTURE(BM_Sample2d, stratified, "stratified");

// A whole pixel's camera samples in 2-D at once (range(0) of them), as the integrator draws
// them, per point.
void BM_Sample2dRun(benchmark::State& state, const char* name) {
    const auto sampler = make_sampler(name);
    const auto count = static_cast<std::uint32_t>(state.range(0));
    std::vector<Vec2> points(count);
    PixelSample s{0, 0, 0, count};
    for (auto _ : state) {
        sampler->get_2d_run(s, dim::kPixel, points);
        benchmark::DoNotOptimize(points.data());
        ++s.pixel;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * count));
}
BENCHMARK_CAPTURE(BM_Sample2dRun, random, "random")->Arg(82);
BENCHMARK_CAPTURE(BM_Sample2dRun, stratified, "stratified")->Arg(82);

// The points of one shading point's shadow-ray set (k = range(0) points), per point.
void BM_SampleSet(benchmark::State& state, const char* name) {
    const auto sampler = make_sampler(name);
    const auto k = static_cast<std::uint32_t>(state.range(0));
    PixelSample s{0, 0, 0, 100};
    for (auto _ : state) {
        for (std::uint32_t j = 0; j < k; ++j) {
            benchmark::DoNotOptimize(sampler->get_2d_in_set(s, dim::light(0, 0), j, k));
        }
        s.index = (s.index + 1) % s.count;
        s.pixel += s.index == 0;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * k));
}
BENCHMARK_CAPTURE(BM_SampleSet, stratified, "stratified")->Arg(5)->Arg(9);
BENCHMARK_CAPTURE(BM_SampleSet, random, "random")->Arg(5)->Arg(9);

// The same set at once, as the integrator asks for it.
void BM_SampleSetBatch(benchmark::State& state, const char* name) {
    const auto sampler = make_sampler(name);
    const auto k = static_cast<std::uint32_t>(state.range(0));
    std::array<Vec2, 64> points;
    PixelSample s{0, 0, 0, 100};
    for (auto _ : state) {
        sampler->get_2d_set(s, dim::light(0, 0), k, 0, std::span(points).first(k));
        benchmark::DoNotOptimize(points);
        s.index = (s.index + 1) % s.count;
        s.pixel += s.index == 0;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * k));
}
BENCHMARK_CAPTURE(BM_SampleSetBatch, stratified, "stratified")->Arg(5)->Arg(9);
BENCHMARK_CAPTURE(BM_SampleSetBatch, random, "random")->Arg(5)->Arg(9);

// A direction towards a spherical light from a point outside it, as for every shadow ray.
void BM_SphereLightSample(benchmark::State& state) {
    const SphereLight light({250, 520, 300}, 40, {0.6, 0.6, 0.6}, false);
    std::size_t i = 0;
    for (auto _ : state) {
        const Vec3 x = point_in_cube(6, i % kRays, 400);
        benchmark::DoNotOptimize(light.sample(x, {unit(7, i), unit(8, i)}));
        ++i;
    }
}
BENCHMARK(BM_SphereLightSample);

// Nine directions from one point at once, as for one light's shadow rays at a shading point.
void BM_SphereLightSampleBatch(benchmark::State& state) {
    const SphereLight light({250, 520, 300}, 40, {0.6, 0.6, 0.6}, false);
    std::array<Vec2, 9> u;
    std::array<LightSample, 9> out;
    std::size_t i = 0;
    for (auto _ : state) {
        const Vec3 x = point_in_cube(6, i % kRays, 400);
        for (std::size_t j = 0; j < u.size(); ++j) u[j] = {unit(7, 9 * i + j), unit(8, 9 * i + j)};
        light.sample(x, u, out);
        benchmark::DoNotOptimize(out);
        ++i;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * u.size()));
}
BENCHMARK(BM_SphereLightSampleBatch);

// A direction towards the Cornell box's lamp (one of its two triangles), from points in the
// box below it: by the solid angle the triangle subtends (Arg 0), or from points so far off
// (10⁵ above) that it subtends under 1e-4 sr and is sampled by area (Arg 1).
void BM_EmittingTriangleSample(benchmark::State& state) {
    const Scene scene = load_scene_from_string(R"(<Scene><Camera Ex="0" Ey="0" Ez="-1" Lx="0"
        Ly="0" Lz="0" Fov="40"/><Materials><Lamp ker="17" keg="12" keb="4"/></Materials>
        <Triangle Ax="213" Ay="548.8" Az="227" Bx="213" By="548.8" Bz="332" Cx="343" Cy="548.8"
        Cz="332" Material="Lamp"/></Scene>)",
                                               "bench.xml")
                            .scene;
    const Emitters emitters(scene);
    const double lift = state.range(0) == 0 ? 0.0 : 1e5;
    std::size_t i = 0;
    for (auto _ : state) {
        Vec3 x = point_in_cube(6, i % kRays, 540);
        x.y += lift;
        benchmark::DoNotOptimize(emitters.sample(0, x, {unit(7, i), unit(8, i)}, 0));
        ++i;
    }
}
BENCHMARK(BM_EmittingTriangleSample)->Arg(0)->Arg(1);

// Building the sampling distribution of a full-size 4096 x 2048 environment map (its luminance
// already computed): a cost paid once per render, at start-up.
void BM_Distribution2DBuild(benchmark::State& state) {
    constexpr std::size_t nu = 4096, nv = 2048;
    std::vector<float> f(nu * nv);
    for (std::size_t k = 0; k < f.size(); ++k) f[k] = static_cast<float>((k * 2654435761u) % 1000);
    for (auto _ : state) {
        const Distribution2D d(f, nu, nv);
        benchmark::DoNotOptimize(d.integral());
    }
}
BENCHMARK(BM_Distribution2DBuild)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace drt::bench
