// Output files that appear only when complete (write, then rename), and where an output path leads: the commands'
// way of never leaving half a file, and of refusing an output that would replace an input. A tool's concern, not
// the engine's: the engine formats rows (phiq/csv_writer.hpp); the commands decide where the text goes.
#pragma once

#include <cstdio>
#include <cstdint>
#include <string>

#include "phiq/types.hpp"  // phiq::Error, which these functions throw

namespace phiq {

// Where an output path leads: what AtomicOutputFile writes, found before anything is created.
struct OutputPath {
  // The file written: the path given, or for a symbolic link (a chain of them) its final target, so that the link
  // stays and its target is replaced; a target relative to its link's directory is joined to it.
  std::string target;
  bool exists = false;  // `target` exists (as a regular file, unless `direct`)
  // Written in place, not replaced: a character or block device (`/dev/null`), a FIFO, or one of the process's
  // own descriptors (`/dev/stdout`, `/dev/fd/N`, `/proc/self/fd/N`: written through a copy of the descriptor, at
  // its offset). Nothing can be taken back from such a file: a failure after the first write leaves what was
  // written.
  bool direct = false;
  // For a direct descriptor path, the descriptor (else −1).
  int descriptor = -1;
};

// Resolves `path` as AtomicOutputFile will write it. Throws phiq::Error "PATH: cannot write: REASON" for an empty
// path, a directory, a socket, a loop of symbolic links or a file that cannot be examined.
OutputPath resolve_output_path(const std::string& path);

// True when the two paths name the same file as outputs or inputs: the same existing file (hard links and symbolic
// links included), or, for files that do not exist yet, the same resolved target. Never throws.
bool same_file(const std::string& a, const std::string& b);

// An output file that appears only when complete: written to a temporary in its target's directory
// (resolve_output_path: a symbolic link is followed, and its target replaced) and renamed onto the target by
// commit(). The temporary has no name (O_TMPFILE) where the file system allows it, so that a process killed by
// SIGKILL leaves nothing; at publish() it is linked as "TARGET.tmp-PID" and renamed at once. Elsewhere, and for
// Hold::kClosedBetweenWrites, it is the named file "TARGET.tmp-PID" from the start; such files left by processes
// that no longer run are removed when a file is next written beside them (remove_stale_temporaries). If it is
// destroyed without commit() (failure, exception), the temporary is removed and an existing file at the target is
// left untouched. A device, a FIFO or an open descriptor of the process (OutputPath::direct) is
// opened at once and written in place instead: no temporary, no rename (`-o /dev/null` stays a device).
class AtomicOutputFile {
 public:
  // How a temporary is held between writes. kClosedBetweenWrites closes it once created and opens it again (to
  // append) for each write() and for finish(): a command with thousands of outputs (`phiq batch`, one per case)
  // then holds no descriptor per output, and cannot run out of them. A direct target is always held open.
  enum class Hold { kOpen, kClosedBetweenWrites };
  // Creates the temporary (or opens the direct target; a FIFO waits here for its reader). Throws phiq::Error
  // "PATH: cannot write: REASON" if it cannot (resolve_output_path's errors included).
  explicit AtomicOutputFile(std::string path, Hold hold = Hold::kOpen);
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  void write(const std::string& data);  // throws phiq::Error on an I/O error
  // Hands what has reached the temporary so far to the disk, without waiting (a hint: errors ignored), for files
  // another writer fills by their name (HDF5), so that finish()'s fsync does not wait for all of it at the end.
  // write() does the same by itself every 8 MiB.
  void start_writeback();
  // Takes the temporary back to its first `size` bytes, dropping what is buffered and not yet written: after a
  // failed write, a batch's file is cut back to the cases it holds whole. Throws phiq::Error for a direct file
  // (nothing written there can be taken back), after finish(), or on an I/O error.
  void truncate(std::uint64_t size);
  // finish() then publish(), under the lock of the target's directory (DirectoryLock). Throws phiq::Error on an I/O
  // error (the temporary is then removed by the destructor).
  void commit();
  // Flushes and closes: to disk (fsync) for a temporary. After it only publish() remains; throws phiq::Error.
  void finish();
  // Renames the finished temporary onto the target (nothing to do for a direct file); throws phiq::Error. The
  // caller holds the DirectoryLock of the target (OutputSet does) when outputs must change together.
  void publish();

  const std::string& path() const { return path_; }      // as given
  const std::string& target() const { return target_; }  // the file replaced (resolve_output_path)
  // The named temporary file while it exists (until publish() or destruction); empty for a direct file and for an
  // unnamed temporary (nothing to remove on a signal).
  const std::string& temporary_path() const { return tmp_; }
  bool direct() const { return direct_; }      // written in place (OutputPath::direct)
  bool finished() const { return finished_; }  // finish() succeeded

 private:
  std::string path_, target_, tmp_;
  // Opens the closed temporary again to append to it (Hold::kClosedBetweenWrites); throws phiq::Error.
  void reopen();
  std::FILE* f_ = nullptr;
  bool direct_ = false, finished_ = false, committed_ = false;
  bool unnamed_ = false;  // an O_TMPFILE temporary, held open until publish()
  bool closed_between_writes_ = false;
  // Write-behind (write()): bytes written through the open temporary, and those handed to the disk so far.
  static constexpr std::uint64_t kWriteBehindBytes = std::uint64_t{8} << 20;
  std::uint64_t written_ = 0, flushed_ = 0;
};

}  // namespace phiq
