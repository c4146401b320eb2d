// drt's mesh hierarchy against Embree 3 on the same rays (bench/meshes.sh runs it).
//
// The rays come from a real scene once: its camera's rays (jittered, `--spp` per pixel) and, where
// they first hit a diffuse surface, shadow rays to points of every light, spawned as the renderer
// spawns them. Only the rays that reach the mesh's bounding box are kept, because only those
// would reach its leaf test in a render. The mesh itself is the scene's OBJ file with the scene's
// scale and turn, optionally subdivided (every triangle split into four at its edges' midpoints,
// which keeps the surface and so the rays' meaning). drt and Embree get the same float vertices
// in the same triangle order; camera rays ask for the nearest hit (rtcIntersect1), shadow rays
// for any hit (rtcOccluded1). The two sides alternate, round after round, on the same threads.
//
// Usage: drt_mesh_race SCENE.xml [--subdivide N] [--spp N] [--rounds N] [--threads N]
//                      [--write-obj FILE] [--dump FILE]
// --write-obj writes the (subdivided) mesh in the scene's coordinates, for a render of it.
// --dump writes drt's exact answers, which two versions of the traversal must share.
#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "drt/accel/bvh.h"
#include "drt/accel/mesh.h"
#include "drt/io/obj_reader.h"
#include "drt/render/integrator.h"
#include "drt/scene/light.h"
#include "drt/scene/scene_loader.h"
#include "drt/util/rng.h"

namespace {

using namespace drt;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Splits every triangle into four at its edges' midpoints; a midpoint is shared by the two
// triangles of its edge, so a closed mesh stays closed.
ObjMesh subdivided(const ObjMesh& in) {
    ObjMesh out;
    out.positions = in.positions;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;
    const auto middle = [&](std::uint32_t a, std::uint32_t b) {
        const auto key = std::minmax(a, b);
        const auto [it, added] =
            midpoint.try_emplace(key, static_cast<std::uint32_t>(out.positions.size()));
        if (added) out.positions.push_back((in.positions[a] + in.positions[b]) * 0.5);
        return it->second;
    };
    for (std::size_t c = 0; c < in.position_indices.size(); c += 3) {
        const std::uint32_t a = in.position_indices[c], b = in.position_indices[c + 1],
                            d = in.position_indices[c + 2];
        const std::uint32_t ab = middle(a, b), bd = middle(b, d), da = middle(d, a);
        for (const std::uint32_t v : {a, ab, da, ab, b, bd, da, bd, d, ab, bd, da}) {
            out.position_indices.push_back(v);
        }
    }
    out.normal_indices.assign(out.position_indices.size(), ObjMesh::kNoNormal);
    return out;
}

// Writes the mesh moved by `offset`, so that a scene can place it with no transform at all.
void write_obj(const ObjMesh& mesh, const Vec3& offset, const std::filesystem::path& path) {
    std::ofstream file(path);
    char line[128];
    for (const Vec3& p : mesh.positions) {
        const Vec3 q = p + offset;
        std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", q.x, q.y, q.z);
        file << line;
    }
    for (std::size_t c = 0; c < mesh.position_indices.size(); c += 3) {
        file << "f " << mesh.position_indices[c] + 1 << ' ' << mesh.position_indices[c + 1] + 1
             << ' ' << mesh.position_indices[c + 2] + 1 << '\n';
    }
    if (!file) throw std::runtime_error("cannot write " + path.string());
}

struct MeshRay {
    Ray ray;  // in the mesh's own coordinates
    double t_max;
};

struct RaySets {
    std::vector<MeshRay> camera, shadow;
};

bool reaches(const Bounds& box, const Ray& ray, double t_max) {
    double near = 0, far = t_max;
    for (int k = 0; k < 3; ++k) {
        double t0 = (box.lo[k] - ray.origin[k]) / ray.dir[k];
        double t1 = (box.hi[k] - ray.origin[k]) / ray.dir[k];
        if (t0 > t1) std::swap(t0, t1);
        near = std::max(near, t0);
        far = std::min(far, t1);
    }
    return near <= far;
}

RaySets record_rays(const Scene& scene, const Mesh& mesh, int spp) {
    const Bvh bvh(scene.objects);
    const Camera camera = scene.camera();
    const Vec3 origin = mesh.path().at(0);
    Bounds box = mesh.mesh().bounds();
    box = {box.lo - Vec3{1, 1, 1} * 1e-3, box.hi + Vec3{1, 1, 1} * 1e-3};
    RaySets sets;
    const int w = scene.settings.width, h = scene.settings.height;
    const int shadow_per_light = std::max(1, scene.settings.shadow_rays);
    std::uint64_t n = 0;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            for (int s = 0; s < spp; ++s, ++n) {
                const Vec2 film{x + to_unit(hash_of(1, n)), y + to_unit(hash_of(2, n))};
                const Ray ray = camera.generate_ray(film, {0.5, 0.5}, 0);
                if (reaches(box, ray_in_mesh(ray, origin), kInfinity)) {
                    sets.camera.push_back({ray_in_mesh(ray, origin), kInfinity});
                }
                const auto hit = bvh.intersect(ray, {0, kInfinity});
                if (!hit || hit->object->material().diffuse <= 0) continue;
                const SurfaceHit surface = hit->object->surface_at(ray, *hit);
                for (std::size_t l = 0; l < scene.lights.size(); ++l) {
                    for (int k = 0; k < shadow_per_light; ++k) {
                        const std::uint64_t m = (n * 16 + l) * 64 + k;
                        const LightSample ls = scene.lights[l]->sample(
                            surface.light_point, {to_unit(hash_of(3, m)), to_unit(hash_of(4, m))});
                        if (dot(ls.dir, surface.light_normal) <= 0) continue;
                        const Ray shadow =
                            spawn_ray(surface.light_point, surface.normal, ls.dir, 0);
                        const Ray local = ray_in_mesh(shadow, origin);
                        if (reaches(box, local, ls.distance)) {
                            sets.shadow.push_back({local, ls.distance});
                        }
                    }
                }
            }
        }
    }
    return sets;
}

