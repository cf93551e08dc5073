// MPI for `phiq batch` (batch_ranks.hpp), or one process when phiq is built without MPI or not run by mpirun.
#include "batch_ranks.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <functional>
#include <iostream>
#include <limits>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cli_support.hpp"      // quiet_interrupts
#include "command_support.hpp"  // fail
#include "phiq/types.hpp"       // phiq::Error

#if PHIQ_WITH_MPI
#include <mpi.h>
#endif

namespace phiq::tools {

namespace {

// Started by a launcher with more than one process (Open MPI, or any PMI / PMIx launcher)?
int launched_size() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* s = std::getenv(v)) return std::atoi(s);
  return std::getenv("PMIX_RANK") ? 2 : 1;  // PMIx without a size: a launcher all the same
}

#if PHIQ_WITH_MPI
// A message, flat: the fixed fields, then each string as its length and bytes.
std::string pack(const CaseMessage& m) {
  std::string b;
  auto put = [&b](const void* p, std::size_t n) { b.append(static_cast<const char*>(p), n); };
  auto put_string = [&](const std::string& s) {
    const std::uint64_t n = s.size();
    put(&n, sizeof n);
    put(s.data(), s.size());
  };
  const std::int32_t kind = static_cast<std::int32_t>(m.kind);
  const std::int32_t flags =
      (m.complete ? 1 : 0) | (m.failed ? 2 : 0) | (m.on_shared_analysis ? 4 : 0) | (m.asks ? 8 : 0);
  const std::int32_t sig = m.signal;
  put(&kind, sizeof kind);
  put(&flags, sizeof flags);
  put(&sig, sizeof sig);
  put(&m.k, sizeof m.k);
  put(&m.setup_ns, sizeof m.setup_ns);
  put(&m.sweep_ns, sizeof m.sweep_ns);
  put(&m.format_ns, sizeof m.format_ns);
  for (const std::string* s : {&m.line, &m.outcome_json, &m.text, &m.values}) put_string(*s);
  return b;
}

CaseMessage unpack(const char* b, std::size_t size) {
  CaseMessage m;
  std::size_t at = 0;
  auto get = [&](void* p, std::size_t n) {
    if (at + n > size) throw Error("batch: a truncated message between MPI ranks (phiq bug)");
    std::memcpy(p, b + at, n);
    at += n;
  };
  auto get_string = [&](std::string& s) {
    std::uint64_t n = 0;
    get(&n, sizeof n);
    if (n > size - at) throw Error("batch: a truncated message between MPI ranks (phiq bug)");
    s.assign(b + at, n);
    at += n;
  };
  std::int32_t kind = 0, flags = 0, sig = 0;
  get(&kind, sizeof kind);
  get(&flags, sizeof flags);
  get(&sig, sizeof sig);
  m.kind = static_cast<CaseMessage::Kind>(kind);
  m.complete = flags & 1, m.failed = flags & 2, m.on_shared_analysis = flags & 4, m.asks = flags & 8;
  m.signal = sig;
  get(&m.k, sizeof m.k);
  get(&m.setup_ns, sizeof m.setup_ns);
  get(&m.sweep_ns, sizeof m.sweep_ns);
  get(&m.format_ns, sizeof m.format_ns);
  for (std::string* s : {&m.line, &m.outcome_json, &m.text, &m.values}) get_string(*s);
  return m;
}

// Waits for `r` by polling (Open MPI's blocking calls spin a core, which the cases on this machine need) until it
// completes (true) or `give_up` says to stop waiting (false: a peer that died mid-message never completes it).
// The sleep between polls grows from 20 µs to 1 ms: each wake-up costs (in a virtual machine, most of rank 0's
// time went to them at a fixed 50 µs), and an answer usually arrives while the worker still runs its case.
bool wait_politely(MPI_Request* r, const std::function<bool()>& give_up = {}) {
  for (int done = 0, pause_us = 20;; pause_us = std::min(2 * pause_us, 1000)) {
    MPI_Test(r, &done, MPI_STATUS_IGNORE);
    if (done) return true;
    if (give_up && give_up()) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(pause_us));
  }
}
#endif

}  // namespace

