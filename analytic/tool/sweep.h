// `analytic sweep`: measures each approximation of the paper over its parameter space.
#pragma once

#include <filesystem>

namespace pine::analytic::tool {

struct SweepOptions {
    std::filesystem::path outDir;
    int coneCases = 2000;     ///< random (phi, L, V, n) cases for the cone fits
    unsigned seed = 20000513;  ///< fixed: the same sweep gives the same numbers
    bool plot = true;         ///< run scripts/plot_sweep.py on the CSVs
};

/// Writes f_fit.csv, cone_fits.csv, linear_law.csv, linear_law_opacity.csv, summary.json and
/// (with `plot`) sweep.png into outDir, each atomically. Progress on stderr. Returns 0, or 1 if
/// plotting failed; throws InputError if outDir cannot be written (before any work).
int runSweep(const SweepOptions& options);

}  // namespace pine::analytic::tool
