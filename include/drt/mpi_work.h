// Several processes, on one machine or many, rendering one image (mpirun -n K drt ...): how drt
// knows it was started by mpirun, and the tile exchange behind the TileSource/TileSink seam.
// Rank 0 (the leader) hands tiles out on request and receives every finished tile; each process
// renders what it is given with all its threads. A tile's buffer is the same bits whichever
// process renders it, so the image cannot depend on the number of processes.
#pragma once

#include <cstdlib>
#include <functional>
#include <vector>

#include "drt/render_context.h"
#include "drt/renderer.h"
#include "drt/tile.h"

namespace drt {

// True when a launcher started this process as one of a job: Open MPI's mpirun sets
// OMPI_COMM_WORLD_SIZE, PMIx launchers (Open MPI, Slurm's srun --mpi=pmix) PMIX_RANK, MPICH's
// hydra and other PMI launchers PMI_RANK. drt starts MPI only then, so a drt run without mpirun
// costs and prints exactly what it did before MPI existed.
bool launched_by_mpirun(const std::function<const char*(const char*)>& getenv = std::getenv);

// MPI, started for the life of this object; constructed only when launched_by_mpirun().
class MpiJob {
  public:
    // Throws std::runtime_error when this drt was built without MPI.
    MpiJob();
    ~MpiJob();
    MpiJob(const MpiJob&) = delete;
    MpiJob& operator=(const MpiJob&) = delete;

    int rank() const { return rank_; }
    int size() const { return size_; }
    bool leader() const { return rank_ == 0; }
    // Processes of this job on this machine, this one included: they share its cores.
    int local_size() const { return local_size_; }

    // The leader's value, on every process (collective).
    int leaders(int value) const;
    // The highest of every process's value, on every process (collective).
    int highest(int value) const;

    // Renders the tiles `todo` of `context` across all processes (collective). On the leader,
    // every finished tile goes to `sink`; elsewhere `todo` and `sink` are not used. A stop
    // requested on a process ends its share: the leader then hands out nothing more, and
    // another process gives back the tiles it was handed but did not render. Returns the worker
    // threads of this process.
    int render(const RenderContext& context, std::vector<Tile> todo, TileSink& sink,
               const RenderOptions& options) const;

  private:
    int rank_ = 0, size_ = 1, local_size_ = 1;
};

}  // namespace drt
