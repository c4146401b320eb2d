// The `drt` command line (../shared/spec/cli.md): render, batch render, compare, info.
#pragma once

#include <iosfwd>

namespace drt {

// Exit status: 0 done, 1 a render or comparison failed, 2 bad usage, scene or image.
int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace drt
