// How large a render may be. Every limit follows from one stated memory budget, or from the
// integer widths the renderer counts in, and is checked before anything is allocated: a scene or
// option past one is bad input (exit 2), not a render that runs the machine out of memory.
// The "Limits" sections of docs/scene-format.md and docs/usage.md state them for users.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace drt {

// What a render may take: the memory of a modest machine, so that a limit is never the
// reason a scene that fits it fails.
inline constexpr std::uint64_t kMemoryBudget = std::uint64_t{4} << 30;  // 4 GiB

// Memory per pixel at the peak, the final write: the float image (12 bytes), adaptive
// sampling's per-pixel counts (4) and the encoded file in memory (at most 12, a .pfm).
inline constexpr std::uint64_t kBytesPerPixel = 28;
// Memory per AOV value of a pixel (--aov) at the same peak: the float (4 bytes) and its place in
// the encoded .exr (at most 4). A checkpoint holds the float, so it too stays within the budget.
inline constexpr std::uint64_t kBytesPerAovChannel = 8;
// Memory per camera sample of a pixel, in every worker thread: its colour, film and lens points
// (24 + 16 + 16), adaptive sampling's luminance (8), and the remembered glossy points of a run
// (up to 32 dimensions of 16 bytes).
inline constexpr std::uint64_t kBytesPerSample = 576;

// 2^27 pixels (e.g. 16384 x 8192) take 3.5 GiB at 28 bytes each: the largest power of two
// within the budget.
inline constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 27;
// Either side; a 65536 x 2048 image is still within kMaxPixels.
inline constexpr int kMaxImageSide = 65536;
// Whether an image of width x height is past either limit above (the sides checked first, so the
// product cannot overflow).
constexpr bool past_image_limits(std::uint64_t width, std::uint64_t height) {
    return width > kMaxImageSide || height > kMaxImageSide || width * height > kMaxPixels;
}
// What every reader of an image's size says when it is past a limit, naming the side limit
// where a side is past it: "image of WxH pixels exceeds the limit of 134217728 pixels" (or "of
// 65536 pixels a side").
std::string image_limit_message(std::uint64_t width, std::uint64_t height);
// Camera samples per pixel, and shadow or glossy rays per shading point: 2^16 each, so that a
// pixel's sample index times a set's size stays within the samplers' 32-bit index space (and a
// thread's per-sample memory within 36 MiB).
inline constexpr int kMaxSamples = 65536;
inline constexpr int kMaxRaysPerPoint = 65536;
// Bounces: each level of reflection or refraction is a level of recursion on a worker thread's
// stack (about 1 KiB each, several times that in a sanitizer build); 512 keeps the deepest chain
// within 8 MiB stacks with room to spare.
inline constexpr int kMaxDepthLimit = 512;

// Photon maps (<Photons>): every progressive pass keeps its own map for the whole render, one
// pass per camera sample index, each photon stored at most once, at 48 bytes with its share of
// the pass's hash grid. Samples × Count × 48 B may take at most a quarter of the budget; one
// pass at most 2^24 photons (768 MiB).
inline constexpr std::uint64_t kBytesPerPhoton = 48;
inline constexpr std::uint64_t kMaxPhotonBytes = kMemoryBudget / 4;
inline constexpr int kMaxPhotonsPerPass = 1 << 24;

// Worker threads: more than the cores of any machine drt runs on, and each takes per-sample
// memory (kBytesPerSample) of its own.
inline constexpr int kMaxThreads = 1024;
// The worker threads a `threads` option means: itself, or for 0 all the machine's cores (at
// least one).
int worker_threads(int threads);

// A scene file larger than this is refused before it is parsed (the XML tree takes several
// times the text).
inline constexpr std::uint64_t kMaxSceneBytes = std::uint64_t{64} << 20;  // 64 MiB
// An OBJ file larger than this is refused while reading: 1 GiB of text holds about 30 million
// vertices and twice as many triangles, a mesh that already takes most of the budget in memory.
inline constexpr std::uint64_t kMaxObjBytes = std::uint64_t{1} << 30;
// An image file larger than this is refused while reading: a .pfm of kMaxPixels with its header.
inline constexpr std::uint64_t kMaxImageFileBytes = 12 * kMaxPixels + 4096;

// One block of an OpenEXR file as its reader holds it decoded (a block of scan lines, or a tile),
// all channels: the reader allocates it from the header, twice, before it reads any pixel. A
// 65536-pixel row of eight float channels in DWAB's 256-line blocks still fits.
inline constexpr std::uint64_t kMaxExrBlockBytes = std::uint64_t{512} << 20;  // 512 MiB

// The image textures of a scene together, their mip-maps included: half the budget, leaving the
// rest to the rendered image, the meshes and the renderer's own memory.
inline constexpr std::uint64_t kMaxTextureBytes = kMemoryBudget / 2;

}  // namespace drt
