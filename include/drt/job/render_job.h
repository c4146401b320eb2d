// One scene's render as the command line runs it: in one process or across an MPI job, resumed
// from and kept in a checkpoint file, and stopped early by a signal. Whatever of that applies,
// the finished image is the bits of a plain render (renderer.h), because every tile is.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <stop_token>
#include <vector>

#include "drt/job/mpi_work.h"
#include "drt/render/renderer.h"
#include "drt/scene/scene.h"

namespace drt {

struct RenderJobOptions {
    int threads = 0;  // per process; 0 = all cores (shared by the job's processes on a machine)
    std::optional<AdaptiveSampling> adaptive;
    // Called now and then with the fraction of the image done, resumed tiles included; only on
    // the leader of an MPI job.
    std::function<void(double)> on_progress;
    // Where finished tiles are kept, with the files the render depends on (the scene file and
    // what it reads) for the checkpoint's fingerprint.
    std::optional<std::filesystem::path> checkpoint;
    std::vector<std::filesystem::path> scene_files;
    std::chrono::duration<double> checkpoint_interval = std::chrono::seconds(30);
    // For tests: stop as a signal would once this many tiles are done, resumed ones included.
    std::optional<std::size_t> stop_after_tiles;
    // Hand the costliest tiles out first (costly_first, render_context.h); otherwise row by row.
    bool costly_first = true;
    // False when nothing shows the image's error estimate: its calibration is skipped (up to 8 %
    // of the camera samples, render_context.h). A checkpoint keeps the estimate's sums, so a
    // render with one always estimates.
    bool estimate_error = true;
    // Above 1: one pixel of each pixel_block x pixel_block square is rendered, the others left 0
    // (RenderContext): a render to a target error's pilot (progressive.h), which keeps no
    // checkpoint (the checkpoint's fingerprint does not know this).
    int pixel_block = 1;
    // Not empty: a render to a target error's top-up round (progressive.h), which renders only
    // these pixels (indices y * width + x, ascending), each twice (RenderContext); no checkpoint.
    std::vector<std::uint32_t> top_up;
    std::stop_token stop;
    const MpiJob* mpi = nullptr;  // absent: one process
};

struct RenderJobResult {
    RenderResult render;      // the whole image on the leader; empty on the other processes
    std::size_t tiles = 0;    // in the image
    std::size_t resumed = 0;  // taken from the checkpoint
    std::size_t done = 0;     // finished, resumed ones included
    bool complete() const { return done == tiles; }
};

// Collective under MPI. Throws CheckpointError (on every process) when the checkpoint cannot be
// used; when stopped, the checkpoint has been written before this returns. The caller writes
// the image, and removes the checkpoint once the image is safely written.
RenderJobResult run_render_job(const Scene& scene, const RenderJobOptions& options);

}  // namespace drt
