// Running the built drt binary (or mpirun with it) as outside users do, for the tests that check
// the command line: exit status, messages and files left behind.
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace drt {

inline std::string read_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

struct Outcome {
    int status = -1;  // the exit status, or 128 + the signal that ended the process
    std::string out, err;
};

// Starts `argv` (argv[0] looked up in PATH) in `cwd` with stdout and stderr going to files
// there (no pipe to fill up) and stdin closed; returns its process id.
inline pid_t start_process(const std::vector<std::string>& argv, const std::filesystem::path& cwd) {
    const std::filesystem::path out_file = cwd / ".drt_stdout", err_file = cwd / ".drt_stderr";
    const pid_t pid = fork();
    if (pid == 0) {
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
inline Outcome finish_process(pid_t pid, const std::filesystem::path& cwd) {
    int wstatus = 0;
    waitpid(pid, &wstatus, 0);
    Outcome r;
    r.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus)
                                  : (WIFSIGNALED(wstatus) ? 128 + WTERMSIG(wstatus) : -1);
    const std::filesystem::path out_file = cwd / ".drt_stdout", err_file = cwd / ".drt_stderr";
    r.out = read_bytes(out_file);
    r.err = read_bytes(err_file);
    std::filesystem::remove(out_file);
    std::filesystem::remove(err_file);
    return r;
}

inline Outcome run_process(const std::vector<std::string>& argv, const std::filesystem::path& cwd) {
    return finish_process(start_process(argv, cwd), cwd);
}

// Runs the drt binary with `args` in `cwd`.
inline Outcome run_drt(const std::vector<std::string>& args, const std::filesystem::path& cwd) {
    std::vector<std::string> argv{DRT_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_process(argv, cwd);
}

}  // namespace drt