bool BatchRanks::launched_without_support() {
#if PHIQ_WITH_MPI
  return false;
#else
  return launched_size() > 1;
#endif
}

std::unique_ptr<BatchRanks> BatchRanks::join() {
  std::unique_ptr<BatchRanks> r(new BatchRanks());
#if PHIQ_WITH_MPI
  if (launched_size() > 1) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_MULTIPLE, &provided);
    r->mpi_ = true;
    if (provided < MPI_THREAD_MULTIPLE) {
      MPI_Finalize();
      throw Error("batch: this MPI library cannot serve several threads per rank (MPI_THREAD_MULTIPLE)");
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &r->rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &r->size_);
  }
#endif
  return r;
}

std::unique_ptr<BatchRanks> BatchRanks::join_command(const std::string& command, const std::string& work, int* status) {
  if (launched_without_support()) {
    *status = fail(command + ": started by mpirun with several processes, but this phiq was built without MPI " +
                       "(PHIQ_MPI=OFF): each would run the whole " + work + "; run it without mpirun",
                   2);
    return nullptr;
  }
  std::unique_ptr<BatchRanks> ranks;
  try {
    ranks = join();
  } catch (const Error& e) {
    *status = fail(e.what(), 1);
    return nullptr;
  }
  if (ranks->rank() > 0) {  // rank 0 says everything (a worker rank's errors are its too)
    std::cerr.rdbuf(nullptr);
    quiet_interrupts();
  }
  return ranks;
}

BatchRanks::~BatchRanks() { (void)finish(0); }

int BatchRanks::finish(int status) {
  if (finished_) return status;
  finished_ = true;
#if PHIQ_WITH_MPI
  if (mpi_) {
    if (abandoned_) MPI_Abort(MPI_COMM_WORLD, status == 0 ? 1 : status);
    MPI_Finalize();
  }
#endif
  return status;
}

std::string BatchRanks::describe() const {
  return size_ == 1 ? std::string("one process") : std::to_string(size_) + " MPI ranks";
}

int BatchRanks::total_remote_workers(int my_threads) {
#if PHIQ_WITH_MPI
  if (mpi_) {
    const int mine = rank_ == 0 ? 0 : my_threads;
    int total = 0;
    MPI_Reduce(&mine, &total, 1, MPI_INT, MPI_SUM, 0, MPI_COMM_WORLD);
    return rank_ == 0 ? total : my_threads;
  }
#endif
  (void)my_threads;
  return 0;
}

