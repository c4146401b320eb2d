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
#include <stdexcept>
#include <stop_token>
#include <string>
#include <vector>

#include "drt/job/mpi_work.h"
#include "drt/render/render_context.h"
#include "drt/render/render_request.h"
#include "drt/render/renderer.h"
#include "drt/scene/scene.h"

namespace drt {

// The processes of an MPI job would render the image differently: each reads the scene and its
// files itself and runs its own drt, and one that read other bytes, took other options or is
// another build would put tiles of another image into this one. The message names a process.
class ProcessesDisagree : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// How a job runs; what it renders is its RenderRequest.
struct RenderJobOptions {
    int threads = 0;  // per process; 0 = all cores (shared by the job's processes on a machine)
    // Called now and then with the fraction of the image done, resumed tiles included; only on
    // the leader of an MPI job.
    std::function<void(double)> on_progress;
    // Where finished tiles are kept, with the files the render depends on (the scene file and
    // what it reads) for the checkpoint's fingerprint. Only for the whole image at the scene's
    // samples and seed, whose error a checkpoint always estimates (it keeps the estimate's sums).
    std::optional<std::filesystem::path> checkpoint;
    std::vector<std::filesystem::path> scene_files;
    // Under MPI, hash_files(scene_files) as this process read them, worked out once a scene by
    // the caller: every process's must be the leader's (a process with a stale copy differs).
    std::uint64_t scene_files_hash = 0;
    std::chrono::duration<double> checkpoint_interval = std::chrono::seconds(30);
    // For tests: stop as a signal would once this many tiles are done, resumed ones included.
    std::optional<std::size_t> stop_after_tiles;
    // Hand the costliest tiles out first (costly_first, render_context.h); otherwise row by row.
    bool costly_first = true;
    std::stop_token stop;
    const MpiJob* mpi = nullptr;  // absent: one process
};

struct RenderJobResult {
    RenderResult render;      // the whole image on the leader; empty on the other processes
    std::size_t tiles = 0;    // in the image
    std::size_t resumed = 0;  // taken from the checkpoint
    std::size_t done = 0;     // finished, resumed ones included
    // Why the checkpoint of a stopped render could not be written (empty: it was, or there is
    // none): the image is still returned, so that the caller can keep what was rendered.
    std::string checkpoint_failure;
    bool complete() const { return done == tiles; }
};

// Sets `scene` up and renders `request` (collective under MPI). Throws CheckpointError (on every
// process) when the checkpoint cannot be used, ProcessesDisagree (on every process) when the
// processes of an MPI job do not render alike (checked first, on a few pixels and the files); when
// stopped, the checkpoint has been written before this returns, or checkpoint_failure says why not.
// The caller writes the image, and removes the checkpoint once the image is safely written.
RenderJobResult run_render_job(const Scene& scene, const RenderRequest& request,
                               const RenderJobOptions& options);

// The same on a scene set up already, for one of several requests against it. Throws
// std::invalid_argument for a checkpoint of any request but the scene's whole image.
RenderJobResult run_render_job(const RenderContext& context, const RenderRequest& request,
                               const RenderJobOptions& options);

}  // namespace drt
