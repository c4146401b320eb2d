#include <iostream>
#include <optional>

#include "drt/cli/cli.h"
#include "drt/job/mpi_work.h"
#include "drt/util/interrupt.h"

int main(int argc, char** argv) {
    drt::install_interrupt_handlers();
    // MPI starts only under mpirun (mpi_work.h): a plain run pays nothing for it.
    std::optional<drt::MpiJob> mpi;
    if (drt::launched_by_mpirun()) {
        try {
            mpi.emplace();
        } catch (const std::exception& e) {
            std::cerr << "drt: " << e.what() << "\n";
            return 2;
        }
    }
    if (mpi && !mpi->leader()) {
        // The leader speaks for the job: the others' messages would repeat its own.
        std::ostream silent(nullptr);
        return drt::run_cli(argc, argv, silent, silent, &*mpi);
    }
    return drt::run_cli(argc, argv, std::cout, std::cerr, mpi ? &*mpi : nullptr);
}
