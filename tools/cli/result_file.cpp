#include "result_file.hpp"

#include "phiq/hdf5_reader.hpp"

namespace phiq::tools {

ResultFormat result_format(const std::string& option, const std::string& out_path) {
  if (option == "hdf5") return ResultFormat::kHdf5;
  if (option == "csv") return ResultFormat::kCsv;
  return phiq::has_hdf5_extension(out_path) ? ResultFormat::kHdf5 : ResultFormat::kCsv;
}

void check_hdf5_target(const std::string& path) {
  if (phiq::resolve_output_path(path).direct)
    throw phiq::Error(path +
                      ": cannot write HDF5 to a device, FIFO or open descriptor: it seeks and reads back what it "
                      "wrote (write to a file, or use --format csv)");
}

std::unique_ptr<phiq::Hdf5Writer> open_hdf5_results(const phiq::AtomicOutputFile& file, const phiq::Scene& scene,
                                                    int deflate, phiq::ColumnNaming naming) {
  if (file.direct() || file.temporary_path().empty())
    throw phiq::Error(file.path() + ": cannot write: HDF5 needs a named temporary file (phiq bug)");
  phiq::Hdf5Options o;
  o.scene_path = scene.path;
  o.scene_text = scene.text;
  o.parameters = scene.parameters;
  o.expected_rows = static_cast<std::size_t>(phiq::rows_written(scene.sweep));
  o.shown_path = file.path();
  o.deflate = deflate;
  o.shuffle = deflate > 0;  // the doubles' exponent bytes together: bench/README.md, "Writing HDF5"
  o.naming = naming;
  return std::make_unique<phiq::Hdf5Writer>(file.temporary_path(), *scene.model, scene.sweep, o);
}

void hand_blocks_to_disk(const phiq::Hdf5Writer& h5, std::size_t rows_before, phiq::AtomicOutputFile& file) {
  if (h5.rows() / h5.block_rows() != rows_before / h5.block_rows()) file.start_writeback();
}

}  // namespace phiq::tools