// Runs body(i) for every i < count on `threads` threads, in chunks handed out as they finish.
void parallel_for(std::size_t count, int threads, const std::function<void(std::size_t)>& body) {
    std::atomic<std::size_t> next{0};
    constexpr std::size_t kChunk = 1024;
    const auto work = [&] {
        for (;;) {
            const std::size_t begin = next.fetch_add(kChunk);
            if (begin >= count) return;
            const std::size_t end = std::min(count, begin + kChunk);
            for (std::size_t i = begin; i < end; ++i) body(i);
        }
    };
    std::vector<std::jthread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
}

struct Answer {
    float t;  // nearest hit, or 0/1 for occlusion; -1: none
    std::uint32_t triangle;
};

class EmbreeScene {
  public:
    EmbreeScene(RTCDevice device, const TriangleMesh& mesh) : scene_(rtcNewScene(device)) {
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        const auto positions = mesh.positions();
        auto* vertices = static_cast<float*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                    3 * sizeof(float), positions.size()));
        std::memcpy(vertices, positions.data(), positions.size_bytes());
        const auto triangles = mesh.triangles();
        auto* indices = static_cast<std::uint32_t*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(std::uint32_t), triangles.size()));
        std::memcpy(indices, triangles.data(), triangles.size_bytes());
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene_, geometry);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene_);
    }
    ~EmbreeScene() { rtcReleaseScene(scene_); }
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    Answer intersect(const MeshRay& r) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh{};
        fill(rh.ray, r);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene_, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {-1, 0};
        return {rh.ray.tfar, rh.hit.primID};
    }
    bool occluded(const MeshRay& r) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay ray{};
        fill(ray, r);
        rtcOccluded1(scene_, &context, &ray);
        return ray.tfar < 0;
    }

  private:
    static void fill(RTCRay& ray, const MeshRay& r) {
        ray.org_x = static_cast<float>(r.ray.origin.x);
        ray.org_y = static_cast<float>(r.ray.origin.y);
        ray.org_z = static_cast<float>(r.ray.origin.z);
        ray.dir_x = static_cast<float>(r.ray.dir.x);
        ray.dir_y = static_cast<float>(r.ray.dir.y);
        ray.dir_z = static_cast<float>(r.ray.dir.z);
        ray.tnear = 0;
        ray.tfar = static_cast<float>(std::min(r.t_max, 3e38));
        ray.mask = ~0u;
        ray.flags = 0;
    }
    RTCScene scene_;
};

