// The `drt` command line (docs/usage.md): render, batch render, compare, info.
#pragma once

#include <iosfwd>

namespace drt {

class MpiJob;

// Exit status: 0 done, 1 a render or comparison failed, 2 bad usage, scene or image, 128 + the
// signal for a render interrupted by SIGINT or SIGTERM. `mpi`: the job this process is one of
// when mpirun started it; renders are then shared with the other processes, and only the leader
// writes files and reports.
int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
            const MpiJob* mpi = nullptr);

}  // namespace drt
