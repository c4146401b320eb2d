#include "drt/job/mpi_work.h"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <deque>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "drt/job/tile_codec.h"
#include "drt/util/limits.h"

namespace drt {

bool launched_by_mpirun(const std::function<const char*(const char*)>& getenv) {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"}) {
        const char* value = getenv(name);
        if (value != nullptr && *value != '\0') return true;
    }
    return false;
}

bool bound_by_mpirun_default(const std::function<const char*(const char*)>& getenv) {
    const char* bound = getenv("OMPI_MCA_orte_bound_at_launch");
    const char* asked = getenv("OMPI_MCA_hwloc_base_binding_policy");
    return bound != nullptr && std::strcmp(bound, "1") == 0 && (asked == nullptr || *asked == '\0');
}

namespace {

// When the calling thread may run on fewer CPUs than `share`, lets it, and the threads it starts
// from now on, run on every CPU: the kernel keeps them within the CPUs the system allows the
// process (a batch system's cpuset).
void widen_to_share(int share) {
    cpu_set_t mask;
    CPU_ZERO(&mask);
    if (sched_getaffinity(0, sizeof mask, &mask) != 0 || CPU_COUNT(&mask) >= share) return;
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) CPU_SET(cpu, &mask);
    // On failure the binding stays: slower, never wrong.
    (void)sched_setaffinity(0, sizeof mask, &mask);
}

// The worker threads of a process by default: its share of the machine's cores, which the
// processes this job put on the machine divide among themselves.
int share_of_machine(int local_processes) {
    return std::max(1, worker_threads(0) / std::max(1, local_processes));
}

using Clock = std::chrono::steady_clock;

// Message kinds between a process and the leader.
enum Tag : int {
    kRequest = 1,  // to the leader: an int, how many tiles the process would like
    kGrant,        // from the leader: tile indices; none means there is no more work
    kResult,       // to the leader: one finished tile (encode_tile)
    kDone,         // to the leader: tile indices handed out but not rendered; nothing follows
    kShared,       // from the leader, between renders: 32-bit values (MpiJob::broadcast)
};

// How long a communication thread sleeps while it waits for a message: at first short against
// a tile's render time, then, while nothing comes, twice as long each time, up to a fraction of
// the time between the finished tiles it handles (Pace). Each wake-up takes the core from a
// worker on a machine with as many workers as cores, and on a virtual machine a timer costs an
// exit to the host besides, so a fixed short poll would wake far more often than tiles finish.
constexpr auto kIdleLeast = std::chrono::microseconds(100);
// Before any tile has been timed, and where tiles are quick, the longest sleep; a thousandth of
// a second is still short against a tile of a scene worth several processes.
constexpr auto kIdleMost = std::chrono::microseconds(1000);
// Where tiles are slow, the longest sleep: short against a person stopping the render.
constexpr auto kIdleLongest = std::chrono::microseconds(20000);

// The time between the finished tiles a communication thread handles (smoothed), and so how
// long it may sleep: a process asks for tiles while its workers still have one in hand, and the
// leader's sleep and then the asking process's delay the answer by at most an eighth of that
// time, short even against the cheap tiles that come last (costly_first).
class Pace {
  public:
    void tick(Clock::time_point now) {
        if (last_) {
            const auto since = std::chrono::duration_cast<std::chrono::microseconds>(now - *last_);
            interval_ = interval_.count() == 0 ? since : (3 * interval_ + since) / 4;
        }
        last_ = now;
    }
    std::chrono::microseconds longest_sleep() const {
        return std::clamp<std::chrono::microseconds>(interval_ / 16, kIdleMost, kIdleLongest);
    }

  private:
    std::optional<Clock::time_point> last_;
    std::chrono::microseconds interval_{0};
};

// Sleeps between polls: kIdleLeast after something happened, twice as long each time nothing did,
// up to what the pace allows.
class Backoff {
  public:
    void idle(const Pace& pace) {
        std::this_thread::sleep_for(wait_);
        wait_ = std::min(2 * wait_, pace.longest_sleep());
    }
    void reset() { wait_ = kIdleLeast; }

  private:
    std::chrono::microseconds wait_ = kIdleLeast;
};

// Wakes another process's communication thread when its workers did something it must act on
// (took a tile, finished one, finished all), so that it sleeps instead of polling between tiles.
class Doorbell {
  public:
    void ring() {
        {
            const std::lock_guard lock(mutex_);
            rung_ = true;
        }
        rang_.notify_one();
    }
    // Until rung or `most` has passed.
    void wait(std::chrono::microseconds most) {
        std::unique_lock lock(mutex_);
        rang_.wait_for(lock, most, [&] { return rung_; });
        rung_ = false;
    }

