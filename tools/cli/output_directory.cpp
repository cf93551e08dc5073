// Stale temporaries and the commit lock of output directories (output_directory.hpp).
#include "output_directory.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <mutex>
#include <set>
#include <tuple>
#include <utility>

namespace phiq {

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string temporary_name(const std::string& target, long pid) { return target + ".tmp-" + std::to_string(pid); }

void remove_stale_temporaries(const std::string& target) {
  static std::mutex mutex;
  // directories already looked at by this process (the path too: an inode is reused once a directory is removed)
  static std::set<std::tuple<dev_t, ino_t, std::string>> cleaned;
  const std::string dir = directory_of(target);
  struct stat ds;
  if (::stat(dir.c_str(), &ds) != 0) return;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (!cleaned.insert({ds.st_dev, ds.st_ino, dir}).second) return;
  }
  DIR* d = ::opendir(dir.c_str());
  if (!d) return;
  const int dfd = ::dirfd(d);
  const uid_t me = ::geteuid();
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    const std::size_t at = name.rfind(".tmp-");
    if (at == std::string::npos || at == 0 || at + 5 == name.size()) continue;
    const std::string digits = name.substr(at + 5);
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const long pid = std::stol(digits);
    if (pid <= 0 || pid == static_cast<long>(::getpid())) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to ask)
    struct stat st;
    if (::fstatat(dfd, e->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode) || st.st_uid != me) continue;
    ::unlinkat(dfd, e->d_name, 0);
  }
  ::closedir(d);
}

DirectoryLock::DirectoryLock(const std::vector<std::string>& targets) {
  std::vector<std::tuple<dev_t, ino_t, int>> dirs;
  for (const std::string& t : targets) {
    const int fd = ::open(directory_of(t).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) continue;
    struct stat st;
    if (::fstat(fd, &st) != 0) {
      ::close(fd);
      continue;
    }
    const bool seen = std::any_of(dirs.begin(), dirs.end(), [&](const auto& d) {
      return std::get<0>(d) == st.st_dev && std::get<1>(d) == st.st_ino;
    });
    if (seen) {
      ::close(fd);
      continue;
    }
    dirs.emplace_back(st.st_dev, st.st_ino, fd);
  }
  std::sort(dirs.begin(), dirs.end());
  for (const auto& [dev, ino, fd] : dirs) {
    int r;
    do r = ::flock(fd, LOCK_EX);
    while (r != 0 && errno == EINTR);
    fds_.push_back(fd);  // closed (and so unlocked) with the lock, locked or not
  }
}

DirectoryLock::~DirectoryLock() {
  for (auto it = fds_.rbegin(); it != fds_.rend(); ++it) ::close(*it);
}

}  // namespace phiq
