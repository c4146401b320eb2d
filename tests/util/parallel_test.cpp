// Work on several threads: every thread runs, the caller waits, and the first exception comes
// back to the caller (instead of std::terminate) after the other threads have seen it and ended;
// a fork-join's two halves run at once, an exception from either coming back the same way.
#include "drt/util/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

namespace drt {
namespace {

using namespace std::chrono_literals;

// Spins until `failed` is set, for at most a few seconds so that a broken flag fails the test
// instead of hanging it; says whether the flag came.
bool until_failed(const std::atomic<bool>& failed) {
    const auto give_up = std::chrono::steady_clock::now() + 5s;
    while (!failed.load()) {
        if (std::chrono::steady_clock::now() > give_up) return false;
        std::this_thread::sleep_for(100us);
    }
    return true;
}

TEST(RunOnThreads, RunsOnEveryThreadAtOnceWhileTheCallerWaits) {
    for (const int threads : {1, 3}) {
        std::mutex mutex;
        std::set<std::thread::id> ids;
        std::atomic<int> arrived{0};
        run_on_threads(threads, [&](const std::atomic<bool>&) {
            {
                const std::lock_guard lock(mutex);
                ids.insert(std::this_thread::get_id());
            }
            // Every thread waits here for all the others: the test hangs, not passes, if they
            // ran one after another.
            ++arrived;
            while (arrived.load() < threads) std::this_thread::yield();
        });
        EXPECT_EQ(ids.size(), static_cast<std::size_t>(threads));
        EXPECT_EQ(ids.count(std::this_thread::get_id()), 0U);
    }
}

TEST(RunOnThreads, NoThreadsMeansOne) {
    std::atomic<int> calls{0};
    run_on_threads(0, [&](const std::atomic<bool>&) { ++calls; });
    EXPECT_EQ(calls.load(), 1);
}

TEST(RunOnThreads, TheFirstExceptionReachesTheCallerAfterTheOthersSawIt) {
    std::atomic<int> next{0}, saw{0};
    try {
        run_on_threads(4, [&](const std::atomic<bool>& failed) {
            if (next++ == 0) throw std::runtime_error("first");
            if (until_failed(failed)) ++saw;
            throw std::runtime_error("later");  // after the first: not the one rethrown
        });
        FAIL() << "nothing was rethrown";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "first");
    }
    EXPECT_EQ(saw.load(), 3);
}

TEST(RunOnThreads, WaitingIsCalledMeanwhileAndItsExceptionStopsTheThreads) {
    std::atomic<int> calls{0}, saw{0};
    try {
        run_on_threads(
            2,
            [&](const std::atomic<bool>& failed) {
                if (until_failed(failed)) ++saw;
            },
            [&] {
                if (++calls == 3) throw std::runtime_error("progress");
            },
            1ms);
        FAIL() << "nothing was rethrown";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "progress");
    }
    EXPECT_EQ(calls.load(), 3);
    EXPECT_EQ(saw.load(), 2);
}

TEST(ForkJoin, RunsTheFirstHereAndTheSecondOnAnotherThreadAtOnce) {
    std::thread::id first_on, second_on;
    std::atomic<int> arrived{0};
    // Each waits for the other: the test hangs, not passes, if they ran one after another.
    const auto meet = [&] {
        ++arrived;
        while (arrived.load() < 2) std::this_thread::yield();
    };
    fork_join(
        [&] {
            first_on = std::this_thread::get_id();
            meet();
        },
        [&] {
            second_on = std::this_thread::get_id();
            meet();
        });
    EXPECT_EQ(first_on, std::this_thread::get_id());
    EXPECT_NE(second_on, std::this_thread::get_id());
}

TEST(ForkJoin, AnExceptionFromEitherReachesTheCallerOnceBothHaveEnded) {
    std::atomic<bool> other_ended{false};
    try {
        fork_join([] { throw std::runtime_error("first"); },
                  [&] {
                      std::this_thread::sleep_for(20ms);
                      other_ended = true;
                  });
        FAIL() << "nothing was rethrown";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "first");
        EXPECT_TRUE(other_ended.load());
    }
    other_ended = false;
    try {
        fork_join(
            [&] {
                std::this_thread::sleep_for(20ms);
                other_ended = true;
            },
            [] { throw std::runtime_error("second"); });
        FAIL() << "nothing was rethrown";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "second");
        EXPECT_TRUE(other_ended.load());
    }
    // Both: the first's, the second's dropped.
    try {
        fork_join([] { throw std::runtime_error("first"); },
                  [] { throw std::runtime_error("second"); });
        FAIL() << "nothing was rethrown";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "first");
    }
}

}  // namespace
}  // namespace drt
