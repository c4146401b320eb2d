// The one path for SIGINT, SIGTERM and SIGHUP. A signal removes every registered temporary file
// (with async-signal-safe calls only) and then either ends the process as the signal's default
// action would, or, while a CooperativeStop is alive, only raises the stop flag for the code
// holding it to poll and wind down (a checkpoint, a partial image) before it exits itself.
//
// Signal dispositions belong to the whole process, so this is the one place with process-wide
// state: a fixed table the handler can read without allocating or locking.
#pragma once

#include <atomic>
#include <filesystem>

namespace drt {

// Installs the handlers; call once from main(). Without it signals keep their default actions
// (which is what the tests and fuzz targets that call run_cli directly want).
void install_interrupt_handlers();

// The signal that asked drt to stop (SIGINT, SIGTERM or SIGHUP), or 0. Lock-free, so a render's
// worker threads may poll it as often as they like.
const std::atomic<int>& stop_signal();

// While one is alive, a signal only sets stop_signal(); a second signal ends the process at once.
class CooperativeStop {
  public:
    CooperativeStop();
    ~CooperativeStop();
    CooperativeStop(const CooperativeStop&) = delete;
    CooperativeStop& operator=(const CooperativeStop&) = delete;
};

// Registers a temporary file for removal should a signal arrive, for as long as the guard lives.
// Register before creating the file and let the guard go after it has been renamed or removed, so
// that no moment leaves a temporary file unregistered. A path the table cannot hold (too long,
// or all slots taken) is simply not registered.
class TemporaryFileGuard {
  public:
    explicit TemporaryFileGuard(const std::filesystem::path& path);
    ~TemporaryFileGuard();
    TemporaryFileGuard(const TemporaryFileGuard&) = delete;
    TemporaryFileGuard& operator=(const TemporaryFileGuard&) = delete;

  private:
    int slot_ = -1;
};

}  // namespace drt
