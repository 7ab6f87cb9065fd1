#include "pine/support/folder_lock.h"

#include "pine/support/atomic_file.h"
#include "pine/support/input_error.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace pine::io {

namespace fs = std::filesystem;

FolderLock::FolderLock(const fs::path& folder, const std::function<void()>& onWait)
{
    mFd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (mFd < 0) {
        throw InputError("cannot write into '" + folder.string() + "': " + std::strerror(errno));
    }
    if (::flock(mFd, LOCK_EX | LOCK_NB) == 0) return;
    if (errno == EBADF || errno == ENOLCK || errno == EOPNOTSUPP || errno == EINVAL) {
        // A file system that cannot lock a folder (NFS emulates flock with byte-range locks,
        // which a folder opened for reading cannot take): written unlocked, as before locks.
        ::close(mFd);
        mFd = -1;
        return;
    }
    if (errno == EWOULDBLOCK) {
        if (onWait) onWait();
        int locked;
        while ((locked = ::flock(mFd, LOCK_EX)) != 0 && errno == EINTR) {
        }
        if (locked == 0) return;
    }
    const int why = errno;
    ::close(mFd);
    throw InputError("cannot lock '" + folder.string() + "': " + std::strerror(why));
}

FolderLock::~FolderLock()
{
    if (mFd >= 0) ::close(mFd);  // closing releases the lock
}

fs::path FolderLock::of(const fs::path& file)
{
    return folderOf(file);
}

}  // namespace pine::io
