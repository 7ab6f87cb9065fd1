// A render's stats and settings as JSON (the --stats file), written atomically.
#pragma once

#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/render_stats.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace pine::vdbtrace {

nlohmann::json toJson(const RenderStats& stats);
nlohmann::json toJson(const EffectsPlan& plan);

/// Writes JSON, indented, atomically (io::writeTextAtomically). Throws InputError.
void writeJsonAtomically(const nlohmann::json& json, const std::filesystem::path& path);

}  // namespace pine::vdbtrace
