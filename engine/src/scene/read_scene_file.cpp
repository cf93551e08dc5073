// Reading a scene file's bytes (read_scene_file.hpp): the system calls, and what each kind of file gets.
#include "scene/read_scene_file.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

namespace phiq::detail::scene {

namespace {

// How long a FIFO scene is waited for its first bytes (or its writer's end) before it is refused.
constexpr int kFifoWaitMilliseconds = 5000;

}  // namespace

std::string read_scene_file(const std::string& path, const SceneLimits& limits) {
  auto refuse = [&](const std::string& why) { return SceneError(path + ": " + why); };
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) throw refuse(std::string("cannot open the scene file: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0) throw refuse(std::string("cannot read the scene file: ") + std::strerror(errno));
  const char* what = S_ISDIR(st.st_mode)                           ? "a directory"
                     : S_ISCHR(st.st_mode)                         ? "a character device"
                     : S_ISBLK(st.st_mode)                         ? "a block device"
                     : S_ISSOCK(st.st_mode)                        ? "a socket"
                     : S_ISREG(st.st_mode) || S_ISFIFO(st.st_mode) ? nullptr
                                                                   : "not a regular file";
  if (what) throw refuse(std::string("is ") + what + ", not a scene file");
  auto too_large = [&](std::uint64_t bytes, const char* more) {
    return refuse("the scene is " + std::string(more) + std::to_string(bytes >> 20) + " MiB; the limit is " +
                  std::to_string(limits.max_file_bytes >> 20) + " MiB");
  };
  if (S_ISREG(st.st_mode) && static_cast<std::uint64_t>(st.st_size) > limits.max_file_bytes)
    throw too_large(static_cast<std::uint64_t>(st.st_size), "");
  if (S_ISFIFO(st.st_mode)) {
    // a pipe whose writer has not come (or writes nothing) is waited for a bounded time, not for ever
    struct pollfd p {
      fd, POLLIN, 0
    };
    int ready;
    do ready = ::poll(&p, 1, kFifoWaitMilliseconds);
    while (ready < 0 && errno == EINTR);
    if (ready == 0)
      throw refuse("a FIFO with nothing written to it in " + std::to_string(kFifoWaitMilliseconds / 1000) +
                   " s (no writer?)");
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);  // the writer is there: block until it writes
  std::string text;
  if (S_ISREG(st.st_mode)) text.reserve(static_cast<std::size_t>(st.st_size));
  char chunk[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw refuse(std::string("cannot read the scene file: ") + std::strerror(errno));
    if (n == 0) break;
    text.append(chunk, static_cast<std::size_t>(n));
    if (text.size() > limits.max_file_bytes) throw too_large(text.size(), "more than ");
  }
  return text;
}

}  // namespace phiq::detail::scene