struct Options {
    std::filesystem::path scene;
    int subdivide = 0, spp = 1, rounds = 5, threads = 2;
    std::filesystem::path write_obj;
    std::filesystem::path dump;
};

Options parse(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const auto value = [&] {
            if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
            return std::string(argv[++i]);
        };
        if (a == "--subdivide")
            o.subdivide = std::stoi(value());
        else if (a == "--spp")
            o.spp = std::stoi(value());
        else if (a == "--rounds")
            o.rounds = std::stoi(value());
        else if (a == "--threads")
            o.threads = std::stoi(value());
        else if (a == "--write-obj")
            o.write_obj = value();
        else if (a == "--dump")
            o.dump = value();
        else
            o.scene = a;
    }
    if (o.scene.empty()) throw std::invalid_argument("usage: drt_mesh_race SCENE.xml [options]");
    return o;
}

const Mesh& first_mesh(const Scene& scene) {
    for (const auto& object : scene.objects) {
        if (const auto* mesh = dynamic_cast<const Mesh*>(object.get())) return *mesh;
    }
    throw std::invalid_argument(scene.path + " has no mesh");
}

void race(const char* kind, const std::vector<MeshRay>& rays, int rounds, int threads,
          const std::function<Answer(const MeshRay&)>& drt_side,
          const std::function<Answer(const MeshRay&)>& embree_side) {
    std::vector<Answer> ours(rays.size()), theirs(rays.size());
    std::vector<double> drt_rates, embree_rates;
    for (int round = 0; round < rounds; ++round) {
        auto start = Clock::now();
        parallel_for(rays.size(), threads, [&](std::size_t i) { ours[i] = drt_side(rays[i]); });
        drt_rates.push_back(rays.size() / seconds_since(start) / 1e6);
        start = Clock::now();
        parallel_for(rays.size(), threads,
                     [&](std::size_t i) { theirs[i] = embree_side(rays[i]); });
        embree_rates.push_back(rays.size() / seconds_since(start) / 1e6);
    }
    std::size_t same = 0, hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Answer &a = ours[i], &b = theirs[i];
        hits += a.t >= 0;
        // A ray through a shared edge or vertex may be given either triangle, at the same t.
        same += (a.t < 0 && b.t < 0) ||
                (a.t >= 0 && b.t >= 0 &&
                 (a.triangle == b.triangle || std::abs(a.t - b.t) <= 1e-5f * std::abs(a.t)));
    }
    const double d = median(drt_rates), e = median(embree_rates);
    std::printf(
        "%-7s %9zu rays  hits %5.1f %%  drt %7.2f Mrays/s  Embree %7.2f Mrays/s  "
        "ratio %.2f  agree %zu/%zu (%.4f %%)\n",
        kind, rays.size(), 100.0 * hits / rays.size(), d, e, d / e, same, rays.size(),
        100.0 * same / rays.size());
}

// drt's exact answers (t, triangle and barycentrics of every camera ray's hit, yes or no for
// every shadow ray), for telling whether two versions of the traversal answer alike.
void dump_answers(const TriangleMesh& mesh, const RaySets& rays,
                  const std::filesystem::path& path) {
    std::ofstream file(path, std::ios::binary);
    const auto put = [&](const auto& value) {
        file.write(reinterpret_cast<const char*>(&value), sizeof value);
    };
    for (const MeshRay& r : rays.camera) {
        const auto hit = mesh.intersect(r.ray, {0, r.t_max});
        put(hit ? hit->t : -1.0);
        put(hit ? hit->triangle : 0u);
        put(hit ? hit->b.b0 : 0.0), put(hit ? hit->b.b1 : 0.0), put(hit ? hit->b.b2 : 0.0);
    }
    for (const MeshRay& r : rays.shadow) put(mesh.occluded(r.ray, {0, r.t_max}));
    if (!file) throw std::runtime_error("cannot write " + path.string());
}

