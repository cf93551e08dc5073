#include "cli_support.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <mutex>
#include <thread>

#include "output_directory.hpp"

namespace phiq::tools {

namespace {

// Everything the signal thread reads, under one mutex: the command's thread takes it to create a temporary and
// register it, to publish its files, and to change the mode, so that the signal thread never sees half of either.
std::mutex g_mutex;
std::vector<AtomicOutputFile*> g_live;  // files of live OutputSets whose temporaries a signal removes
int g_stop_depth = 0;                   // live StopOnSignal objects
bool g_quiet = false;                   // outputs committed: exit without a word
int g_settled = -1;                     // the status of the error line already printed (−1: none)
// (before a command names its subject, it has created no output yet)
std::string g_subject, g_suffix = "; no output written";
std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
bool g_stdout_closed = false;

sigset_t handled_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  return set;
}

[[noreturn]] void exit_on(int sig) {  // with g_mutex held: no temporary appears or goes meanwhile
  if (!g_quiet) {
    for (AtomicOutputFile* f : g_live)
      if (!f->temporary_path().empty()) ::unlink(f->temporary_path().c_str());
    const std::string line = "phiq: " + (g_subject.empty() ? "" : g_subject + ": ") + "interrupted (" +
                             signal_name(sig) + ")" + g_suffix + "\n";
    if (g_settled < 0 && ::write(STDERR_FILENO, line.data(), line.size()) < 0) {
      // nothing more to do about it: the exit status still says what happened
    }
  }
  ::_exit(g_settled >= 0 ? g_settled : 128 + sig);
}

void wait_for_signals() {
  const sigset_t set = handled_signals();
  for (;;) {
    int sig = 0;
    if (sigwait(&set, &sig) != 0) continue;
    std::lock_guard<std::mutex> lock(g_mutex);
    int none = 0;
    g_signal.compare_exchange_strong(none, sig);
    if (g_stop_depth > 0 && !g_stop.load()) {
      g_stop = true;  // the sweep stops at its next row; the command reports it
      continue;
    }
    exit_on(sig);
  }
}

}  // namespace

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
  }
  return "a signal";
}

void settle_interrupts(int status) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_settled < 0) g_settled = status;
}

void quiet_interrupts() {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_quiet = true;
}

void start_interrupts() {
  const sigset_t set = handled_signals();
  // blocked here, before any other thread exists, so blocked in every thread created later (TBB's workers too):
  // only the thread below receives them, with sigwait, in ordinary code that may take the mutex
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread(wait_for_signals).detach();
}

void set_interrupt_subject(const std::string& subject, const std::string& suffix) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_subject = subject;
  g_suffix = suffix;
}

const std::atomic<bool>& stop_flag() { return g_stop; }
int interrupt_signal() { return g_signal.load(); }
int interrupt_exit_status() { return 128 + g_signal.load(); }
std::string interrupt_message() { return std::string("interrupted (") + signal_name(g_signal.load()) + ")"; }

StopOnSignal::StopOnSignal() {
  std::lock_guard<std::mutex> lock(g_mutex);
  ++g_stop_depth;
}

StopOnSignal::~StopOnSignal() {
  std::lock_guard<std::mutex> lock(g_mutex);
  --g_stop_depth;
}

OutputSet::~OutputSet() {
  std::lock_guard<std::mutex> lock(g_mutex);
  for (const auto& f : files_) g_live.erase(std::remove(g_live.begin(), g_live.end(), f.get()), g_live.end());
  files_.clear();  // removes the temporaries not published
}

AtomicOutputFile& OutputSet::add(const std::string& path, AtomicOutputFile::Hold hold) {
  if (resolve_output_path(path).direct) {
    // no temporary to remove on a signal; a FIFO may wait here for its reader, which a signal must interrupt
    auto file = std::make_unique<AtomicOutputFile>(path);
    std::lock_guard<std::mutex> lock(g_mutex);
    files_.push_back(std::move(file));
    return *files_.back();
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  files_.push_back(std::make_unique<AtomicOutputFile>(path, hold));
  g_live.push_back(files_.back().get());
  return *files_.back();
}

void OutputSet::commit() {
  for (const auto& f : files_)
    if (!f->finished()) f->finish();
  std::vector<std::string> targets;
  for (const auto& f : files_)
    if (!f->direct()) targets.push_back(f->target());
  // another phiq renaming files in these directories waits, so that a pair (CSV and summary) is one command's
  const DirectoryLock directories(targets);
  std::lock_guard<std::mutex> lock(g_mutex);
  for (const auto& f : files_) f->publish();
  g_quiet = true;
}

void OutputSet::commit_one(AtomicOutputFile& file) {
  if (!file.finished()) file.finish();
  std::vector<std::string> targets;
  if (!file.direct()) targets.push_back(file.target());
  const DirectoryLock directories(targets);
  std::lock_guard<std::mutex> lock(g_mutex);
  file.publish();
}

void OutputSet::drop(AtomicOutputFile& file) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_live.erase(std::remove(g_live.begin(), g_live.end(), &file), g_live.end());
  for (auto it = files_.begin(); it != files_.end(); ++it)
    if (it->get() == &file) {
      files_.erase(it);  // removes its temporary
      return;
    }
}

std::optional<std::string> output_clash(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs) {
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const NamedPath& o = outputs[k];
    if (o.path.empty()) return o.what + ": the path is empty";
    bool direct = false;
    try {
      direct = resolve_output_path(o.path).direct;
    } catch (const Error&) {
      continue;  // a directory, a socket, ...: creating the file says so
    }
    if (direct) continue;  // a device or FIFO is written in place: several outputs may share it
    for (const NamedPath& in : inputs)
      if (!in.path.empty() && same_file(o.path, in.path))
        return o.what + " " + o.path + ": the same file as " + in.what + " " + in.path +
               " (an output never replaces an input)";
    for (std::size_t j = 0; j < k; ++j)
      if (same_file(o.path, outputs[j].path))
        return outputs[j].what + " " + outputs[j].path + " and " + o.what + " " + o.path + " are the same file";
  }
  return std::nullopt;
}

void ensure_standard_descriptors() {
  for (int fd = 0; fd <= 2; ++fd) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    if (fd == STDOUT_FILENO) g_stdout_closed = true;
    // the lowest free descriptor: fd itself; read-only, so that writes to it fail instead of vanishing
    const int got = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (got >= 0 && got != fd) ::close(got);
  }
}

bool stdout_was_closed() { return g_stdout_closed; }

std::optional<std::string> stdout_error() {
  errno = 0;
  std::cout.flush();  // with the streams synchronised (the default), this is stdout's fflush: its errno counts
  int err = errno;
  const bool flushed = std::fflush(stdout) == 0;
  if (err == 0) err = errno;
  if (flushed && !std::ferror(stdout) && !std::cout.bad() && !std::cout.fail()) return std::nullopt;
  std::string why = g_stdout_closed ? "it is closed" : err ? std::strerror(err) : "a write failed";
  return "standard output: cannot write: " + why;
}

}  // namespace phiq::tools