  private:
    std::mutex mutex_;
    std::condition_variable rang_;
    bool rung_ = false;
};

std::vector<unsigned char> bytes_of(const std::vector<std::uint64_t>& words) {
    std::vector<unsigned char> bytes(words.size() * sizeof(std::uint64_t));
    if (!words.empty()) std::memcpy(bytes.data(), words.data(), bytes.size());
    return bytes;
}

// Tile indices travel as the machine's 64-bit words: every process of a job runs the same
// binary on the same kind of processor.
void send_tiles(const Transport& transport, const std::vector<Tile>& tiles, int to, int tag) {
    std::vector<std::uint64_t> indices;
    indices.reserve(tiles.size());
    for (const Tile& t : tiles) indices.push_back(t.index);
    transport.send(to, tag, bytes_of(indices));
}

std::vector<Tile> receive_tiles(const Transport& transport, const RenderContext& context, int from,
                                int tag) {
    const std::vector<unsigned char> bytes = transport.receive(from, tag);
    if (bytes.size() % sizeof(std::uint64_t) != 0) {
        throw std::runtime_error("MPI: a list of tiles of " + std::to_string(bytes.size()) +
                                 " bytes");
    }
    std::vector<Tile> tiles;
    for (std::size_t at = 0; at < bytes.size(); at += sizeof(std::uint64_t)) {
        std::uint64_t index = 0;
        std::memcpy(&index, bytes.data() + at, sizeof index);
        tiles.push_back(context.tiles().at(static_cast<std::size_t>(index)));
    }
    return tiles;
}

void send_int(const Transport& transport, int value, int to, int tag) {
    std::vector<unsigned char> bytes(sizeof value);
    std::memcpy(bytes.data(), &value, sizeof value);
    transport.send(to, tag, bytes);
}

int receive_int(const Transport& transport, int from, int tag) {
    const std::vector<unsigned char> bytes = transport.receive(from, tag);
    int value = 0;
    if (bytes.size() != sizeof value) throw std::runtime_error("MPI: a request of the wrong size");
    std::memcpy(&value, bytes.data(), sizeof value);
    return value;
}

// A finished tile from process `from`; a damaged message is a failure of the job's transport.
TileBuffer received_tile(std::span<const unsigned char> bytes, const RenderContext& context,
                         std::size_t aov_channels, int from) {
    try {
        return decode_tile(bytes, context.tiles(), diffuse_count_for(context.scene().settings),
                           aov_channels);
    } catch (const TileCodecError& e) {
        throw std::runtime_error("MPI: a tile message from process " + std::to_string(from) + ": " +
                                 e.what());
    }
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
        if (tiles_.empty()) emptied_ = Clock::now();
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
        if (n > 0 && tiles_.empty()) emptied_ = Clock::now();
        return out;
    }
    void give_back(const std::vector<Tile>& tiles) {
        const std::lock_guard lock(mutex_);
        tiles_.insert(tiles_.begin(), tiles.begin(), tiles.end());
    }
    void give_back(const Tile& tile) override { give_back(std::vector<Tile>{tile}); }
    bool empty() const {
        const std::lock_guard lock(mutex_);
        return tiles_.empty();
    }
    // After a failure: hand out nothing more.
    void close() { failed_.store(true); }
    // When the last tile was handed out (the last time, if some came back).
    std::optional<Clock::time_point> emptied() const {
        const std::lock_guard lock(mutex_);
        return emptied_;
    }

  private:
    bool closed() const { return failed_.load() || stop_.stop_requested(); }

    mutable std::mutex mutex_;
    std::deque<Tile> tiles_;
    std::size_t size_;
    std::stop_token stop_;
    std::atomic<bool> failed_{false};
    std::optional<Clock::time_point> emptied_;
};

