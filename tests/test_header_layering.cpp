// The layers of the public headers (engine/README.md): the output plan and the step view (output_plan.hpp) lie
// below the solver, the sweep and the writers, so that a CSV or HDF5 writer compiles against the plan and the
// model, not the sweep; and what the writers write is decided in engine/src/output/. Read from the headers' own
// `#include "phiq/..."` lines, followed transitively.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace header_layering {

namespace fs = std::filesystem;

const fs::path kHeaders = fs::path(PHIQ_SOURCE_DIR) / "engine" / "include";

// The phiq headers `header` (a path below engine/include, "phiq/sweep.hpp") includes directly.
std::vector<std::string> direct_includes(const std::string& header) {
  static const std::regex include(R"(^\s*#\s*include\s+[<"](phiq/[^">]+)[">])");
  std::vector<std::string> out;
  std::istringstream lines(phiq::test::file_text(kHeaders / header));
  std::smatch m;
  for (std::string line; std::getline(lines, line);)
    if (std::regex_search(line, m, include)) out.push_back(m[1]);
  return out;
}

// Every phiq header `header` includes, directly or through others (the generated version.hpp, not in the source
// tree, is taken as including none).
std::set<std::string> reached_from(const std::string& header) {
  std::set<std::string> seen;
  std::vector<std::string> todo{header};
  while (!todo.empty()) {
    const std::string h = todo.back();
    todo.pop_back();
    if (!fs::exists(kHeaders / h)) continue;
    for (const std::string& i : direct_includes(h))
      if (seen.insert(i).second) todo.push_back(i);
  }
  return seen;
}

std::vector<std::string> public_headers() {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(kHeaders / "phiq"))
    if (e.path().extension() == ".hpp") out.push_back(fs::relative(e.path(), kHeaders).generic_string());
  return out;
}

TEST(HeaderLayering, TheIncludeGraphIsRead) {
  // what phiq.hpp reaches: the reading of the include lines finds the headers (else the tests below pass on nothing)
  const std::set<std::string> all = reached_from("phiq/phiq.hpp");
  for (const char* h : {"phiq/sweep.hpp", "phiq/sensitivity.hpp", "phiq/csv_writer.hpp", "phiq/hdf5_writer.hpp",
                        "phiq/output_plan.hpp", "phiq/model.hpp", "phiq/types.hpp"})
    EXPECT_EQ(all.count(h), 1u) << h;
  EXPECT_EQ(reached_from("phiq/sweep.hpp").count("phiq/output_plan.hpp"), 1u);
}

TEST(HeaderLayering, NoHeaderReachesItself) {
  const std::vector<std::string> headers = public_headers();
  ASSERT_GT(headers.size(), 30u);
  for (const std::string& h : headers) EXPECT_EQ(reached_from(h).count(h), 0u) << h << " includes itself";
}

// The output plan and the step view, and the writers that read them, include neither the sweep nor the solver
// (directly or through another phiq header): a writer is built against the plan and the model.
TEST(HeaderLayering, ThePlanAndTheWritersIncludeNoSweepOrSolver) {
  const std::vector<std::string> above = {"phiq/sweep.hpp",    "phiq/sensitivity.hpp",  "phiq/stepper.hpp",
                                          "phiq/batch.hpp",    "phiq/scene.hpp",        "phiq/kinematics.hpp",
                                          "phiq/assembly.hpp", "phiq/rank_analysis.hpp"};
  for (const char* header : {"phiq/output_plan.hpp", "phiq/csv_writer.hpp", "phiq/hdf5_writer.hpp"}) {
    const std::set<std::string> reached = reached_from(header);
    for (const std::string& h : above) EXPECT_EQ(reached.count(h), 0u) << header << " includes " << h;
  }
  // the plan and the writers sit on the base types: not the model (declared, read in their sources), its
  // workspace or the linear solvers either
  for (const char* header : {"phiq/output_plan.hpp", "phiq/csv_writer.hpp", "phiq/hdf5_writer.hpp"}) {
    const std::set<std::string> reached = reached_from(header);
    for (const char* h : {"phiq/model.hpp", "phiq/workspace.hpp", "phiq/linear_solver.hpp"})
      EXPECT_EQ(reached.count(h), 0u) << header << " includes " << h;
  }
}

// What the writers write of an output plan is decided with them, in engine/src/output/: no other stage defines a
// member of OutputPlan.
TEST(HeaderLayering, TheOutputPlansMembersAreDefinedInOutput) {
  static const std::regex definition(R"(^[A-Za-z_].*\bOutputPlan::[a-z_]+\s*\()");
  const fs::path src = fs::path(PHIQ_SOURCE_DIR) / "engine" / "src";
  int in_output = 0;
  for (const auto& e : fs::recursive_directory_iterator(src)) {
    if (e.path().extension() != ".cpp") continue;
    const bool output = e.path().parent_path().filename() == "output";
    std::istringstream lines(phiq::test::file_text(e.path()));
    for (std::string line; std::getline(lines, line);) {
      if (!std::regex_search(line, definition)) continue;
      EXPECT_TRUE(output) << fs::relative(e.path(), src).generic_string() << " defines " << line;
      in_output += output;
    }
  }
  EXPECT_GT(in_output, 0);  // OutputPlan::sensitivity_outputs(), found where it belongs
}

}  // namespace header_layering
