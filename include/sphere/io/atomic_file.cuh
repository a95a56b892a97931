#pragma once
/// \file
/// Writing a whole file so that a reader only ever finds the old content or the complete new
/// content, never a mixture: the bytes go to `<path>.tmp` in the same folder, are flushed to
/// the disk (fsync), and the temporary is renamed over the target (rename is atomic within
/// one file system). A run killed while writing leaves the previous file intact and, at most,
/// a stale `<path>.tmp` that the next write replaces. Host-only code (POSIX).
#include <cerrno>
#include <cstddef>
#include <cstring>
#include <string>

#include <fcntl.h>
#include <unistd.h>

#include "../core/error.cuh"

namespace sphere {

namespace detail {
/// The folder part of a path ("." when it has none), for syncing the folder after a rename.
inline std::string folder_of(const std::string& path)
{
    const std::string::size_type slash = path.find_last_of('/');
    if (slash == std::string::npos) return ".";
    return slash == 0 ? std::string("/") : path.substr(0, slash);
}

/// Removes the temporary file and throws sphere::error naming the target, the temporary and
/// the system's reason (errno `code`).
[[noreturn]] inline void abandon_temporary(const std::string& path, const std::string& tmp, const char* doing, int code)
{
    ::unlink(tmp.c_str());
    fail("cannot write '", path, "': ", doing, " the temporary file '", tmp, "' failed: ", std::strerror(code));
}
} // namespace detail

/// Writes `size` bytes from `data` to `path` atomically (see the file comment). Replaces an
/// existing file and a stale `<path>.tmp`. Throws sphere::error naming `path` and the reason
/// (folder missing, permission denied, disk full, ...) when any step fails; the temporary is
/// removed then and the previous content of `path`, if any, is left untouched.
inline void write_file_atomically(const std::string& path, const char* data, std::size_t size)
{
    if (path.empty()) detail::fail("cannot write a file with an empty path");
    const std::string tmp = path + ".tmp";
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        const int code = errno;
        detail::fail("cannot write '", path, "': creating the temporary file '", tmp, "' failed: ", std::strerror(code));
    }
    // Chunks of 1 MiB: a partial write() is continued, an interrupted one retried.
    constexpr std::size_t chunk = std::size_t(1) << 20;
    while (size > 0) {
        const ssize_t written = ::write(fd, data, size < chunk ? size : chunk);
        if (written < 0) {
            if (errno == EINTR) continue;
            const int code = errno;
            ::close(fd);
            detail::abandon_temporary(path, tmp, "writing", code);
        }
        data += written;
        size -= static_cast<std::size_t>(written);
    }
    if (::fsync(fd) != 0) {
        const int code = errno;
        ::close(fd);
        detail::abandon_temporary(path, tmp, "flushing", code);
    }
    if (::close(fd) != 0) detail::abandon_temporary(path, tmp, "closing", errno);
    if (::rename(tmp.c_str(), path.c_str()) != 0) detail::abandon_temporary(path, tmp, "renaming", errno);
    // Make the rename itself durable; a folder that cannot be synced is no error.
    const int dir = ::open(detail::folder_of(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {
        ::fsync(dir);
        ::close(dir);
    }
}

/// Writes `contents` to `path` atomically; see write_file_atomically(path, data, size).
inline void write_file_atomically(const std::string& path, const std::string& contents)
{
    write_file_atomically(path, contents.data(), contents.size());
}

} // namespace sphere
