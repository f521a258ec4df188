#pragma once
/// \file
/// The one way simsr writes an output file (npy, npz, vtu, pvd, obj, msh, MEDIT, TetGen, CSV, SVG,
/// model files and checkpoints): all of it or nothing, and never silently.
///
///     simsr::io::write_file_atomic("out/table.csv", text);    // bytes or text, whole
///
///     simsr::io::AtomicFile f("out/frames.npy");              // streaming: a temporary file appears
///     f.write(header);                                         // every write checked
///     f.write(data.data(), data.size());
///     f.commit();                                              // sync, close, rename over the target
///
/// A regular target (or a missing one) is written to a unique temporary file in the same folder
/// (`.<name>.<pid>.<n>.simsr-tmp`, same filesystem), every write(2) is checked (partial writes
/// continued, EINTR retried), the file is fsync'ed, closed (the close checked), renamed over the
/// target in one step, and the folder is fsync'ed so the rename survives a power cut. A reader of
/// the target sees the old file or the new one, never a mix; a writer killed at any point (even by
/// SIGKILL) leaves the previous file as it was, plus at worst its hidden temporary file.
///
/// Any failure throws simsr::WriteError naming the target with the operating system's reason
/// (errno text), after removing the temporary file: a missing folder, a "folder" that is a file,
/// an unwritable folder, a full disk, a failed sync, close or rename. An existing target the user
/// cannot write (e.g. mode 0444) is refused rather than replaced, and so is a writable file in a
/// folder the user may not write (the temporary file needs the folder); a new file gets the usual mode
/// (0666 less the umask), a replaced one keeps its mode; a symbolic link to a regular file has its
/// target replaced, the link kept (a dangling link is replaced by the file).
///
/// Special files are written in place: a target that exists and is not a regular file (a device
/// such as /dev/null or /dev/full, a FIFO, a socket) is opened for writing as it is, written and
/// closed, each step checked, so `/dev/full` reports "No space left on device" and a FIFO gets the
/// bytes in order (its open waits for a reader, as a shell redirection does); renaming a regular
/// file over /dev/full would replace the device, which no one wants. A folder as target is an error.
///
/// POSIX only (open/write/fsync/rename).

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "../core/error.hpp"

namespace simsr::io {

/// One output file being written: the temporary file (or the special file, written in place) is
/// open from construction to commit(); destroying an uncommitted AtomicFile removes the temporary
/// file and leaves the target untouched. Unbuffered: hand write() large pieces.
class AtomicFile {
 public:
  /// Creates the temporary file next to `path` (or opens `path` when it is a special file).
  /// WriteError when that is impossible (missing or unwritable folder, a file used as a folder,
  /// a target that is a folder or that the user may not write).
  explicit AtomicFile(std::filesystem::path path) : path_(std::move(path)), target_(path_) {
    struct ::stat st {};
    if (::stat(path_.c_str(), &st) == 0) {
      if (S_ISDIR(st.st_mode)) throw WriteError(name(), "is a folder, not a file", EISDIR);
      if (!S_ISREG(st.st_mode)) {  // device, FIFO, socket: in place
        do fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
        while (fd_ < 0 && errno == EINTR);
        if (fd_ < 0) throw error("cannot open it for writing", errno);
        return;
      }
      if (::access(path_.c_str(), W_OK) != 0) throw error("refusing to replace a file that is not writable", errno);
      struct ::stat lst {};
      if (::lstat(path_.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode)) {  // replace the link's target, keep the link
        std::error_code ec;
        auto resolved = std::filesystem::canonical(path_, ec);
        if (!ec) target_ = std::move(resolved);
      }
      keep_mode_ = true;
      mode_ = st.st_mode & 07777;
    }
    // Otherwise the target does not exist yet (or its folder does not, or cannot be searched):
    // creating the temporary file says which.
    folder_ = target_.parent_path();
    if (folder_.empty()) folder_ = ".";
    static std::atomic<unsigned long> counter{0};
    const std::string stem = target_.filename().string().substr(0, 128);  // stays within NAME_MAX
    for (int attempt = 0;; ++attempt) {
      temp_ = folder_ / ("." + stem + "." + std::to_string(::getpid()) + "." + std::to_string(counter++) + ".simsr-tmp");
      do fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOCTTY, 0666);
      while (fd_ < 0 && errno == EINTR);
      if (fd_ >= 0) break;
      const int e = errno;
      if (e == EEXIST && attempt < 1000) continue;  // a killed writer's leftover of the same pid
      temp_.clear();
      throw error("cannot create a temporary file in the folder '" + folder_.string() + "'", e);
    }
    if (keep_mode_) (void)::fchmod(fd_, mode_);  // best effort: a mode we may not set is no reason to fail
  }

  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() { abandon(); }

