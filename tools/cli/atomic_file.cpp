// Output files written under a temporary name and renamed when complete, and the resolution of output paths
// (symbolic links, devices, FIFOs, the process's own descriptors): atomic_file.hpp.
#include "atomic_file.hpp"

#include <fcntl.h>
#include <stdio_ext.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cstring>
#include <filesystem>

#include "output_directory.hpp"
#include "phiq/types.hpp"

namespace phiq {

namespace {

std::string cannot_write(const std::string& path, const std::string& why) { return path + ": cannot write: " + why; }

// The descriptor N when `p` names one of this process's open descriptors (/dev/fd/N, /proc/self/fd/N,
// /proc/thread-self/fd/N, /proc/<own pid>/fd/N), else −1. Following such a link would lead to "pipe:[…]" or to the
// file the shell opened, which must be written through the descriptor (its offset, O_APPEND), not replaced.
int own_descriptor(const std::string& p) {
  const std::string pid = "/proc/" + std::to_string(::getpid()) + "/fd/";
  for (const std::string& prefix :
       {std::string("/dev/fd/"), std::string("/proc/self/fd/"), std::string("/proc/thread-self/fd/"), pid}) {
    if (p.size() <= prefix.size() || p.compare(0, prefix.size(), prefix) != 0) continue;
    int fd = 0;
    const char* first = p.data() + prefix.size();
    const auto [end, ec] = std::from_chars(first, p.data() + p.size(), fd);
    if (ec != std::errc() || end != p.data() + p.size() || fd < 0) return -1;
    return ::fcntl(fd, F_GETFD) == -1 ? -1 : fd;
  }
  return -1;
}

}  // namespace

OutputPath resolve_output_path(const std::string& path) {
  if (path.empty()) throw Error("cannot write to an empty path");
  OutputPath out;
  std::string p = path;
  for (int links = 0;; ++links) {
    if (links > 40) throw Error(cannot_write(path, std::strerror(ELOOP)));
    if (const int fd = own_descriptor(p); fd >= 0) {
      out.target = p, out.exists = true, out.direct = true, out.descriptor = fd;
      return out;
    }
    struct stat st;
    if (::lstat(p.c_str(), &st) != 0) {
      // not there yet: created (a missing directory is reported when the temporary is created)
      if (errno == ENOENT) return out.target = p, out;
      throw Error(cannot_write(path, std::strerror(errno)));
    }
    if (S_ISLNK(st.st_mode)) {
      std::string link(PATH_MAX, '\0');
      const ssize_t n = ::readlink(p.c_str(), link.data(), link.size());
      if (n < 0) throw Error(cannot_write(path, std::strerror(errno)));
      link.resize(static_cast<std::size_t>(n));
      if (link.empty() || link.front() != '/') {  // relative to the link's directory
        const std::size_t slash = p.rfind('/');
        link = (slash == std::string::npos ? std::string() : p.substr(0, slash + 1)) + link;
      }
      p = std::move(link);
      continue;
    }
    out.target = p, out.exists = true;
    if (S_ISREG(st.st_mode)) return out;
    if (S_ISDIR(st.st_mode)) throw Error(cannot_write(path, "is a directory"));
    if (S_ISSOCK(st.st_mode)) throw Error(cannot_write(path, "is a socket"));
    out.direct = true;  // character or block device, FIFO
    return out;
  }
}

bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::equivalent(a, b, ec) && !ec) return true;
  try {  // a file to be created: where the paths lead, directories resolved
    const OutputPath ra = resolve_output_path(a), rb = resolve_output_path(b);
    if (ra.exists || rb.exists) return false;  // not both existing, or they would be equivalent
    const fs::path ca = fs::weakly_canonical(ra.target, ec);
    if (ec) return false;
    const fs::path cb = fs::weakly_canonical(rb.target, ec);
    return !ec && ca == cb;
  } catch (const Error&) {
    return false;
  }
}