// The leader's communication thread: answers requests, passes finished tiles to the sink and
// takes back unrendered ones, until every other process has said it is done.
void serve(const Transport& transport, const RenderContext& context, std::size_t aov_channels,
           LeaderQueue& queue, TileSink& sink, MpiShare& share, std::exception_ptr& error) {
    const auto seconds = [](Clock::time_point from, Clock::time_point to) {
        return std::chrono::duration<double>(to - from).count();
    };
    const int processes = transport.size();
    int active = processes - 1;
    Backoff backoff;
    Pace pace;
    while (active > 0) {
        const std::optional<Envelope> waiting = transport.poll(Transport::kAny, Transport::kAny);
        if (!waiting) {
            backoff.idle(pace);
            continue;
        }
        backoff.reset();
        const int from = waiting->from;
        switch (waiting->tag) {
            case kRequest: {
                const int wanted = receive_int(transport, from, kRequest);
                send_tiles(transport,
                           queue.take(static_cast<std::size_t>(std::max(1, wanted)), processes),
                           from, kGrant);
                break;
            }
            case kResult: {
                const Clock::time_point start = Clock::now();
                pace.tick(start);
                const std::vector<unsigned char> bytes = transport.receive(from, kResult);
                if (error) break;  // drain the others, but add nothing more
                const Clock::time_point received = Clock::now();
                try {
                    sink.add(received_tile(bytes, context, aov_channels, from));
                } catch (...) {
                    error = std::current_exception();
                    queue.close();
                }
                ++share.messages;
                share.receive_seconds += seconds(start, received);
                share.assemble_seconds += seconds(received, Clock::now());
                break;
            }
            case kDone:
                queue.give_back(receive_tiles(transport, context, from, kDone));
                --active;
                break;
            default:
                throw std::logic_error("MPI: unexpected message tag " +
                                       std::to_string(waiting->tag));
        }
    }
}

// Another process's tiles: handed over by its communication thread, taken by its workers.
class WorkerQueue final : public TileSource {
  public:
    WorkerQueue(std::size_t size, std::stop_token stop, Doorbell& taken)
        : size_(size), stop_(std::move(stop)), taken_(taken) {}

