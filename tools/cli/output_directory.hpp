// What phiq does to the directory an output file is written in, beyond the file itself: the temporaries that a
// killed phiq (kill -9, a power cut) left there, removed when phiq next writes beside them; and the advisory lock
// under which outputs are renamed onto their targets, so that two phiq commands writing the same files never leave
// the CSV of one with the summary of the other. Separate from atomic_file.*, which is about one file.
#pragma once

#include <string>
#include <vector>

namespace phiq {

// The name of the temporary of `target` written by process `pid`: "TARGET.tmp-PID", in the target's directory.
std::string temporary_name(const std::string& target, long pid);

// Removes, once per directory and process, the temporaries ("NAME.tmp-PID", regular files owned by this user) that
// processes no longer running left in the directory of `target` (kill(PID, 0) says ESRCH). Never throws; a file
// that cannot be removed stays.
void remove_stale_temporaries(const std::string& target);

// An exclusive advisory lock (flock) on the directories of some targets, taken in one order (device, inode) so
// that two commands locking the same directories cannot deadlock, and released when destroyed. A command waits
// for it; it is held only while finished outputs are renamed onto their targets, so the wait is short. Where a
// directory cannot be opened or locked (no read permission, a file system without flock) it is not locked.
class DirectoryLock {
 public:
  explicit DirectoryLock(const std::vector<std::string>& targets);
  ~DirectoryLock();
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;

 private:
  std::vector<int> fds_;
};

// The directory part of `path` ("." for a bare name).
std::string directory_of(const std::string& path);

}  // namespace phiq
