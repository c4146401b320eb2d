#include "drt/mpi_work.h"

#include <stdexcept>
#include <string>
#include <string_view>

#ifdef DRT_HAVE_MPI
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "drt/checkpoint.h"
#endif

namespace drt {

bool launched_by_mpirun(const std::function<const char*(const char*)>& getenv) {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"}) {
        const char* value = getenv(name);
        if (value != nullptr && *value != '\0') return true;
    }
    return false;
}

#ifndef DRT_HAVE_MPI

MpiJob::MpiJob() {
    throw std::runtime_error(
        "started by mpirun, but this drt was built without MPI (install libopenmpi-dev and "
        "rebuild)");
}
MpiJob::~MpiJob() = default;
int MpiJob::leaders(int value) const {
    return value;
}
int MpiJob::highest(int value) const {
    return value;
}
int MpiJob::render(const RenderContext&, std::vector<Tile>, TileSink&, const RenderOptions&) const {
    throw std::logic_error("MPI render without MPI");
}

#else

namespace {

using Clock = std::chrono::steady_clock;

// Message kinds between a process and the leader.
enum Tag : int {
    kRequest = 1,  // to the leader: an int, how many tiles the process would like
    kGrant,        // from the leader: tile indices; none means there is no more work
    kResult,       // to the leader: one finished tile (encode_tile)
    kDone,         // to the leader: tile indices handed out but not rendered; nothing follows
};

// How long the communication thread sleeps when there was nothing to do: short against a
// tile's render time (milliseconds), long enough that polling costs no measurable CPU.
constexpr auto kIdle = std::chrono::microseconds(200);

void check(int code, const char* what) {
    if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

std::vector<std::uint64_t> indices_of(const std::vector<Tile>& tiles) {
    std::vector<std::uint64_t> out;
    out.reserve(tiles.size());
    for (const Tile& t : tiles) out.push_back(t.index);
    return out;
}

void send_indices(const std::vector<std::uint64_t>& indices, int to, int tag) {
    check(MPI_Send(indices.data(), static_cast<int>(indices.size()), MPI_UINT64_T, to, tag,
                   MPI_COMM_WORLD),
          "send");
}

std::vector<std::uint64_t> receive_indices(int from, int tag) {
    MPI_Status status;
    check(MPI_Probe(from, tag, MPI_COMM_WORLD, &status), "probe");
    int count = 0;
    MPI_Get_count(&status, MPI_UINT64_T, &count);
    std::vector<std::uint64_t> indices(static_cast<std::size_t>(count));
    check(
        MPI_Recv(indices.data(), count, MPI_UINT64_T, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
        "receive");
    return indices;
}

// The leader's tiles not handed out yet, shared by its own workers and the processes it serves.
class LeaderQueue final : public TileSource {
  public:
    LeaderQueue(std::vector<Tile> tiles, std::stop_token stop)
        : tiles_(tiles.begin(), tiles.end()), size_(tiles.size()), stop_(std::move(stop)) {}

    std::optional<Tile> next() override {
        const std::lock_guard lock(mutex_);
        if (tiles_.empty() || closed()) return std::nullopt;
        const Tile t = tiles_.front();
        tiles_.pop_front();
        return t;
    }
    std::size_t size() const override { return size_; }

    // Up to `wanted` tiles for another process, fewer near the end so that the last tiles are
    // spread over every process instead of waiting in one's queue.
    std::vector<Tile> take(std::size_t wanted, int processes) {
        const std::lock_guard lock(mutex_);
        if (closed()) return {};
        const std::size_t fair = std::max<std::size_t>(1, tiles_.size() / (2 * processes));
        const std::size_t n = std::min({wanted, fair, tiles_.size()});
        std::vector<Tile> out(tiles_.begin(), tiles_.begin() + static_cast<std::ptrdiff_t>(n));
        tiles_.erase(tiles_.begin(), tiles_.begin() + static_cast<std::ptrdiff_t>(n));
        return out;
    }
    void give_back(const std::vector<Tile>& tiles) {
        const std::lock_guard lock(mutex_);
        tiles_.insert(tiles_.begin(), tiles.begin(), tiles.end());
    }
    bool empty() const {
        const std::lock_guard lock(mutex_);
        return tiles_.empty();
    }
    // After a failure: hand out nothing more.
    void close() { failed_.store(true); }

  private:
    bool closed() const { return failed_.load() || stop_.stop_requested(); }

    mutable std::mutex mutex_;
    std::deque<Tile> tiles_;
    std::size_t size_;
    std::stop_token stop_;
    std::atomic<bool> failed_{false};
};

// The leader's communication thread: answers requests, passes finished tiles to the sink and
// takes back unrendered ones, until every other process has said it is done.
void serve(const RenderContext& context, LeaderQueue& queue, TileSink& sink, int processes,
           std::exception_ptr& error) {
    int active = processes - 1;
    std::vector<unsigned char> bytes;
    while (active > 0) {
        int flag = 0;
        MPI_Status status;
        check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), "probe");
        if (!flag) {
            std::this_thread::sleep_for(kIdle);
            continue;
        }
        const int from = status.MPI_SOURCE;
        switch (status.MPI_TAG) {
            case kRequest: {
                int wanted = 0;
                check(MPI_Recv(&wanted, 1, MPI_INT, from, kRequest, MPI_COMM_WORLD,
                               MPI_STATUS_IGNORE),
                      "receive");
                send_indices(indices_of(queue.take(static_cast<std::size_t>(std::max(1, wanted)),
                                                   processes)),
                             from, kGrant);
                break;
            }
            case kResult: {
                int count = 0;
                MPI_Get_count(&status, MPI_BYTE, &count);
                bytes.resize(static_cast<std::size_t>(count));
                check(MPI_Recv(bytes.data(), count, MPI_BYTE, from, kResult, MPI_COMM_WORLD,
                               MPI_STATUS_IGNORE),
                      "receive");
                if (error) break;  // drain the others, but add nothing more
                try {
                    sink.add(
                        decode_tile(bytes, context.tiles(), "process " + std::to_string(from)));
                } catch (...) {
                    error = std::current_exception();
                    queue.close();
                }
                break;
            }
            case kDone: {
                std::vector<Tile> back;
                for (std::uint64_t i : receive_indices(from, kDone)) {
                    back.push_back(context.tiles().at(static_cast<std::size_t>(i)));
                }
                queue.give_back(back);
                --active;
                break;
            }
            default:
                throw std::logic_error("MPI: unexpected message tag " +
                                       std::to_string(status.MPI_TAG));
        }
    }
}

// Another process's tiles: handed over by its communication thread, taken by its workers.
class WorkerQueue final : public TileSource {
  public:
    WorkerQueue(std::size_t size, std::stop_token stop) : size_(size), stop_(std::move(stop)) {}

