// The plot scripts the tools start (scripts/plot_*.py, DESIGN.md: Debian's python3 with
// matplotlib, Agg backend): started directly, never through a shell, so that no folder name is
// ever interpreted as a command.
#pragma once

#include <filesystem>
#include <string>

namespace pine::tool {

/// $PINE_PLOT_SCRIPT where set, else NAME where `cmake --install` put it (share/pine beside the
/// executable's bin/), else scripts/NAME in the source tree this was built from.
std::filesystem::path plotScript(const std::string& name);

/// Runs `/usr/bin/python3 SCRIPT FOLDER` with MPLBACKEND=Agg and waits for it: true if it
/// exited with status 0.
bool runPlotScript(const std::filesystem::path& script, const std::filesystem::path& folder);

}  // namespace pine::tool
