// BVH traversal over 10, 1,000 and 100,000 spheres, still and moving: nearest hit of rays from
// outside the cloud (camera rays) and any hit of segments inside it (shadow rays), per ray; the
// same in the Cornell box's mesh.
#include <benchmark/benchmark.h>

#include "bench_world.h"
#include "drt/accel/bvh.h"
#include "drt/accel/occluders.h"
#include "drt/geometry/plane.h"
#include "drt/scene/scene_loader.h"

namespace drt::bench {
namespace {

constexpr int kRays = 4096;

void BM_BvhNearest(benchmark::State& state) {
    const SphereWorld world(static_cast<int>(state.range(0)), state.range(1) != 0);
    const Bvh bvh(world.objects);
    const RaySet set(kRays, false);
    std::size_t i = 0, hits = 0;
    for (auto _ : state) {
        const auto hit = bvh.intersect(set.rays[i], {0, kInfinity});
        hits += hit.has_value();
        benchmark::DoNotOptimize(hit);
        i = (i + 1) % kRays;
    }
    state.counters["hit_fraction"] = double(hits) / double(state.iterations());
}

void BM_BvhOccluded(benchmark::State& state) {
    const SphereWorld world(static_cast<int>(state.range(0)), state.range(1) != 0);
    const Bvh bvh(world.objects);
    const RaySet set(kRays, true);
    std::size_t i = 0, hits = 0;
    for (auto _ : state) {
        const bool blocked = bvh.occluded(set.rays[i], {0, set.lengths[i]});
        hits += blocked;
        benchmark::DoNotOptimize(blocked);
        i = (i + 1) % kRays;
    }
    state.counters["hit_fraction"] = double(hits) / double(state.iterations());
}

void BM_BvhBuild(benchmark::State& state) {
    const SphereWorld world(static_cast<int>(state.range(0)), state.range(1) != 0);
    for (auto _ : state) {
        const Bvh bvh(world.objects);
        benchmark::DoNotOptimize(bvh.node_count());
    }
}

// Shadow rays in a room of five planes and two spheres from points on the floor to a light of
// radius 40: tested against everything, or against the occluders gathered once per point for
// its nine rays (the gathering included).
void BM_RoomShadowRays(benchmark::State& state) {
    Material material;
    std::vector<std::unique_ptr<Object>> objects;
    objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{0, 1, 0}, material));
    objects.push_back(std::make_unique<Plane>(Vec3{0, 600, 0}, Vec3{0, -1, 0}, material));
    objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 0}, Vec3{1, 0, 0}, material));
    objects.push_back(std::make_unique<Plane>(Vec3{800, 0, 0}, Vec3{-1, 0, 0}, material));
    objects.push_back(std::make_unique<Plane>(Vec3{0, 0, 800}, Vec3{0, 0, -1}, material));
    objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{250, 130, 550}}, 130, material));
    objects.push_back(std::make_unique<Sphere>(std::vector<Vec3>{{530, 120, 300}}, 120, material));
    const Bvh bvh(objects);
    const bool gather = state.range(0) != 0;
    const Ball light{{250, 520, 300}, 40};
    std::size_t i = 0, blocked = 0;
    for (auto _ : state) {
        const Vec3 origin{800 * unit(9, i), 1e-6, 800 * unit(10, i)};
        const Occluders occluders = gather ? Occluders(bvh, origin, light, 0) : Occluders{};
        for (std::size_t j = 0; j < 9; ++j) {
            const Vec3 target =
                light.centre + Vec3{unit(11, 9 * i + j) - 0.5, unit(12, 9 * i + j) - 0.5,
                                    unit(13, 9 * i + j) - 0.5} *
                                   40.0;
            const Vec3 d = target - origin;
            const Ray ray{origin, d / length(d), 0};
            blocked += occluders.occluded(bvh, ray, {0, length(d) - 40});
        }
        ++i;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * 9));
    state.counters["blocked_fraction"] = double(blocked) / double(9 * state.iterations());
}
BENCHMARK(BM_RoomShadowRays)->ArgName("gathered")->Arg(0)->Arg(1);

// The Cornell box of the Cycles race (scenes/gi/cornell-box.xml: one mesh of 38 triangles):
// nearest hits of rays from points inside the box in uniform directions, or shadow rays from
// those points to points on the lamp, stopped short of it as the path integrator stops them.
void BM_CornellBoxRays(benchmark::State& state) {
    const LoadedScene loaded = load_scene(DRT_SOURCE_DIR "/scenes/gi/cornell-box.xml");
    const Bvh bvh(loaded.scene.objects);
    const bool shadow = state.range(0) != 0;
    std::vector<Ray> rays;
    std::vector<double> lengths;
    for (int i = 0; i < kRays; ++i) {
        const Vec3 origin{1 + 554 * unit(14, i), 1 + 546 * unit(15, i), 1 + 557 * unit(16, i)};
        Vec3 d;
        double reach = kInfinity;
        if (shadow) {
            const Vec3 lamp{213 + 130 * unit(17, i), 548.8, 227 + 105 * unit(18, i)};
            d = lamp - origin;
            reach = length(d) * (1 - 1e-5);
        } else {
            const double z = 2 * unit(17, i) - 1, r = std::sqrt(1 - z * z);
            const double phi = 2 * kPi * unit(18, i);
            d = {r * std::cos(phi), r * std::sin(phi), z};
        }
        rays.push_back({origin, d / length(d), 0});
        lengths.push_back(reach);
    }
    std::size_t i = 0, hits = 0;
    for (auto _ : state) {
        const bool hit = shadow ? bvh.occluded(rays[i], {0, lengths[i]})
                                : bvh.intersect(rays[i], {0, kInfinity}).has_value();
        hits += hit;
        benchmark::DoNotOptimize(hit);
        i = (i + 1) % kRays;
    }
    state.counters["hit_fraction"] = double(hits) / double(state.iterations());
}
BENCHMARK(BM_CornellBoxRays)->ArgName("shadow")->Arg(0)->Arg(1);

// Arguments: sphere count, moving (0/1).
void world_sizes(benchmark::internal::Benchmark* b) {
    b->ArgNames({"spheres", "moving"});
    for (int moving : {0, 1}) {
        for (int count : {10, 1000, 100000}) b->Args({count, moving});
    }
}
BENCHMARK(BM_BvhNearest)->Apply(world_sizes);
BENCHMARK(BM_BvhOccluded)->Apply(world_sizes);
BENCHMARK(BM_BvhBuild)->Apply(world_sizes)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace drt::bench
