// Runs that write into one folder at once take turns while they write: two bakes of one folder
// would otherwise leave grids and manifests from different runs, and one run's clean-up of
// stale temporaries would remove the other's live ones (issue 14).
#pragma once

#include <filesystem>
#include <functional>

namespace pine::io {

/// An exclusive advisory lock (flock) on a folder, held while the object lives: taken at once if
/// free, else after calling onWait() (to say so) and waiting. No file is created. Every lock
/// taken is a separate one, so two in one process also take turns. Locks only runs of these
/// tools; other programs are not stopped. Where the file system cannot lock a folder (NFS),
/// no lock is taken. Throws InputError if the folder cannot be opened.
class FolderLock {
public:
    explicit FolderLock(const std::filesystem::path& folder,
                        const std::function<void()>& onWait = {});
    ~FolderLock();
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;

    /// The folder `file` is in ("." for a bare name).
    static std::filesystem::path of(const std::filesystem::path& file);

private:
    int mFd = -1;
};

}  // namespace pine::io