AtomicOutputFile::AtomicOutputFile(std::string path, Hold hold) : path_(std::move(path)) {
  const OutputPath where = resolve_output_path(path_);
  target_ = where.target;
  direct_ = where.direct;
  const std::string shown = target_ == path_ ? path_ : path_ + " (a link to " + target_ + ")";
  int fd = -1;
  if (where.descriptor >= 0) {
    fd = ::fcntl(where.descriptor, F_DUPFD_CLOEXEC, 0);
  } else if (direct_) {
    fd = ::open(target_.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);  // a FIFO waits for its reader here
  } else {
    remove_stale_temporaries(target_);
    if (hold == Hold::kOpen) {
      // no name until it is complete: a process killed by SIGKILL leaves nothing behind
      fd = ::open(directory_of(target_).c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
      if (fd >= 0) {
        unnamed_ = true;
      } else if (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL) {
        const int err = errno;
        throw Error(cannot_write(shown, std::strerror(err)));
      }
    }
    if (fd < 0) {  // held closed between writes, or a file system without unnamed files: a named temporary
      tmp_ = temporary_name(target_, ::getpid());
      fd = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
    }
  }
  if (fd < 0) {
    const int err = errno;
    tmp_.clear();
    throw Error(cannot_write(shown, std::strerror(err)));
  }
  f_ = ::fdopen(fd, "wb");
  if (!f_) {
    const int err = errno;
    ::close(fd);
    if (!tmp_.empty()) ::unlink(tmp_.c_str());
    tmp_.clear();
    throw Error(cannot_write(shown, std::strerror(err)));
  }
  if (hold == Hold::kClosedBetweenWrites && !direct_) {
    closed_between_writes_ = true;
    std::fclose(f_);  // nothing written yet: nothing to lose
    f_ = nullptr;
  }
}

void AtomicOutputFile::reopen() {
  const int fd = ::open(tmp_.c_str(), O_WRONLY | O_APPEND | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) throw Error(cannot_write(path_, std::strerror(errno)));
  f_ = ::fdopen(fd, "ab");
  if (!f_) {
    const int err = errno;
    ::close(fd);
    throw Error(cannot_write(path_, std::strerror(err)));
  }
}

AtomicOutputFile::~AtomicOutputFile() {
  if (f_) std::fclose(f_);  // an unnamed temporary not published vanishes here
  if (!committed_ && !tmp_.empty()) ::unlink(tmp_.c_str());
}

void AtomicOutputFile::write(const std::string& data) {
  if (finished_ || (!f_ && !closed_between_writes_)) throw Error(path_ + ": cannot write: already closed");
  if (closed_between_writes_) {
    reopen();
    bool ok = std::fwrite(data.data(), 1, data.size(), f_) == data.size() && std::fflush(f_) == 0;
    int err = ok ? 0 : errno;
    if (std::fclose(f_) != 0 && ok) ok = false, err = errno;
    f_ = nullptr;
    if (!ok) throw Error(cannot_write(path_, std::strerror(err)));
    return;
  }
  if (std::fwrite(data.data(), 1, data.size(), f_) != data.size())
    throw Error(cannot_write(path_, std::strerror(errno)));
  written_ += data.size();
  // A large output starts going to disk as it is written (a hint: errors ignored), so that publishing it (fsync)
  // takes a moment, not the seconds of gigabytes held in the page cache: an interrupted batch must publish
  // before mpirun's SIGKILL follows its SIGTERM, a second later.
  if (!direct_ && written_ - flushed_ >= kWriteBehindBytes && std::fflush(f_) == 0) {
    (void)::sync_file_range(::fileno(f_), static_cast<off_t>(flushed_), static_cast<off_t>(written_ - flushed_),
                            SYNC_FILE_RANGE_WRITE);
    flushed_ = written_;
  }
}

void AtomicOutputFile::start_writeback() {
  if (direct_ || finished_) return;
  if (f_) {
    if (std::fflush(f_) == 0) (void)::sync_file_range(::fileno(f_), 0, 0, SYNC_FILE_RANGE_WRITE);
    return;
  }
  if (tmp_.empty()) return;
  const int fd = ::open(tmp_.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  (void)::sync_file_range(fd, 0, 0, SYNC_FILE_RANGE_WRITE);  // 0, 0: the whole file
  ::close(fd);
}

void AtomicOutputFile::truncate(std::uint64_t size) {
  if (direct_) throw Error(cannot_write(path_, "a device, FIFO or descriptor cannot be cut back"));
  if (finished_ || (!f_ && !closed_between_writes_)) throw Error(path_ + ": cannot write: already closed");
  const auto at = static_cast<off_t>(size);
  if (!f_) {  // closed between writes: by its name
    if (::truncate(tmp_.c_str(), at) != 0) throw Error(cannot_write(path_, std::strerror(errno)));
    return;
  }
  // what stdio still holds would be written at the next flush, after the cut: drop it (a failed fflush keeps it)
  ::__fpurge(f_);
  std::clearerr(f_);
  if (::ftruncate(::fileno(f_), at) != 0 || ::fseeko(f_, at, SEEK_SET) != 0)
    throw Error(cannot_write(path_, std::strerror(errno)));
  written_ = size, flushed_ = std::min(flushed_, size);
}

void AtomicOutputFile::finish() {
  if (finished_ || (!f_ && !closed_between_writes_)) throw Error(path_ + ": cannot write: already closed");
  if (!f_) reopen();  // closed between writes: open once more to sync it
  bool ok = std::fflush(f_) == 0 && !std::ferror(f_);
  int err = errno;
  // a temporary goes to disk before it is renamed; a device or FIFO has nothing to sync (fsync: EINVAL)
  if (ok && !direct_ && ::fsync(::fileno(f_)) != 0) ok = false, err = errno;
  // an unnamed temporary stays open: its descriptor is all there is of it until publish() links it
  if (!unnamed_ || !ok) {
    if (std::fclose(f_) != 0 && ok) ok = false, err = errno;
    f_ = nullptr;
  }
  if (!ok) throw Error(cannot_write(path_, std::strerror(err)));
  finished_ = true;
}

void AtomicOutputFile::publish() {
  if (!finished_) throw Error(path_ + ": cannot write: not finished");
  if (committed_) return;
  if (unnamed_) {
    // linkat cannot replace a file: the unnamed temporary gets its temporary's name, which rename() moves onto
    // the target in one step, as a named temporary is
    tmp_ = temporary_name(target_, ::getpid());
    ::unlink(tmp_.c_str());  // (a leftover of this process, if any)
    const std::string self = "/proc/self/fd/" + std::to_string(::fileno(f_));
    if (::linkat(::fileno(f_), "", AT_FDCWD, tmp_.c_str(), AT_EMPTY_PATH) != 0 &&
        ::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, tmp_.c_str(), AT_SYMLINK_FOLLOW) != 0) {
      const int err = errno;
      tmp_.clear();
      throw Error(cannot_write(path_, std::string("link: ") + std::strerror(err)));
    }
    std::fclose(f_);
    f_ = nullptr;
  }
  if (!direct_ && std::rename(tmp_.c_str(), target_.c_str()) != 0)
    throw Error(cannot_write(path_, std::string("rename: ") + std::strerror(errno)));
  committed_ = true;
  tmp_.clear();
}

void AtomicOutputFile::commit() {
  finish();
  const DirectoryLock lock({target_});
  publish();
}

}  // namespace phiq
