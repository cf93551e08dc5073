// `phiq batch SCENE CASES -o OUT.csv|OUT.h5 --resume`: an interrupted batch completed. The cases an earlier run of
// the same batch committed to OUT (whole cases, in case order: batch_file.cpp) are kept, and the batch runs on from
// the case after the last of them, into a new file published as OUT when it ends, so that OUT.csv is the file one
// uninterrupted run writes, byte for byte (an HDF5 file: the same values), and the earlier one stays whole until
// then.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "atomic_file.hpp"
#include "phiq/types.hpp"  // phiq::Error

namespace phiq::tools {

// OUT is not the earlier output of this batch (exit 2).
struct ResumeError : Error {
  using Error::Error;
};

struct ResumePoint {
  std::size_t first = 0;              // the first case to run (0: the whole batch)
  std::size_t cases_in_file = 0;      // the cases OUT holds
  std::vector<char> in_file;          // per case before `first`: 1 in OUT, 0 left out (it failed earlier)
  std::uint64_t bytes = 0;            // OUT's size (CSV): the bytes kept
  std::size_t rows = 0;               // OUT's rows: those kept
  std::size_t last_case_rows = 0;     // the rows of the last case in OUT (case first − 1)
  std::uint64_t last_case_bytes = 0;  // where that case begins: its first row's byte (CSV) …
  std::size_t last_case_row = 0;      // … and row
};

// Where the batch of `cases` cases whose CSV begins with `header` (its newline included) goes on after OUT: a
// missing OUT is the whole batch. Throws ResumeError "OUT: --resume: …" for a file that is not such a batch's:
// another header, a row that does not begin with a case of the batch or goes back in case order, a last row
// without its newline.
ResumePoint read_resume_point(const std::string& out, const std::string& header, std::size_t cases);

// The same for an HDF5 batch output (`columns`: the batch's, `case` first): read back as its table (the CSV's
// columns and doubles); its cases must be whole numbers of the batch, in order. Throws ResumeError as above, and
// for a file that is not phiq's HDF5 results.
ResumePoint read_resume_point_hdf5(const std::string& out, const std::vector<std::string>& columns, std::size_t cases);

// OUT cut inside its last case (an earlier run stopped by a full disk, a file copied in part): when that case
// has fewer rows than it writes (`case_rows`), it is dropped from `p`, to be run again. Throws ResumeError for
// more rows than that.
void drop_unfinished_case(ResumePoint& p, std::size_t case_rows, const std::string& out);

// Copies OUT's bytes (the cases kept) into `file`, the batch's new output; returns how many. Throws phiq::Error.
std::uint64_t copy_resumed_cases(const std::string& out, const ResumePoint& p, AtomicOutputFile& file);

}  // namespace phiq::tools
