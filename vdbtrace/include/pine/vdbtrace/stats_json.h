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

/// Writes `text` to `path` through a temporary file in the same folder, then renames it: a
/// reader never sees a half-written file. Throws ImageError naming the path.
void writeTextAtomically(const std::string& text, const std::filesystem::path& path);

/// The same for JSON, indented.
void writeJsonAtomically(const nlohmann::json& json, const std::filesystem::path& path);

}  // namespace pine::vdbtrace
