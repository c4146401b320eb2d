#include "drt/cli/cli.h"

#include <exception>
#include <iostream>
#include <string>

#include "cli_common.h"

namespace drt {

int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err,
            const MpiJob* mpi) {
    // The last guard: every command catches what it expects, and nothing may end in an abort.
    try {
        if (argc >= 2) {
            const std::string command = argv[1];
            // CLI11 takes the program name from argv[0]; hand it "drt compare" and the rest.
            if (command == "compare") return cli::compare_command(argc - 1, argv + 1, out, err);
            if (command == "info") return cli::info_command(argc - 1, argv + 1, out, err);
            if (command == "converge") return cli::converge_command(argc - 1, argv + 1, out, err);
        }
        return cli::render_command(argc, argv, out, err, mpi);
    } catch (const std::exception& e) {
        return cli::report_failure(e, "drt", "", err);
    }
}

}  // namespace drt
