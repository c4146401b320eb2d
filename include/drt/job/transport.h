// The messages an MPI job exchanges (mpi_work.h), behind an interface so that MPI itself lives in
// a module of its own, drt_mpi.so beside the drt binary, loaded only when a launcher started drt.
// A plain run then loads no MPI library at all: it starts as fast as a drt built without MPI.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace drt {

// A message waiting to be received: who sent it and what kind it is.
struct Envelope {
    int from = 0;
    int tag = 0;
};

// A message on its way (Transport::send_later); it keeps its bytes until they have left.
class Sending {
  public:
    // Destroyed before sent() said so, it waits for the message to leave.
    virtual ~Sending() = default;
    // True once the message has left this process; only looks, never waits.
    virtual bool sent() = 0;
};

// Messages of bytes between the processes of one job, and the two collectives drt needs.
// Implemented over MPI by the module (src/job/mpi_module/); at most one thread calls it at a time.
class Transport {
  public:
    static constexpr int kAny = -1;

    virtual ~Transport() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    // Processes of this job on this machine, this one included: they share its cores.
    virtual int local_size() const = 0;
    // The leader's (rank 0's) value, on every process.
    virtual int broadcast(int value) const = 0;
    // The highest of every process's value, on every process.
    virtual int highest(int value) const = 0;
    // Returns once `bytes` may be reused: for a message above MPI's eager limit (Open MPI's
    // shared memory: 4 KB), only once the receiver has taken it, spinning a core meanwhile.
    virtual void send(int to, int tag, std::span<const unsigned char> bytes) const = 0;
    // Starts sending `bytes` and returns at once, whatever the receiver is doing.
    virtual std::unique_ptr<Sending> send_later(int to, int tag,
                                                std::vector<unsigned char> bytes) const = 0;
    // The first message from `from` with `tag` (either may be kAny) if one is waiting; it stays
    // waiting.
    virtual std::optional<Envelope> poll(int from, int tag) const = 0;
    // The next message from `from` with `tag`, waiting for it if need be.
    virtual std::vector<unsigned char> receive(int from, int tag) const = 0;
};

// A shared module loaded for the life of this object. Throws std::runtime_error naming the
// file when it cannot be loaded.
class SharedModule {
  public:
    explicit SharedModule(const std::filesystem::path& file);
    ~SharedModule();
    SharedModule(const SharedModule&) = delete;
    SharedModule& operator=(const SharedModule&) = delete;

    // Throws std::runtime_error when the module has no such symbol.
    void* symbol(const char* name) const;

  private:
    void* handle_;
    std::filesystem::path file_;
};

// drt_mpi.so in the folder of the running binary.
std::filesystem::path mpi_module_path();

// Starts MPI through `module` (which must outlive the transport). Throws std::runtime_error
// when MPI cannot start.
std::unique_ptr<Transport> start_mpi(const SharedModule& module);

// The name of the function drt_mpi.so exports: it starts MPI and puts the transport in `out`.
inline constexpr const char* kStartMpiSymbol = "drt_start_mpi";
using StartMpi = void (*)(std::unique_ptr<Transport>* out);

}  // namespace drt
