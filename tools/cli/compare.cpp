// `phiq compare A B`: two result files, CSV or HDF5 on either side (phiq/hdf5_reader.hpp), compared column by column
// within tolerances (phiq/csv_compare.hpp); exit 1 when they differ.
#include <cmath>
#include <iostream>
#include <memory>

#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "phiq/csv_compare.hpp"
#include "phiq/hdf5_reader.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

int cmd_compare(const std::string& a_path, const std::string& b_path, const phiq::CompareOptions& options) {
  phiq::CompareResult r;
  try {
    const phiq::CsvTable a = phiq::read_result_table(a_path), b = phiq::read_result_table(b_path);
    try {
      r = phiq::compare_csv(a, b, options);
    } catch (const phiq::Error& e) {  // a --columns name not in a file: a command-line error names its option
      return fail("compare: --columns: " + std::string(e.what()), 2);
    }
  } catch (const phiq::Error& e) {  // the file and line are named
    return fail(e.what(), 2);
  }
  if (r.equal) {
    std::cerr << "phiq: compare " << printable(a_path) << " " << printable(b_path) << ": " << r.summary() << "\n";
    return 0;
  }
  return fail("compare " + a_path + " " + b_path + ": " + r.summary(), 1);
}

}  // namespace

Command register_compare(CLI::App& app) {
  struct Args {
    std::string a, b;
    CompareOptions options;
  };
  auto a = std::make_shared<Args>();
  CLI::App* compare =
      app.add_subcommand("compare", "Compare two result files (CSV or HDF5) column by column within tolerances");
  compare->add_option("a", a->a, "First results file, CSV or HDF5 (e.g. the reference)")->required();
  compare->add_option("b", a->b, "Second results file, CSV or HDF5")->required();
  const CLI::Validator tolerance = number(0.0, HUGE_VAL, true, "a number >= 0 (inf: any difference)");
  compare->add_option("--rtol", a->options.rtol, "Relative tolerance: |a-b| <= atol + rtol*max(|a|,|b|)")
      ->capture_default_str()
      ->check(tolerance);
  compare->add_option("--atol", a->options.atol, "Absolute tolerance")->capture_default_str()->check(tolerance);
  compare->add_option("--columns", a->options.columns, "Compare only these columns (default: all; headers must match)")
      ->delimiter(',');
  return {compare, [a] { return cmd_compare(a->a, a->b, a->options); }};
}

}  // namespace phiq::tools
