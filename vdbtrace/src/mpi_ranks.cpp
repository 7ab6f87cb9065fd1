// The MPI module (ranks.h): Open MPI's C interface behind Ranks. Only the main thread calls
// MPI (MPI_THREAD_FUNNELED); the renders' TBB workers never do.
#include "pine/vdbtrace/ranks.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <thread>

namespace pine::vdbtrace {
namespace {

// A message longer than MPI's int count goes in pieces of this many bytes.
constexpr std::size_t kPiece = std::size_t(1) << 30;
constexpr int kSizeTag = 1, kPieceTag = 2;

// Open MPI's blocking calls spin while they wait: rank 0 waiting for another rank's frame,
// or a rank waiting for rank 0 to take its frame, would burn a core the renders need (measured:
// the paper forest's 24 frames on 2 ranks, 2 cores: 93.7 CPU-s, 80.1 asleep). Each call is
// started, then tested every millisecond, asleep in between: a frame takes seconds, the
// millisecond is nothing.
void await(MPI_Request& request)
{
    for (;;) {
        int done = 0;
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
}

class MpiRanks final : public Ranks {
public:
    MpiRanks(int* argc, char*** argv)
    {
        int provided = 0;
        MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
        MPI_Comm_rank(MPI_COMM_WORLD, &mRank);
        MPI_Comm_size(MPI_COMM_WORLD, &mSize);
        MPI_Comm local;
        MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, mRank, MPI_INFO_NULL, &local);
        MPI_Comm_size(local, &mLocalSize);
        MPI_Comm_free(&local);
    }
    ~MpiRanks() override { MPI_Finalize(); }

    int rank() const override { return mRank; }
    int size() const override { return mSize; }
    int sizeOnThisMachine() const override { return mLocalSize; }

    void send(int to, const Bytes& bytes) override
    {
        unsigned long long size = bytes.size();
        MPI_Request r;
        MPI_Isend(&size, 1, MPI_UNSIGNED_LONG_LONG, to, kSizeTag, MPI_COMM_WORLD, &r);
        await(r);
        for (std::size_t at = 0; at < bytes.size(); at += kPiece) {
            const int count = int(std::min(kPiece, bytes.size() - at));
            MPI_Isend(bytes.data() + at, count, MPI_BYTE, to, kPieceTag, MPI_COMM_WORLD, &r);
            await(r);
        }
    }

    Bytes receive(int from) override
    {
        unsigned long long size = 0;
        MPI_Request r;
        MPI_Irecv(&size, 1, MPI_UNSIGNED_LONG_LONG, from, kSizeTag, MPI_COMM_WORLD, &r);
        await(r);
        Bytes bytes(size);
        for (std::size_t at = 0; at < bytes.size(); at += kPiece) {
            const int count = int(std::min(kPiece, bytes.size() - at));
            MPI_Irecv(bytes.data() + at, count, MPI_BYTE, from, kPieceTag, MPI_COMM_WORLD, &r);
            await(r);
        }
        return bytes;
    }

    void broadcast(Bytes& bytes, int root) override
    {
        unsigned long long size = bytes.size();
        MPI_Request r;
        MPI_Ibcast(&size, 1, MPI_UNSIGNED_LONG_LONG, root, MPI_COMM_WORLD, &r);
        await(r);
        bytes.resize(size);
        for (std::size_t at = 0; at < bytes.size(); at += kPiece) {
            const int count = int(std::min(kPiece, bytes.size() - at));
            MPI_Ibcast(bytes.data() + at, count, MPI_BYTE, root, MPI_COMM_WORLD, &r);
            await(r);
        }
    }

    double sum(double value) override
    {
        double total = 0.0;
        MPI_Request r;
        MPI_Iallreduce(&value, &total, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD, &r);
        await(r);
        return total;
    }

    [[noreturn]] void abort(int status) override
    {
        MPI_Abort(MPI_COMM_WORLD, status);
        std::exit(status);  // MPI_Abort does not return; this tells the compiler so
    }

private:
    int mRank = 0, mSize = 1, mLocalSize = 1;
};

}  // namespace
}  // namespace pine::vdbtrace

extern "C" __attribute__((visibility("default"))) pine::vdbtrace::Ranks* pine_mpi_ranks(
    int* argc, char*** argv)
{
    return new pine::vdbtrace::MpiRanks(argc, argv);
}
