#include "drt/util/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

namespace drt {

namespace {

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};

// A slot is claimed by setting its state from kFree to kWriting, filled, then published as
// kInUse; the handler reads only published slots.
enum SlotState : int { kFree, kWriting, kInUse };
struct Slot {
    std::atomic<int> state{kFree};
    std::array<char, 4096> path{};
};
static_assert(std::atomic<int>::is_always_lock_free);

std::array<Slot, 32> g_temporaries;
std::atomic<int> g_stop_signal{0};
std::atomic<int> g_cooperative{0};

void remove_temporaries() {
    for (Slot& slot : g_temporaries) {
        if (slot.state.load(std::memory_order_acquire) == kInUse) ::unlink(slot.path.data());
    }
}

extern "C" void on_signal(int sig) {
    const int saved_errno = errno;
    remove_temporaries();
    int expected = 0;
    const bool first = g_stop_signal.compare_exchange_strong(expected, sig);
    if (first && g_cooperative.load() > 0) {
        errno = saved_errno;
        return;
    }
    // The default action, so the parent sees the process ended by this signal (status 128 + sig).
    ::signal(sig, SIG_DFL);
    ::raise(sig);
}

}  // namespace

void install_interrupt_handlers() {
    struct sigaction action {};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    for (const int sig : kSignals) sigaddset(&action.sa_mask, sig);
    for (const int sig : kSignals) {
        struct sigaction previous {};
        // A signal ignored by whoever started drt (nohup) stays ignored.
        if (::sigaction(sig, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
        ::sigaction(sig, &action, nullptr);
    }
}

const std::atomic<int>& stop_signal() {
    return g_stop_signal;
}

CooperativeStop::CooperativeStop() {
    g_cooperative.fetch_add(1);
}

CooperativeStop::~CooperativeStop() {
    g_cooperative.fetch_sub(1);
}

TemporaryFileGuard::TemporaryFileGuard(const std::filesystem::path& path) {
    const std::string& text = path.native();
    for (int i = 0; i < static_cast<int>(g_temporaries.size()); ++i) {
        Slot& slot = g_temporaries[i];
        if (text.size() >= slot.path.size()) return;
        int expected = kFree;
        if (!slot.state.compare_exchange_strong(expected, kWriting)) continue;
        std::memcpy(slot.path.data(), text.c_str(), text.size() + 1);
        slot.state.store(kInUse, std::memory_order_release);
        slot_ = i;
        return;
    }
}

TemporaryFileGuard::~TemporaryFileGuard() {
    if (slot_ >= 0) g_temporaries[slot_].state.store(kFree, std::memory_order_release);
}

}  // namespace drt
