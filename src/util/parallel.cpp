#include "drt/util/parallel.h"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace drt {

void run_on_threads(int threads, const std::function<void(const std::atomic<bool>& failed)>& work,
                    const std::function<void()>& waiting, std::chrono::milliseconds interval) {
    std::atomic<bool> failed{false};
    std::exception_ptr error;  // the first one thrown; guarded by mutex
    std::mutex mutex;
    std::condition_variable finished;
    const int count = std::max(1, threads);
    int running = count;
    const auto fail = [&](std::exception_ptr e) {
        const std::lock_guard lock(mutex);
        if (!error) error = std::move(e);
        failed.store(true);
    };
    {
        std::vector<std::jthread> pool;
        pool.reserve(static_cast<std::size_t>(count));
        for (int i = 0; i < count; ++i) {
            pool.emplace_back([&] {
                try {
                    work(failed);
                } catch (...) {
                    fail(std::current_exception());
                }
                const std::lock_guard lock(mutex);
                if (--running == 0) finished.notify_all();
            });
        }
        try {
            std::unique_lock lock(mutex);
            const auto done = [&] { return running == 0; };
            if (!waiting) finished.wait(lock, done);
            while (!finished.wait_for(lock, interval, done)) {
                lock.unlock();
                waiting();
                lock.lock();
            }
        } catch (...) {  // from waiting: the threads end early too
            fail(std::current_exception());
        }
    }  // joins the threads
    if (error) std::rethrow_exception(error);
}

void fork_join(const std::function<void()>& first, const std::function<void()>& second) {
    std::exception_ptr error;  // second's; read once the thread has been joined
    {
        const std::jthread other([&] {
            try {
                second();
            } catch (...) {
                error = std::current_exception();
            }
        });
        first();  // should it throw, leaving this block joins the thread before the rethrow
    }
    if (error) std::rethrow_exception(error);
}

}  // namespace drt
