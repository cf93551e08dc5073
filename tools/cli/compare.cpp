// `phiq compare A B`: two result files, CSV or HDF5 on either side (phiq/hdf5_reader.hpp), compared column by column
// within tolerances (phiq/csv_compare.hpp); exit 1 when they differ. One side may be an `.asmt` file: its TimeSeries
// against the result's parts (phiq/import_asmt.hpp, asmt_comparison()).
#include <cmath>
#include <iostream>
#include <memory>

#include "command_line.hpp"
#include "command_support.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "compare_reports.hpp"
#include "phiq/csv_compare.hpp"
#include "phiq/hdf5_reader.hpp"
#include "phiq/import_asmt.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// The reports asked for (--json, --junit) are written on both verdicts, equal or not, and committed together;
// unreadable input (exit 2) writes none.
int cmd_compare(const CompareSubject& subject, const std::string& json_path, const std::string& junit_path) {
  const std::string &a_path = subject.a, &b_path = subject.b;
  std::vector<NamedPath> outs;
  if (!json_path.empty()) outs.push_back({"--json", json_path});
  if (!junit_path.empty()) outs.push_back({"--junit", junit_path});
  if (const auto clash = output_clash(outs, {{"the first results file", a_path}, {"the second results file", b_path}}))
    return fail("compare: " + *clash, 2);
  phiq::CompareResult r;
  const bool a_asmt = phiq::is_asmt_path(a_path), b_asmt = phiq::is_asmt_path(b_path);
  if (a_asmt && b_asmt)
    return fail("compare: " + a_path + ", " + b_path + ": two .asmt files; one must be a result", 2);
  try {
    phiq::CsvTable a = a_asmt ? phiq::CsvTable{} : phiq::read_result_table(a_path);
    phiq::CsvTable b = b_asmt ? phiq::CsvTable{} : phiq::read_result_table(b_path);
    if (a_asmt || b_asmt) {  // the TimeSeries' quantities on both sides, each table on its own side
      phiq::AsmtComparison c = phiq::asmt_comparison(a_asmt ? b : a, a_asmt ? a_path : b_path);
      a = std::move(a_asmt ? c.series : c.result), b = std::move(a_asmt ? c.result : c.series);
      for (const std::string& why : c.left_out) std::cerr << "phiq: compare: not compared: " << printable(why) << "\n";
    }
    try {
      r = phiq::compare_csv(a, b, subject.options);
    } catch (const phiq::Error& e) {  // a --columns name not in a file: a command-line error names its option
      return fail("compare: --columns: " + std::string(e.what()), 2);
    }
  } catch (const phiq::Error& e) {  // the file and line are named
    return fail(e.what(), 2);
  } catch (const phiq::SceneError& e) {  // an .asmt file that cannot be read, or holds no TimeSeries
    return fail(e.what(), 2);
  }
  try {
    OutputSet outputs;
    if (!json_path.empty()) outputs.add(json_path).write(compare_json(subject, r));
    if (!junit_path.empty()) outputs.add(junit_path).write(compare_junit(subject, r));
    outputs.commit();
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
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
    CompareSubject subject;
    std::string json, junit;
  };
  auto a = std::make_shared<Args>();
  CLI::App* compare =
      app.add_subcommand("compare", "Compare two result files (CSV or HDF5) column by column within tolerances");
  compare->add_option("a", a->subject.a, "First results file, CSV or HDF5 (e.g. the reference), or an .asmt file")
      ->required();
  compare->add_option("b", a->subject.b, "Second results file, CSV or HDF5, or an .asmt file with a TimeSeries")
      ->required();
  const CLI::Validator tolerance = number(0.0, HUGE_VAL, true, "a number >= 0 (inf: any difference)");
  compare->add_option("--rtol", a->subject.options.rtol, "Relative tolerance: |a-b| <= atol + rtol*max(|a|,|b|)")
      ->capture_default_str()
      ->check(tolerance);
  compare->add_option("--atol", a->subject.options.atol, "Absolute tolerance")->capture_default_str()->check(tolerance);
  compare
      ->add_option("--columns", a->subject.options.columns,
                   "Compare only these columns (default: all; headers must match)")
      ->delimiter(',');
  // a flag, not an option: `--json` alone (standard output) never takes the next argument, a CSV, for its file
  compare->add_flag("--json{-}", a->json, "Write the comparison as JSON to standard output, or --json=FILE")
      ->transform(output_path("", false));
  compare->add_option("--junit", a->junit, "Write the comparison as JUnit XML to this file (one test case per column)")
      ->transform(output_path("", false));
  return {compare, [a] { return with_stdout_checked(cmd_compare(a->subject, a->json, a->junit)); }};
}

}  // namespace phiq::tools
