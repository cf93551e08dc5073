// The processes of one `phiq batch`: MPI ranks when phiq was started by mpirun (and built with MPI), else one
// process. Rank 0 hands out the cases one at a time, to its own threads and to every other rank's, as each asks
// (cases near a singular position cost ten times the others: a static split would wait for the slowest rank), and
// writes every case's rows itself, in case order, so that the file is the one a single process writes.
//
// The protocol, one message each way per case: a worker thread of rank r > 0 sends rank 0, with its thread number
// as the tag, a case's result and a request for its next case, and rank 0 answers on that tag with a case, or −1
// when there is none (or the batch stops). The request goes out when the worker starts a case, carrying the
// result of the case before, so that the answer travels while the case runs and the worker never waits for it
// (one case in reserve per worker); a last message without a request (a "bye") carries the last result. Only
// rank 0 writes files and prints.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <new>
#include <optional>
#include <string>

namespace phiq::tools {

// What a worker sends rank 0 after a case: everything rank 0 needs to write and report it as if it had run it.
struct CaseMessage {
  // stopped: a signal ended it early; out of memory: the case threw std::bad_alloc on its rank (the worker's last
  // message: a rank's own "out of memory" goes to its silenced standard error, and would leave rank 0 waiting)
  enum class Kind : std::int32_t { kNone = 0, kDone = 1, kStopped = 2, kOutOfMemory = 3 };
  Kind kind = Kind::kNone;  // the result carried: none (the first request), a case done, stopped, out of memory
  bool asks = true;         // a request for the next case (false: the worker's last message)
  std::int64_t k = -1;      // the case
  bool complete = false, failed = false, on_shared_analysis = false;
  std::string line, outcome_json, text;  // report line, its --summary entry (JSON), its CSV rows
  std::string values;                    // its HDF5 row values (doubles, as bytes)
  std::int64_t setup_ns = 0, sweep_ns = 0, format_ns = 0;
  int signal = 0;  // kStopped: the signal that stopped it
  int rank = 0;    // the rank that sent it (set on arrival; not sent)
};

// Thrown by run_cases() on rank 0 once every worker has stopped, when a worker of rank `rank` > 0 ran out of memory
// in case `k` (running it or sending its result; −1: before its first case): a std::bad_alloc, told by rank 0 with
// the rank that ran out.
struct RankOutOfMemory : std::bad_alloc {
  RankOutOfMemory(int r, std::int64_t c) : rank(r), k(c) {}
  const char* what() const noexcept override { return "out of memory on another MPI rank"; }
  int rank;
  std::int64_t k;
};

// The job: size() ranks (1 without mpirun). Rank 0 is the writer.
class BatchRanks {
 public:
  // Joins the MPI job when phiq runs under mpirun (Open MPI's OMPI_COMM_WORLD_SIZE, or PMI_SIZE / PMIX_RANK, in
  // the environment) and was built with MPI; else one process, and nothing of MPI is started (MPI_Init alone
  // costs 0.4 s). Throws phiq::Error when the MPI library cannot give a thread-safe job.
  static std::unique_ptr<BatchRanks> join();
  // join() for a command (`batch`, `tolerance`): refuses several mpirun processes of a phiq built without MPI
  // (each would do the whole `work`: exit 2) and silences every rank but 0 (its standard error and signal
  // messages: rank 0 says everything). nullptr after printing the one-line error, with the exit status in *status.
  static std::unique_ptr<BatchRanks> join_command(const std::string& command, const std::string& work, int* status);
  ~BatchRanks();  // finish(0), if not called
  // Leaves the job with the command's exit status: MPI_Finalize, or (abandon()) MPI_Abort with `status`, which
  // mpirun then returns. Returns `status`.
  int finish(int status);
  BatchRanks(const BatchRanks&) = delete;
  BatchRanks& operator=(const BatchRanks&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  // A description for messages and the summary: "3 MPI ranks" or "one process".
  std::string describe() const;
  // Whether phiq was started by mpirun with more than one rank but built without MPI (the ranks would each run
  // the whole batch and write the same file): the command refuses that.
  static bool launched_without_support();

  // Every rank's worker-thread count, summed on rank 0 (others: their own). Collective.
  int total_remote_workers(int my_threads);
  // All ranks agree on a status (the largest), so that a set-up error is every rank's. Collective.
  int agree(int status);

  // Worker side (rank > 0): a message to rank 0 in flight, and (m.asks) the answer on its way back.
  class Sent {
   public:
    ~Sent();  // waits for the send
    Sent(const Sent&) = delete;
    Sent& operator=(const Sent&) = delete;
    // The next case; nullopt: none. Waits by polling, the sleep between polls growing from 20 µs to 1 ms, rather
    // than in MPI's calls that spin a core the cases need.
    std::optional<std::int64_t> answer();

   private:
    friend class BatchRanks;
    Sent() = default;
    std::string bytes_;
    std::int64_t next_ = -1;
    void* send_ = nullptr;  // MPI_Request (mpi.h stays out of this header)
    void* recv_ = nullptr;
  };
  // Sends `m` to rank 0 on tag `worker`.
  std::unique_ptr<Sent> send(int worker, const CaseMessage& m);

  // Rank 0: the next worker message, if one has arrived (source rank and tag in *from, *tag); nullopt also when
  // `give_up` turned true while it was arriving (its sender may have died halfway).
  std::optional<CaseMessage> poll(int* from, int* tag, const std::function<bool()>& give_up);
  // Rank 0: the answer to (from, tag): the next case, or −1 (no more); not waited for once `give_up` is true.
  void answer(int from, int tag, std::int64_t k, const std::function<bool()>& give_up);
  // Rank 0: some remote worker never got its last answer (the batch stopped, or a rank died); another rank: one of
  // its workers could not send rank 0 its last message. MPI_Finalize would wait for it, so the job is left by
  // MPI_Abort (on rank 0 after the output is published).
  void abandon() { abandoned_ = true; }

 private:
  BatchRanks() = default;
  int rank_ = 0, size_ = 1;
  bool mpi_ = false, abandoned_ = false, finished_ = false;
};

// Where run_cases()'s std::bad_alloc `e` happened, for the command's one line: "on MPI rank R in case K" or "on MPI
// rank R before its first case" (a RankOutOfMemory), else "on T threads" (this process's `threads`).
std::string out_of_memory_where(const std::bad_alloc& e, int threads);

// What run_cases() does with a case.
struct CaseHandlers {
  std::function<void(std::size_t k, int worker)> run_here;          // rank 0: run case k and take its result
  std::function<CaseMessage(std::size_t k, int worker)> run_for_0;  // other ranks: run case k, for rank 0
  std::function<void(CaseMessage)> deliver;  // rank 0: another rank's message with a result (kDone, kStopped)
  std::function<bool()> halted;              // hand out no more cases (on rank 0; elsewhere: stop asking)
};

// Cases first … n − 1 on every rank's `threads` workers, handed out one at a time by rank 0 (the protocol above):
// on rank 0, its workers take the next case themselves (run_here) while the calling thread answers the other
// ranks' workers and delivers their results, one at a time; on another rank, its workers ask rank 0 and send it
// run_for_0's message. Returns when this rank's part is done: on rank 0, every case handed out and every worker's
// last message received, or at once when halted() (the workers still out then abandoned: BatchRanks::abandon).
// run_here and deliver may run at the same time (rank 0's workers and its answering thread). Returns the worker
// threads of the whole job on rank 0 (every rank's `threads` summed), this rank's own elsewhere. An exception of
// run_here (std::bad_alloc) stops the handing out of cases and is thrown here once rank 0's workers have stopped; a
// std::bad_alloc on another rank (a case, its result's message, the workers' start) ends that worker with a
// kOutOfMemory message, which stops the handing out too, and RankOutOfMemory is thrown here on rank 0 once every
// worker has sent its last message; a rank that cannot send even that aborts the job rather than leave rank 0 waiting.
int run_cases(BatchRanks& ranks, std::size_t first, std::size_t n, int threads, const CaseHandlers& h);

}  // namespace phiq::tools