int run(const Options& options) {
    const LoadedScene loaded = load_scene(options.scene);
    const Scene& scene = loaded.scene;
    const Mesh& placed = first_mesh(scene);
    const auto start_rays = Clock::now();
    const RaySets rays = record_rays(scene, placed, options.spp);
    std::printf("recorded %zu camera and %zu shadow rays reaching the mesh's box in %.1f s\n",
                rays.camera.size(), rays.shadow.size(), seconds_since(start_rays));

    // The mesh as placed, subdivided: its float positions about its centre, rebuilt from them.
    ObjMesh obj;
    {
        const auto positions = placed.mesh().positions();
        const auto triangles = placed.mesh().triangles();
        for (const auto& p : positions) obj.positions.push_back({p[0], p[1], p[2]});
        for (const auto& t : triangles) {
            obj.position_indices.insert(obj.position_indices.end(), t.begin(), t.end());
        }
        obj.normal_indices.assign(obj.position_indices.size(), ObjMesh::kNoNormal);
    }
    for (int i = 0; i < options.subdivide; ++i) obj = subdivided(obj);
    if (!options.write_obj.empty()) write_obj(obj, placed.path().at(0), options.write_obj);

    std::vector<double> drt_builds, embree_builds;
    std::unique_ptr<TriangleMesh> mesh;
    RTCDevice device = rtcNewDevice(("threads=" + std::to_string(options.threads)).c_str());
    std::unique_ptr<EmbreeScene> embree;
    for (int round = 0; round < 3; ++round) {
        auto start = Clock::now();
        mesh = std::make_unique<TriangleMesh>(obj, MeshTransform{}, false);
        drt_builds.push_back(seconds_since(start));
        embree.reset();
        start = Clock::now();
        embree = std::make_unique<EmbreeScene>(device, *mesh);
        embree_builds.push_back(seconds_since(start));
    }
    // The rebuilt mesh's origin is the centre of the placed mesh's float positions, a rounding
    // error away from theirs: the rays follow it.
    RaySets local = rays;
    for (auto* set : {&local.camera, &local.shadow}) {
        for (MeshRay& r : *set) r.ray = ray_in_mesh(r.ray, mesh->origin());
    }
    std::printf("mesh: %zu triangles, %.1f bytes/triangle (positions, indices, hierarchy)\n",
                mesh->triangle_count(),
                static_cast<double>(mesh->bytes()) / mesh->triangle_count());
    std::printf(
        "build (median of 3): drt %.3f s (whole TriangleMesh), Embree %.3f s "
        "(rtcCommitScene, %d threads)\n",
        median(drt_builds), median(embree_builds), options.threads);

    const TriangleMesh& m = *mesh;
    const EmbreeScene& e = *embree;
    race(
        "camera", local.camera, options.rounds, options.threads,
        [&](const MeshRay& r) {
            const auto hit = m.intersect(r.ray, {0, r.t_max});
            return hit ? Answer{static_cast<float>(hit->t), hit->triangle} : Answer{-1, 0};
        },
        [&](const MeshRay& r) { return e.intersect(r); });
    race(
        "shadow", local.shadow, options.rounds, options.threads,
        [&](const MeshRay& r) {
            return m.occluded(r.ray, {0, r.t_max}) ? Answer{1, 0} : Answer{-1, 0};
        },
        [&](const MeshRay& r) {
            return e.occluded(r) ? Answer{1, 0} : Answer{-1, 0};
        });
    if (!options.dump.empty()) dump_answers(m, local, options.dump);
    embree.reset();
    rtcReleaseDevice(device);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(parse(argc, argv));
    } catch (const std::exception& error) {
        std::fprintf(stderr, "drt_mesh_race: %s\n", error.what());
        return 2;
    }
}