    std::optional<Tile> next() override {
        std::unique_lock lock(mutex_);
        if (!ready_.wait(lock, stop_, [&] { return !tiles_.empty() || dry_; })) {
            return std::nullopt;  // stopped
        }
        if (tiles_.empty()) return std::nullopt;
        const Tile t = tiles_.front();
        tiles_.pop_front();
        return t;
    }
    std::size_t size() const override { return size_; }

    std::size_t queued() const {
        const std::lock_guard lock(mutex_);
        return tiles_.size();
    }
    void add(const std::vector<Tile>& tiles) {
        {
            const std::lock_guard lock(mutex_);
            tiles_.insert(tiles_.end(), tiles.begin(), tiles.end());
            if (tiles.empty()) dry_ = true;
        }
        ready_.notify_all();
    }
    // What was handed over but not taken: to give back to the leader.
    std::vector<Tile> drain() {
        const std::lock_guard lock(mutex_);
        std::vector<Tile> left(tiles_.begin(), tiles_.end());
        tiles_.clear();
        dry_ = true;
        return left;
    }

  private:
    mutable std::mutex mutex_;
    std::condition_variable_any ready_;
    std::deque<Tile> tiles_;
    bool dry_ = false;  // the leader has no more
    std::size_t size_;
    std::stop_token stop_;
};

// Finished tiles of another process, encoded, waiting to be sent by its communication thread.
class Outbox final : public TileSink {
  public:
    void add(TileBuffer buffer) override {
        std::vector<unsigned char> bytes = encode_tile(buffer);
        const std::lock_guard lock(mutex_);
        messages_.push_back(std::move(bytes));
    }
    std::optional<std::vector<unsigned char> > take() {
        const std::lock_guard lock(mutex_);
        if (messages_.empty()) return std::nullopt;
        std::vector<unsigned char> m = std::move(messages_.front());
        messages_.pop_front();
        return m;
    }

