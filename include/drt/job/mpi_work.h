// Several processes, on one machine or many, rendering one image (mpirun -n K drt ...): how drt
// knows it was started by mpirun, and the tile exchange behind the TileSource/TileSink seam.
// Rank 0 (the leader) hands tiles out on request and receives every finished tile; each process
// renders what it is given with all its threads. A tile's buffer is the same bits whichever
// process renders it, so the image cannot depend on the number of processes.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "drt/job/transport.h"
#include "drt/render/render_context.h"
#include "drt/render/render_request.h"
#include "drt/render/renderer.h"
#include "drt/render/tile.h"

namespace drt {

// True when a launcher started this process as one of a job: Open MPI's mpirun sets
// OMPI_COMM_WORLD_SIZE, PMIx launchers (Open MPI, Slurm's srun --mpi=pmix) PMIX_RANK, MPICH's
// hydra and other PMI launchers PMI_RANK. drt starts MPI only then, so a drt run without mpirun
// costs and prints exactly what it did before MPI existed.
bool launched_by_mpirun(const std::function<const char*(const char*)>& getenv = std::getenv);

// True when Open MPI's mpirun bound this process to CPUs by its own default (to one core each
// for up to two processes, to a socket beyond), not because the user asked for it (--bind-to,
// which mpirun passes on as OMPI_MCA_hwloc_base_binding_policy). That default suits processes of
// one thread; drt's run several (workers, a communication thread, MPI's own), and bound to one
// core they share it: `mpirun -n 1 drt` ran its two workers on one of two cores. MpiJob then
// lets the process's threads run on every CPU the system allows it, as a plain run's do, when
// the binding gave it fewer CPUs than its share of the machine (its cores over the job's
// processes there).
bool bound_by_mpirun_default(const std::function<const char*(const char*)>& getenv = std::getenv);

// What MpiJob::render_tiles did on this process.
struct MpiShare {
    int threads = 0;  // worker threads of this process
    // Leader only: when its queue handed out the last tile (the start of the render's tail), and
    // the finished tiles other processes sent, with the time its communication thread spent
    // receiving them and adding them to the image.
    std::optional<std::chrono::steady_clock::time_point> emptied;
    std::uint64_t messages = 0;
    double receive_seconds = 0, assemble_seconds = 0;
};

// MPI, started for the life of this object; constructed only when launched_by_mpirun().
class MpiJob {
  public:
    // Loads drt_mpi.so from beside the running binary, starts MPI and undoes mpirun's default
    // binding where it leaves the process less than its share (bound_by_mpirun_default). Throws
    // std::runtime_error, saying what to do, when the module is missing or MPI cannot start.
    MpiJob();
    ~MpiJob();
    MpiJob(const MpiJob&) = delete;
    MpiJob& operator=(const MpiJob&) = delete;

    int rank() const { return transport_->rank(); }
    int size() const { return transport_->size(); }
    bool leader() const { return rank() == 0; }
    // Processes of this job on this machine, this one included: they share its cores.
    int local_size() const { return transport_->local_size(); }

    // The worker threads this process runs for `requested` (0: its share of the machine's cores).
    int threads_for(int requested) const;

    // The leader's value, on every process (collective).
    int broadcast(int value) const;
    // The leader's values, on every process (collective): the leader sends them to each.
    std::vector<std::uint32_t> broadcast(std::vector<std::uint32_t> values) const;
    // The highest of every process's value, on every process (collective).
    int highest(int value) const;

    // Renders the tiles `todo` of `request` across all processes (collective). On the leader,
    // every finished tile goes to `sink`; elsewhere `todo` and `sink` are not used. A stop
    // requested on a process ends its share: the leader then hands out nothing more, and
    // another process gives back the tiles it was handed but did not render. Tiles are handed
    // out in the order of `todo`.
    MpiShare render_tiles(const RenderContext& context, const RenderRequest& request,
                          std::vector<Tile> todo, TileSink& sink,
                          const RenderOptions& options) const;

  private:
    // Declared first, so destroyed last: the transport's code lives in the module.
    std::unique_ptr<SharedModule> module_;
    std::unique_ptr<Transport> transport_;
};

}  // namespace drt
