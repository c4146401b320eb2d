// Running the built drt binary (or mpirun with it) as a user does, and the file helpers its
// tests share.
#pragma once

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "temp_folder.h"

namespace drt::test {

namespace fs = std::filesystem;

// The source tree, for its scenes.
inline const fs::path kSourceDir = DRT_SOURCE_DIR;

// Runs a shell command line and returns its standard output.
inline std::string shell_output(const std::string& command) {
    std::string text;
    const std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
    if (!pipe) return text;
    char buf[4096];
    for (std::size_t n; (n = fread(buf, 1, sizeof buf, pipe.get())) > 0;) text.append(buf, n);
    return text;
}

struct Outcome {
    int status = -1;
    std::string out, err;
};

// Starts `argv` (argv[0] looked up in PATH) in `cwd`, stdout and stderr going to files there (no
// pipe to fill up), stdin closed; returns its process id for finish_process. `address_space`,
// when not 0, caps the child's memory (RLIMIT_AS), so that an allocation fails.
inline pid_t start_process(const std::vector<std::string>& argv, const fs::path& cwd,
                           rlim_t address_space = 0) {
    const fs::path out_file = cwd / ".drt_stdout", err_file = cwd / ".drt_stderr";
    const pid_t pid = fork();
    if (pid == 0) {
        const rlimit cap{address_space, address_space};
        if (address_space != 0 && setrlimit(RLIMIT_AS, &cap) != 0) _exit(127);
        const int in = open("/dev/null", O_RDONLY);
        const int out = open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int err = open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (in < 0 || out < 0 || err < 0 || chdir(cwd.c_str()) != 0) _exit(127);
        dup2(in, 0), dup2(out, 1), dup2(err, 2);
        std::vector<char*> args;
        for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        execvp(args[0], args.data());
        _exit(127);
    }
    return pid;
}

// Waits for a process from start_process and collects what it printed.
inline Outcome finish_process(pid_t pid, const fs::path& cwd) {
    int wstatus = 0;
    waitpid(pid, &wstatus, 0);
    Outcome r;
    // -1 for a crash or an abort: no test expects one.
    r.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
    const fs::path out_file = cwd / ".drt_stdout", err_file = cwd / ".drt_stderr";
    r.out = read_bytes(out_file);
    r.err = read_bytes(err_file);
    fs::remove(out_file);
    fs::remove(err_file);
    return r;
}

inline Outcome run_process(const std::vector<std::string>& argv, const fs::path& cwd) {
    return finish_process(start_process(argv, cwd), cwd);
}

// Runs the drt binary with `args` in `cwd` (memory capped as start_process says).
inline Outcome run_drt(const std::vector<std::string>& args, const fs::path& cwd,
                       rlim_t address_space = 0) {
    std::vector<std::string> argv{DRT_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    return finish_process(start_process(argv, cwd, address_space), cwd);
}

}  // namespace drt::test
