// The processes of one job: `mpirun -np N vdbtrace render ...` starts N, each a rank. Open MPI
// lives in a module (libpine_mpi_ranks.so, built where MPI is installed) loaded only when the
// process was started by mpirun, so that a plain run pays nothing for it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace pine::vdbtrace {

using Bytes = std::vector<unsigned char>;

/// What a rank may ask of the others. Every call is collective or paired as MPI's are: a
/// rank that never answers leaves the others waiting, and a rank that dies ends the job
/// (mpirun kills the rest and says which died).
class Ranks {
public:
    virtual ~Ranks() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    /// Ranks of the job on this machine (mpirun's local size): the cores are shared by them.
    virtual int sizeOnThisMachine() const = 0;
    virtual void send(int to, const Bytes& bytes) = 0;
    virtual Bytes receive(int from) = 0;
    /// `root`'s bytes, on every rank.
    virtual void broadcast(Bytes& bytes, int root) = 0;
    /// The sum of every rank's `value`, on every rank.
    virtual double sum(double value) = 0;
    /// Ends every rank of the job at once, with `status` (after a rank's error, which no other
    /// rank would otherwise hear of while it waits for that rank).
    [[noreturn]] virtual void abort(int status) = 0;
};

/// The ranks of this process's job: Open MPI's when mpirun (or another launcher that sets
/// PMI/PMIx variables) started it, else one rank alone. Call once, before any thread starts.
/// Throws InputError under a launcher when this build has no MPI module (each rank would
/// render everything) or it cannot be loaded.
std::unique_ptr<Ranks> jobRanks(int& argc, char**& argv);

/// The module's file name and entry point: extern "C" Ranks* pine_mpi_ranks(int*, char***),
/// returning a new object (MPI_Finalize in its destructor).
inline constexpr const char* kRanksModuleFile = "libpine_mpi_ranks.so";
inline constexpr const char* kRanksModuleEntry = "pine_mpi_ranks";

}  // namespace pine::vdbtrace
