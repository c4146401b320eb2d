// One function run on several threads at once (the renderer's workers), or two halves of a
// divided task at once (a mesh's tree build): the caller waits, and an exception thrown on any
// thread comes back to it instead of ending the program through std::terminate.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>

namespace drt {

// Runs `work` on `threads` new threads at once (at least one) and returns when all have
// returned. `work` gets a flag that is set once any of them has thrown, so that the others can
// end early. While it waits, the calling thread calls `waiting` (when given) every `interval`;
// an exception from it sets the flag too. The first exception thrown, on any thread, is
// rethrown here once every thread has ended.
void run_on_threads(int threads, const std::function<void(const std::atomic<bool>& failed)>& work,
                    const std::function<void()>& waiting = nullptr,
                    std::chrono::milliseconds interval = std::chrono::milliseconds(250));

// Runs `second` on one new thread while the calling thread runs `first`, and returns when both
// have returned. An exception from either is rethrown here once both have ended; `first`'s when
// both throw.
void fork_join(const std::function<void()>& first, const std::function<void()>& second);

}  // namespace drt
