// The format `phiq run` writes its results in (CSV, HDF5), and HDF5 results written atomically: HDF5 writes a file
// by its name, at random offsets, and resolves that name to a real path (so not /proc/self/fd/N of an unnamed
// O_TMPFILE temporary: HDF5 1.10 refuses it). It therefore writes the named temporary of an AtomicOutputFile held
// closed between writes ("TARGET.tmp-PID"), which commit() renames onto the target as it does a CSV. A failed or
// interrupted phiq removes it and leaves the target as it was; one killed by SIGKILL leaves the temporary, removed
// when phiq next writes in that directory (remove_stale_temporaries).
#pragma once

#include <memory>
#include <string>

#include "atomic_file.hpp"
#include "phiq/hdf5_writer.hpp"
#include "phiq/scene.hpp"

namespace phiq::tools {

enum class ResultFormat { kCsv, kHdf5 };

// `--format` given ("csv", "hdf5"), or empty: HDF5 for an output path ending in .h5 or .hdf5 (any case), else CSV.
ResultFormat result_format(const std::string& option, const std::string& out_path);

// Throws phiq::Error "PATH: cannot write HDF5 to a device, FIFO or open descriptor: ..." when `path` leads to one
// (resolve_output_path: direct): HDF5 seeks and reads back what it wrote. Also resolve_output_path's errors.
void check_hdf5_target(const std::string& path);

// An Hdf5Writer on the named temporary of `file` (added with Hold::kClosedBetweenWrites, not direct), with the
// scene's path and text as attributes and chunks sized for its steps + 1 rows; `deflate` > 0: shuffle and deflate at
// that level; columns named as `naming` names the CSV's. Its errors name file.path().
// Throws phiq::Error "PATH: cannot write: REASON".
std::unique_ptr<phiq::Hdf5Writer> open_hdf5_results(const phiq::AtomicOutputFile& file, const phiq::Scene& scene,
                                                    int deflate = 0,
                                                    phiq::ColumnNaming naming = phiq::ColumnNaming::kDotted);

// After rows were appended to `h5` (it held `rows_before` rows): when it has written a block to its file since, that
// block goes on to the disk while the work runs (AtomicOutputFile::start_writeback(), as write() does for a CSV
// every 8 MiB), so that the fsync before the commit waits for the last block, not for the whole file: an
// interrupted batch publishes within the second mpirun gives it.
void hand_blocks_to_disk(const phiq::Hdf5Writer& h5, std::size_t rows_before, phiq::AtomicOutputFile& file);

}  // namespace phiq::tools
