// drt_mpi.so: the Transport (transport.h) over MPI's C interface. The only code that includes
// mpi.h or links libmpi; drt loads it only when a launcher started it (mpi_work.h).
#include <mpi.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "drt/job/transport.h"

namespace drt {
namespace {

void check(int code, const char* what) {
    if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

int mpi_source(int from) {
    return from == Transport::kAny ? MPI_ANY_SOURCE : from;
}
int mpi_tag(int tag) {
    return tag == Transport::kAny ? MPI_ANY_TAG : tag;
}

class MpiSending final : public Sending {
  public:
    MpiSending(int to, int tag, std::vector<unsigned char> bytes) : bytes_(std::move(bytes)) {
        check(MPI_Isend(bytes_.data(), static_cast<int>(bytes_.size()), MPI_BYTE, to, tag,
                        MPI_COMM_WORLD, &request_),
              "send");
    }
    ~MpiSending() override {
        // MPI reads bytes_ until the request completes. A destructor cannot throw: a failure
        // here is MPI's, which ends the job anyway.
        if (request_ != MPI_REQUEST_NULL) (void)MPI_Wait(&request_, MPI_STATUS_IGNORE);
    }
    MpiSending(const MpiSending&) = delete;
    MpiSending& operator=(const MpiSending&) = delete;

    bool sent() override {
        if (request_ == MPI_REQUEST_NULL) return true;
        int done = 0;
        check(MPI_Test(&request_, &done, MPI_STATUS_IGNORE), "send");  // frees it when done
        return done != 0;
    }

  private:
    std::vector<unsigned char> bytes_;
    MPI_Request request_ = MPI_REQUEST_NULL;
};

class MpiTransport final : public Transport {
  public:
    MpiTransport() {
        // Only a process's communication thread calls MPI while its workers render, and only
        // its main thread otherwise: one thread at a time.
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
    ~MpiTransport() override { MPI_Finalize(); }
    MpiTransport(const MpiTransport&) = delete;
    MpiTransport& operator=(const MpiTransport&) = delete;

    int rank() const override { return rank_; }
    int size() const override { return size_; }
    int local_size() const override { return local_size_; }

    int broadcast(int value) const override {
        check(MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD), "broadcast");
        return value;
    }
    int highest(int value) const override {
        int out = value;
        check(MPI_Allreduce(&value, &out, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD), "reduce");
        return out;
    }

    void send(int to, int tag, std::span<const unsigned char> bytes) const override {
        check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag,
                       MPI_COMM_WORLD),
              "send");
    }
    std::unique_ptr<Sending> send_later(int to, int tag,
                                        std::vector<unsigned char> bytes) const override {
        return std::make_unique<MpiSending>(to, tag, std::move(bytes));
    }
    std::optional<Envelope> poll(int from, int tag) const override {
        int flag = 0;
        MPI_Status status;
        check(MPI_Iprobe(mpi_source(from), mpi_tag(tag), MPI_COMM_WORLD, &flag, &status), "probe");
        if (!flag) return std::nullopt;
        return Envelope{status.MPI_SOURCE, status.MPI_TAG};
    }
    std::vector<unsigned char> receive(int from, int tag) const override {
        MPI_Status status;
        check(MPI_Probe(mpi_source(from), mpi_tag(tag), MPI_COMM_WORLD, &status), "probe");
        int count = 0;
        MPI_Get_count(&status, MPI_BYTE, &count);
        std::vector<unsigned char> bytes(static_cast<std::size_t>(count));
        check(MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG,
                       MPI_COMM_WORLD, MPI_STATUS_IGNORE),
              "receive");
        return bytes;
    }

  private:
    int rank_ = 0, size_ = 1, local_size_ = 1;
};

}  // namespace
}  // namespace drt

// Looked up by name (kStartMpiSymbol) after dlopen, hence C linkage.
extern "C" __attribute__((visibility("default"))) void drt_start_mpi(
    std::unique_ptr<drt::Transport>* out) {
    *out = std::make_unique<drt::MpiTransport>();
}
