#include "pine/vdbtrace/ranks.h"

#include "module_loader.h"
#include "pine/support/input_error.h"

#include <cstdlib>
#include <stdexcept>

namespace pine::vdbtrace {
namespace {

class Alone final : public Ranks {
public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
    int sizeOnThisMachine() const override { return 1; }
    void send(int, const Bytes&) override { throw std::logic_error("a lone rank sent"); }
    Bytes receive(int) override { throw std::logic_error("a lone rank waited for another"); }
    void broadcast(Bytes&, int) override {}
    double sum(double value) override { return value; }
    [[noreturn]] void abort(int status) override { std::exit(status); }
};

const char* environment(const char* name)
{
    const char* value = std::getenv(name);
    return value && *value ? value : nullptr;
}

// True where the environment says a launcher started this process as one of several.
bool startedByLauncher()
{
    // Open MPI's mpirun, then the PMIx and PMI launchers (Slurm's srun, MPICH's hydra).
    return environment("OMPI_COMM_WORLD_SIZE") || environment("PMIX_RANK") ||
           environment("PMI_SIZE");
}

}  // namespace

std::unique_ptr<Ranks> jobRanks(int& argc, char**& argv)
{
    if (!startedByLauncher()) return std::make_unique<Alone>();
    using Entry = Ranks* (*)(int*, char***);
    std::string error;
    const auto entry = reinterpret_cast<Entry>(
        loadModuleEntry(kRanksModuleFile, kRanksModuleEntry, "the MPI module", error));
    if (!entry) {
        throw InputError(
            "started by mpirun, but " + error +
            " (this build has no MPI: install it with scripts/install-deps.sh and configure with "
            "PINE_WITH_MPI on, the default)");
    }
    return std::unique_ptr<Ranks>(entry(&argc, &argv));
}

}  // namespace pine::vdbtrace