    std::optional<Tile> next() override {
        std::optional<Tile> t;
        {
            std::unique_lock lock(mutex_);
            if (!ready_.wait(lock, stop_, [&] { return !tiles_.empty() || dry_; })) {
                return std::nullopt;  // stopped
            }
            if (tiles_.empty()) return std::nullopt;
            t = tiles_.front();
            tiles_.pop_front();
        }
        taken_.ring();  // the communication thread may ask for more
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
    // A tile a stop made a worker abandon: drained with those not taken.
    void give_back(const Tile& tile) override {
        const std::lock_guard lock(mutex_);
        tiles_.push_front(tile);
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
    Doorbell& taken_;
};

// Finished tiles of another process, encoded, waiting to be sent by its communication thread.
class Outbox final : public TileSink {
  public:
    Outbox(Doorbell& added, DiffuseCount diffuse, std::size_t aov_channels)
        : added_(added), diffuse_(diffuse), aov_channels_(aov_channels) {}

    void add(TileBuffer buffer) override {
        std::vector<unsigned char> bytes = encode_tile(buffer, diffuse_, aov_channels_);
        {
            const std::lock_guard lock(mutex_);
            messages_.push_back(std::move(bytes));
        }
        added_.ring();
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
    Doorbell& added_;
    DiffuseCount diffuse_;
    std::size_t aov_channels_;
};

// Another process's communication thread: keeps `threads` tiles ahead of its workers, sends
// their results, and once the workers have finished gives back what they did not take. Only a
// grant comes to it, and only after a request, so it polls only while a request is unanswered
// and otherwise sleeps until its workers ring `doorbell`. Results leave without waiting for the
// leader (send_later): a tile message is above Open MPI's shared-memory eager limit, and a
// blocking send of one spun this thread, on the core its worker needs, until the leader's next
// poll.
void work_for_leader(const Transport& transport, const RenderContext& context, WorkerQueue& queue,
                     Outbox& outbox, int threads, const std::atomic<bool>& workers_finished,
                     Doorbell& doorbell, const std::stop_token& stop) {
    Backoff backoff;
    Pace pace;
    bool requested = false, dry = false;
    std::vector<std::unique_ptr<Sending> > sending;
    const auto receive_grant = [&] {
        std::vector<Tile> tiles = receive_tiles(transport, context, 0, kGrant);
        requested = false;
        dry = tiles.empty();
        queue.add(tiles);
    };
    const auto send_results = [&] {
        bool sent = false;
        while (std::optional<std::vector<unsigned char> > m = outbox.take()) {
            sending.push_back(transport.send_later(0, kResult, std::move(*m)));
            pace.tick(Clock::now());
            sent = true;
        }
        std::erase_if(sending, [](const std::unique_ptr<Sending>& s) { return s->sent(); });
        return sent;
    };
    for (;;) {
        bool busy = false;
        if (!requested && !dry && !stop.stop_requested() &&
            queue.queued() < static_cast<std::size_t>(threads)) {
            send_int(transport, threads, 0, kRequest);
            requested = true;
        }
        if (requested && transport.poll(0, kGrant)) {
            receive_grant();
            busy = true;
        }
        busy = send_results() || busy;
        if (workers_finished.load()) {
            if (requested) receive_grant();  // answered in any case: take it to give it back
            send_results();
            send_tiles(transport, queue.drain(), 0, kDone);
            while (!sending.empty()) {  // the leader takes them before the kDone sent after them
                backoff.idle(pace);
                send_results();
            }
            return;
        }
        if (busy) {
            backoff.reset();
        } else if (requested) {
            backoff.idle(pace);
        } else {
            doorbell.wait(kIdleLongest);  // bounded for a stop, which rings no bell
        }
    }
}

}  // namespace

MpiJob::MpiJob() {
    const std::filesystem::path file = mpi_module_path();
    try {
        module_ = std::make_unique<SharedModule>(file);
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(
            std::string("started by mpirun, but the MPI module is missing or broken (") + e.what() +
            "): build drt where MPI is installed (libopenmpi-dev, tools/install-deps.sh) and "
            "keep drt_mpi.so beside the drt binary");
    }
    transport_ = start_mpi(*module_);
    // A process's share of its machine is the one its default thread count takes (render):
    // under mpirun's default binding, `mpirun -n 1` on two cores got one. Where the shares fill
    // the machine (one core each) the binding stays: pinned processes run faster under load.
    // Threads started from here on (workers, the communication thread) inherit the share.
    if (bound_by_mpirun_default()) widen_to_share(share_of_machine(local_size()));
}

MpiJob::~MpiJob() = default;

int MpiJob::broadcast(int value) const {
    return transport_->broadcast(value);
}

std::vector<std::uint32_t> MpiJob::broadcast(std::vector<std::uint32_t> values) const {
    if (leader()) {
        std::vector<unsigned char> bytes(values.size() * sizeof(std::uint32_t));
        if (!values.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
        for (int to = 1; to < size(); ++to) transport_->send(to, kShared, bytes);
        return values;
    }
    const std::vector<unsigned char> bytes = transport_->receive(0, kShared);
    if (bytes.size() % sizeof(std::uint32_t) != 0) {
        throw std::runtime_error("MPI: shared values of " + std::to_string(bytes.size()) +
                                 " bytes");
    }
    values.resize(bytes.size() / sizeof(std::uint32_t));
    if (!values.empty()) std::memcpy(values.data(), bytes.data(), bytes.size());
    return values;
}

int MpiJob::threads_for(int requested) const {
    return requested > 0 ? requested : share_of_machine(local_size());
}

int MpiJob::highest(int value) const {
    return transport_->highest(value);
}

MpiShare MpiJob::render_tiles(const RenderContext& context, const RenderRequest& request,
                              std::vector<Tile> todo, TileSink& sink,
                              const RenderOptions& options) const {
    RenderOptions run = options;
    run.threads = threads_for(run.threads);
    if (leader()) {
        LeaderQueue queue(std::move(todo), options.stop);
        MpiShare share;
        std::exception_ptr served_error;
        std::jthread server([&] {
            serve(*transport_, context, aov_channel_count(request.aovs), queue, sink, share,
                  served_error);
        });
        std::exception_ptr error;
        try {
            share.threads = drt::render_tiles(context, request, queue, sink, run);
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
            drt::render_tiles(context, request, queue, sink, run);
        }
        share.emptied = queue.emptied();
        return share;
    }
    run.on_progress = nullptr;
    Doorbell doorbell;
    WorkerQueue queue(context.tiles().size(), options.stop, doorbell);
    Outbox outbox(doorbell, diffuse_count_for(context.scene().settings),
                  aov_channel_count(request.aovs));
    std::atomic<bool> workers_finished{false};
    std::jthread communicator([&] {
        work_for_leader(*transport_, context, queue, outbox, run.threads, workers_finished,
                        doorbell, options.stop);
    });
    MpiShare share;
    std::exception_ptr error;
    try {
        share.threads = drt::render_tiles(context, request, queue, outbox, run);
    } catch (...) {
        error = std::current_exception();
    }
    workers_finished.store(true);
    doorbell.ring();
    communicator.join();
    if (error) std::rethrow_exception(error);
    return share;
}

}  // namespace drt
