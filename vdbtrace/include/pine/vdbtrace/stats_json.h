// A render's stats and settings as JSON (the --stats file), written atomically.
#pragma once

#include "pine/vdbtrace/effects_plan.h"

#include <nlohmann/json.hpp>

#include <filesystem>

namespace pine::vdbtrace {

nlohmann::json toJson(const RenderStats& stats);
nlohmann::json toJson(const EffectsPlan& plan);

/// Writes `json` to `path` through a temporary file in the same folder, then renames it.
void writeJsonAtomically(const nlohmann::json& json, const std::filesystem::path& path);

}  // namespace pine::vdbtrace