int BatchRanks::agree(int status) {
#if PHIQ_WITH_MPI
  if (mpi_) {
    int all = 0;
    MPI_Allreduce(&status, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return all;
  }
#endif
  return status;
}

BatchRanks::Sent::~Sent() {
#if PHIQ_WITH_MPI
  for (void* r : {send_, recv_})
    if (r) {
      auto* request = static_cast<MPI_Request*>(r);
      if (*request != MPI_REQUEST_NULL) wait_politely(request);
      delete request;
    }
#endif
}

std::optional<std::int64_t> BatchRanks::Sent::answer() {
#if PHIQ_WITH_MPI
  if (!recv_) return std::nullopt;
  wait_politely(static_cast<MPI_Request*>(recv_));
  if (next_ < 0) return std::nullopt;
  return next_;
#else
  return std::nullopt;
#endif
}

std::unique_ptr<BatchRanks::Sent> BatchRanks::send(int worker, const CaseMessage& m) {
  std::unique_ptr<Sent> s(new Sent());
#if PHIQ_WITH_MPI
  s->bytes_ = pack(m);
  if (s->bytes_.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw Error("batch: a case of more than 2 GiB of rows cannot be sent between MPI ranks: fewer steps per case");
  // every allocation before anything is posted: a request posted and then left by a std::bad_alloc would be waited
  // for by ~Sent for ever
  auto send = std::make_unique<MPI_Request>(), recv = m.asks ? std::make_unique<MPI_Request>() : nullptr;
  if (recv) {
    MPI_Irecv(&s->next_, 1, MPI_INT64_T, 0, worker, MPI_COMM_WORLD, recv.get());
    s->recv_ = recv.release();
  }
  s->send_ = send.release();  // ~Sent waits for it and frees it
  MPI_Isend(s->bytes_.data(), static_cast<int>(s->bytes_.size()), MPI_BYTE, 0, worker, MPI_COMM_WORLD,
            static_cast<MPI_Request*>(s->send_));
#else
  (void)worker, (void)m;
#endif
  return s;
}

std::optional<CaseMessage> BatchRanks::poll(int* from, int* tag, const std::function<bool()>& give_up) {
#if PHIQ_WITH_MPI
  int arrived = 0;
  MPI_Status st;
  MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &st);
  if (!arrived) return std::nullopt;
  int count = 0;
  MPI_Get_count(&st, MPI_BYTE, &count);
  // (not zeroed: received into; a rank killed while sending its rows leaves the message half-arrived, and
  // `give_up` ends the wait, the buffer then left to MPI_Abort)
  auto* bytes = new char[static_cast<std::size_t>(count)];
  MPI_Request r;
  MPI_Irecv(bytes, count, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, &r);
  if (!wait_politely(&r, give_up)) return std::nullopt;
  const std::unique_ptr<char[]> owned(bytes);
  *from = st.MPI_SOURCE;
  *tag = st.MPI_TAG;
  return unpack(bytes, static_cast<std::size_t>(count));
#else
  (void)from, (void)tag, (void)give_up;
  return std::nullopt;
#endif
}

void BatchRanks::answer(int from, int tag, std::int64_t k, const std::function<bool()>& give_up) {
#if PHIQ_WITH_MPI
  MPI_Request r;
  MPI_Isend(&k, 1, MPI_INT64_T, from, tag, MPI_COMM_WORLD, &r);
  (void)wait_politely(&r, give_up);
#else
  (void)from, (void)tag, (void)k, (void)give_up;
#endif
}

namespace {

// Rank 0's side: each message of another rank's worker handled (`handle` returns the case to answer a request
// with, −1 for none) until every worker has sent its last message. A batch that halts (a signal: mpirun sends
// SIGTERM when a rank dies, and SIGKILL a second later) waits for no one: its committed cases are published at
// once, and the workers left unanswered (BatchRanks::abandon).
void serve_remote_workers(BatchRanks& ranks, int workers, const std::function<bool()>& halted,
                          const std::function<std::int64_t(CaseMessage)>& handle) {
  int finished = 0;
  int pause_us = 20;  // between polls while nothing arrives: growing to 1 ms (wake-ups cost: wait_politely)
  while (finished < workers) {
    if (halted()) return ranks.abandon();
    int from = 0, tag = 0;
    std::optional<CaseMessage> m = ranks.poll(&from, &tag, halted);
    if (!m) {
      std::this_thread::sleep_for(std::chrono::microseconds(pause_us));
      pause_us = std::min(2 * pause_us, 1000);
      continue;
    }
    pause_us = 20;
    m->rank = from;
    const bool asks = m->asks;
    const std::int64_t k = handle(std::move(*m));
    if (asks)
      ranks.answer(from, tag, k, halted);
    else
      ++finished;  // its last message: that worker is done
  }
}

}  // namespace

std::string out_of_memory_where(const std::bad_alloc& e, int threads) {
  if (const auto* r = dynamic_cast<const RankOutOfMemory*>(&e))
    return "on MPI rank " + std::to_string(r->rank) +
           (r->k < 0 ? " before its first case" : " in case " + std::to_string(r->k));
  return "on " + std::to_string(threads) + " threads";
}

int run_cases(BatchRanks& ranks, std::size_t first, std::size_t n, int threads, const CaseHandlers& h) {
  const int remote_workers = ranks.total_remote_workers(threads);
  tbb::task_arena arena(threads);
  if (ranks.rank() > 0) {  // a worker rank: its threads ask rank 0 for cases and send it their results
    // Rank 0 waits for every worker's last message: a worker that cannot send it (or never starts) would leave rank
    // 0 waiting for ever, so whatever runs out of memory, the last message is "out of memory", sent by the worker or
    // else by this thread once the arena has returned; when even that fails, the job is aborted (BatchRanks::abandon).
    const std::unique_ptr<std::atomic<bool>[]> said_last(new std::atomic<bool>[static_cast<std::size_t>(threads)] {});
    auto say_out_of_memory = [&](int w, std::int64_t k) {
      CaseMessage m;
      m.kind = CaseMessage::Kind::kOutOfMemory;
      m.k = k;
      m.asks = false;
      try {
        (void)ranks.send(w, m);
        said_last[static_cast<std::size_t>(w)] = true;
      } catch (const std::bad_alloc&) {
      }
    };
    try {
      arena.execute([&] {
        tbb::parallel_for(
            0, threads,
            [&](int w) {
              std::int64_t held = -1;  // the case this worker holds: running it, or sending its result
              try {
                CaseMessage last;  // the result of the case before: none yet (a request alone)
                std::optional<std::int64_t> k = ranks.send(w, last)->answer();
                while (k && !h.halted()) {
                  // the next case asked for now, with the last result: its answer travels while this case runs
                  const std::unique_ptr<BatchRanks::Sent> next = ranks.send(w, last);
                  held = *k;
                  last = h.run_for_0(static_cast<std::size_t>(*k), w);
                  k = next->answer();
                }
                last.asks = false;  // the last result, and no request: this worker is done
                (void)ranks.send(w, last);
                said_last[static_cast<std::size_t>(w)] = true;
              } catch (const std::bad_alloc&) {  // running a case or packing its result: told to rank 0, which stops
                say_out_of_memory(w, held);      // the batch (the case's memory is freed by now)
              }
            },
            tbb::simple_partitioner());
      });
    } catch (const std::bad_alloc&) {  // the arena's own start
    }
    for (int w = 0; w < threads; ++w) {
      if (!said_last[static_cast<std::size_t>(w)]) say_out_of_memory(w, -1);
      if (!said_last[static_cast<std::size_t>(w)]) ranks.abandon();
    }
    return threads;
  }
  std::atomic<std::size_t> next_case{first};
  // The first exception of a worker (out of memory), rethrown here once every worker has stopped: escaping the
  // thread below, it would abort the process. The other workers take no case after it.
  std::exception_ptr failure;
  std::mutex failure_mutex;
  std::atomic<bool> failed{false};
  auto next = [&]() -> std::optional<std::size_t> {
    if (h.halted() || failed.load()) return std::nullopt;
    const std::size_t k = next_case++;
    return k < n ? std::optional<std::size_t>(k) : std::nullopt;
  };
  // rank 0's workers, each taking the next case in order (cases complete about in order, so few wait), while this
  // thread answers the other ranks' workers, if any
  auto fail_with_current = [&] {
    const std::lock_guard<std::mutex> lock(failure_mutex);
    if (!failure) failure = std::current_exception();
    failed = true;
  };
  std::thread local([&] {
    try {  // the arena's own start (its workers' memory) may fail too, before any case
      arena.execute([&] {
        tbb::parallel_for(
            0, threads,
            [&](int w) {
              try {
                for (std::optional<std::size_t> k; (k = next());) h.run_here(*k, w);
              } catch (...) {
                fail_with_current();
              }
            },
            tbb::simple_partitioner());
      });
    } catch (...) {
      fail_with_current();
    }
  });
  std::optional<RankOutOfMemory> remote_failure;  // the first worker of another rank that ran out of memory
  serve_remote_workers(ranks, remote_workers, h.halted, [&](CaseMessage m) {
    if (m.kind == CaseMessage::Kind::kOutOfMemory) {
      if (!remote_failure) remote_failure.emplace(m.rank, m.k);
      failed = true;  // no case handed out after it, here or elsewhere
      return std::int64_t{-1};
    }
    const bool asks = m.asks;
    if (m.kind != CaseMessage::Kind::kNone) h.deliver(std::move(m));
    if (!asks) return std::int64_t{-1};
    const std::optional<std::size_t> k = next();
    return k ? static_cast<std::int64_t>(*k) : std::int64_t{-1};
  });
  local.join();
  if (failure) std::rethrow_exception(failure);
  if (remote_failure) throw *remote_failure;
  return threads + remote_workers;
}

}  // namespace phiq::tools