  private:
    std::mutex mutex_;
    std::deque<std::vector<unsigned char> > messages_;
};

// Another process's communication thread: keeps `threads` tiles ahead of its workers, sends
// their results, and once the workers have finished gives back what they did not take.
void work_for_leader(const RenderContext& context, WorkerQueue& queue, Outbox& outbox, int threads,
                     const std::atomic<bool>& workers_finished, const std::stop_token& stop) {
    bool requested = false, dry = false;
    const auto receive_grant = [&] {
        std::vector<Tile> tiles;
        for (std::uint64_t i : receive_indices(0, kGrant)) {
            tiles.push_back(context.tiles().at(static_cast<std::size_t>(i)));
        }
        requested = false;
        dry = tiles.empty();
        queue.add(tiles);
    };
    for (;;) {
        bool busy = false;
        if (!requested && !dry && !stop.stop_requested() &&
            queue.queued() < static_cast<std::size_t>(threads)) {
            const int wanted = threads;
            check(MPI_Send(&wanted, 1, MPI_INT, 0, kRequest, MPI_COMM_WORLD), "send");
            requested = true;
        }
        if (requested) {
            int flag = 0;
            check(MPI_Iprobe(0, kGrant, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE), "probe");
            if (flag) {
                receive_grant();
                busy = true;
            }
        }
        while (std::optional<std::vector<unsigned char> > m = outbox.take()) {
            check(MPI_Send(m->data(), static_cast<int>(m->size()), MPI_BYTE, 0, kResult,
                           MPI_COMM_WORLD),
                  "send");
            busy = true;
        }
        if (workers_finished.load()) {
            if (requested) receive_grant();  // answered in any case: take it to give it back
            while (std::optional<std::vector<unsigned char> > m = outbox.take()) {
                check(MPI_Send(m->data(), static_cast<int>(m->size()), MPI_BYTE, 0, kResult,
                               MPI_COMM_WORLD),
                      "send");
            }
            send_indices(indices_of(queue.drain()), 0, kDone);
            return;
        }
        if (!busy) std::this_thread::sleep_for(kIdle);
    }
}

}  // namespace

MpiJob::MpiJob() {
    // Only the communication thread calls MPI while workers render, and only the main thread
    // otherwise: one thread at a time.
    int provided = 0;
    check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided), "start");
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    MPI_Comm node;
    check(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node),
          "split by machine");
    MPI_Comm_size(node, &local_size_);
    MPI_Comm_free(&node);
}

MpiJob::~MpiJob() {
    MPI_Finalize();
}

int MpiJob::leaders(int value) const {
    check(MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD), "broadcast");
    return value;
}

int MpiJob::highest(int value) const {
    int out = value;
    check(MPI_Allreduce(&value, &out, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD), "reduce");
    return out;
}

int MpiJob::render(const RenderContext& context, std::vector<Tile> todo, TileSink& sink,
                   const RenderOptions& options) const {
    RenderOptions run = options;
    if (run.threads <= 0) {
        // The machine's cores are shared by the processes this job put on it.
        run.threads = std::max(
            1, static_cast<int>(std::thread::hardware_concurrency()) / std::max(1, local_size_));
    }
    if (leader()) {
        LeaderQueue queue(std::move(todo), options.stop);
        std::exception_ptr served_error;
        std::jthread server([&] { serve(context, queue, sink, size_, served_error); });
        int threads = 0;
        std::exception_ptr error;
        try {
            threads = render_tiles(context, queue, sink, run);
        } catch (...) {
            error = std::current_exception();
            queue.close();
        }
        server.join();
        if (error) std::rethrow_exception(error);
        if (served_error) std::rethrow_exception(served_error);
        // Tiles given back by a process that stopped on its own, after the leader's workers
        // had run dry: everyone else has finished, so they are rendered here.
        if (!queue.empty() && !options.stop.stop_requested()) {
            render_tiles(context, queue, sink, run);
        }
        return threads;
    }
    run.on_progress = nullptr;
    WorkerQueue queue(context.tiles().size(), options.stop);
    Outbox outbox;
    std::atomic<bool> workers_finished{false};
    std::jthread communicator([&] {
        work_for_leader(context, queue, outbox, run.threads, workers_finished, options.stop);
    });
    int threads = 0;
    std::exception_ptr error;
    try {
        threads = render_tiles(context, queue, outbox, run);
    } catch (...) {
        error = std::current_exception();
    }
    workers_finished.store(true);
    communicator.join();
    if (error) std::rethrow_exception(error);
    return threads;
}

#endif

}  // namespace drt