  /// Writes `size` bytes, all of them, or throws WriteError (the temporary file removed).
  void write(const void* data, std::size_t size) {
    if (fd_ < 0) throw ArgumentError(name() + ": write after commit or after a failure");
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
      const ::ssize_t n = ::write(fd_, p, std::min<std::size_t>(size, std::size_t(1) << 30));
      if (n < 0) {
        if (errno == EINTR) continue;
        fail("write failed", errno);
      }
      if (n == 0) fail("write failed (no progress)", EIO);
      p += n;
      size -= static_cast<std::size_t>(n);
    }
  }
  void write(std::string_view text) { write(text.data(), text.size()); }
  void write(std::span<const std::byte> bytes) { write(bytes.data(), bytes.size()); }

  /// Syncs and closes the temporary file, renames it over the target and syncs the folder (a
  /// special file: closes it). WriteError on any failure, the target then as it was before.
  void commit() {
    if (fd_ < 0) throw ArgumentError(name() + ": commit after commit or after a failure");
    if (temp_.empty()) {  // special file, written in place
      const int fd = std::exchange(fd_, -1);
      if (::close(fd) != 0 && errno != EINTR) throw error("close failed", errno);
      return;
    }
    if (::fsync(fd_) != 0 && errno != EINVAL) fail("cannot sync it to disk", errno);
    const int fd = std::exchange(fd_, -1);
    if (::close(fd) != 0 && errno != EINTR) fail("close failed", errno);  // Linux: EINTR still closed it
    if (::rename(temp_.c_str(), target_.c_str()) != 0)
      fail("cannot rename the temporary file '" + temp_.filename().string() + "' over it", errno);
    temp_.clear();  // it is the target now
    const int dir = ::open(folder_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {  // a folder we may write but not read cannot be synced: the rename stands
      const int r = ::fsync(dir), e = errno;
      ::close(dir);
      if (r != 0 && e != EINVAL && e != EBADF)
        throw error("written, but its folder '" + folder_.string() + "' could not be synced", e);
    }
  }

  /// The target as given.
  const std::filesystem::path& path() const noexcept { return path_; }
  /// The temporary file while one is open; empty for a special file or once committed.
  const std::filesystem::path& temporary() const noexcept { return temp_; }

 private:
  std::string name() const { return path_.string(); }
  WriteError error(const std::string& what, int e) const {
    return WriteError(name(), what + ": " + std::system_category().message(e), e);
  }
  /// Removes the temporary file (if any) and throws.
  [[noreturn]] void fail(const std::string& what, int e) {
    abandon();
    throw error(what, e);
  }
  void abandon() noexcept {
    if (fd_ >= 0) ::close(std::exchange(fd_, -1));
    if (!temp_.empty()) {
      ::unlink(temp_.c_str());
      temp_.clear();
    }
  }

  std::filesystem::path path_;    // as given, for messages
  std::filesystem::path target_;  // what the rename replaces (a symbolic link resolved)
  std::filesystem::path folder_;  // target_'s folder
  std::filesystem::path temp_;    // the temporary file, while it exists
  int fd_ = -1;
  bool keep_mode_ = false;
  ::mode_t mode_ = 0;
};

/// Writes `bytes` to `path` through AtomicFile: the whole new file, or WriteError and the old one.
inline void write_file_atomic(const std::filesystem::path& path, std::string_view bytes) {
  AtomicFile f(path);
  f.write(bytes);
  f.commit();
}
inline void write_file_atomic(const std::filesystem::path& path, std::span<const std::byte> bytes) {
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace simsr::io
