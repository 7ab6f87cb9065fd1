// Files written so that a reader never sees one half-written (DESIGN.md: "Writes are atomic"),
// and the probe that refuses an unwritable output before the work rather than after it.
#pragma once

#include "pine/support/input_error.h"

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace pine::io {

/// A fresh name for a temporary file beside `file` (hidden, in the same folder, so that the
/// rename onto `file` is atomic), no longer than a file name may be (NAME_MAX): a long name is
/// shortened in the temporary's, never refused for it.
std::filesystem::path temporaryBeside(const std::filesystem::path& file);

/// Writes `file` by calling write(temporary) on a temporary beside it, syncing it to the disk,
/// calling beforeRename() if given (what must be in place before `file` is: a manifest), then
/// renaming the temporary onto `file`. If write or beforeRename throws or the rename fails,
/// the temporary is removed and `file` is left as it was; throws InputError "cannot write
/// 'FILE': WHY" (WHY from what the callback threw), except for std::bad_alloc, non-standard
/// exceptions and InputErrors from beforeRename (which name their own file), rethrown as they
/// are. For fault-injection tests, PINE_KILL_BEFORE_RENAME=NAME kills the process (SIGKILL)
/// just before a file named NAME would be renamed into place.
void writeAtomically(const std::filesystem::path& file,
                     const std::function<void(const std::filesystem::path& temporary)>& write,
                     const std::function<void()>& beforeRename = {});

/// Removes the temporaries that writes of `file` left behind when killed (temporaryBeside's
/// names); returns how many. A write of the same file running now loses its temporary and
/// fails cleanly. Names longer than 233 bytes share their temporaries' prefix with any name
/// that begins with the same 233 bytes.
int removeStaleTemporaries(const std::filesystem::path& file);

/// Writes `bytes` to `file` (created or truncated), every write and the close checked; throws
/// std::runtime_error with the system's reason (a full disk). Not atomic by itself: the
/// callback writeAtomically's writers call on their temporary.
void writeBytes(const std::filesystem::path& file, std::string_view bytes);

/// The folder `file` lies in: its parent, or "." for a bare name.
std::filesystem::path folderOf(const std::filesystem::path& file);

/// writeAtomically of `text`, checking that every byte reached the disk.
void writeTextAtomically(const std::filesystem::path& file, const std::string& text);

/// Throws InputError (one line naming the path and why) unless a file can be created at
/// `file`: it has a name, is not a folder or another file that is not a regular one (a device,
/// a pipe: a rename would replace it), its folder exists and takes a new file (tried, not
/// guessed from permission bits: read-only mounts, ACLs and root all differ).
void checkWritable(const std::filesystem::path& file);

/// Why `file` cannot be read whole as a file, or empty: "no such file", "not a regular file"
/// (a folder, a device such as /dev/zero) or "cannot reach it: ..." (a folder without search
/// permission, a loop of links). For each reader to word and throw as its own error.
std::string whyUnreadable(const std::filesystem::path& file);

/// checkWritable without trying its folder: for the many files of one folder (an animation's
/// frames) once checkWritable has tried it with one of them.
void checkWritableName(const std::filesystem::path& file);

/// Whether two paths name the same file: the same file if both exist (hard and symbolic links
/// followed), else the same path once made absolute and resolved ("..", links of the folders).
bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b);

/// Throws InputError (one line naming both paths) when an output of a run is one of its inputs
/// or two outputs are the same file: the run would overwrite what it reads, or lose one
/// output to the other. Empty paths are ignored.
void checkOutputsApart(const std::vector<std::filesystem::path>& outputs,
                       const std::vector<std::filesystem::path>& inputs);

/// Throws InputError (one line naming the folder, the file and the input) when a run that
/// writes files named as `writes` says into `folder` would overwrite one of `inputs`: an input
/// lying in `folder` (itself, or the file it links to) under such a name. For the runs that
/// write a folder of reports, whose names are theirs, not the user's.
void checkFolderSparesInputs(const std::filesystem::path& folder,
                             const std::function<bool(const std::string&)>& writes,
                             const std::vector<std::filesystem::path>& inputs);

/// Creates `folder` (and its parents) if missing, then checkWritable of a file in it.
void checkWritableFolder(const std::filesystem::path& folder);

}  // namespace pine::io
