// Files written so that a reader never sees one half-written (DESIGN.md: "Writes are atomic"),
// and the probe that refuses an unwritable output before the work rather than after it.
#pragma once

#include "pine/support/input_error.h"

#include <filesystem>
#include <functional>
#include <string>

namespace pine::io {

/// A fresh name for a temporary file beside `file` (hidden, in the same folder, so that the
/// rename onto `file` is atomic).
std::filesystem::path temporaryBeside(const std::filesystem::path& file);

/// Writes `file` by calling write(temporary) on a temporary beside it, then renaming the
/// temporary onto `file`. If write throws or the rename fails, the temporary is removed and
/// `file` is left as it was; throws InputError "cannot write 'FILE': WHY" (WHY from what the
/// callback threw), except for std::bad_alloc and non-standard exceptions, rethrown as they
/// are.
void writeAtomically(const std::filesystem::path& file,
                     const std::function<void(const std::filesystem::path& temporary)>& write);

/// writeAtomically of `text`, checking that every byte reached the disk.
void writeTextAtomically(const std::filesystem::path& file, const std::string& text);

/// Throws InputError (one line naming the path and why) unless a file can be created at
/// `file`: it has a name, is not a folder, its folder exists and takes a new file (tried, not
/// guessed from permission bits: read-only mounts, ACLs and root all differ).
void checkWritable(const std::filesystem::path& file);

/// Creates `folder` (and its parents) if missing, then checkWritable of a file in it.
void checkWritableFolder(const std::filesystem::path& folder);

}  // namespace pine::io
