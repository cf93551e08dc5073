// The commands of `phiq`, one file each (run.cpp, batch.cpp, ...). Each register_* function adds its subcommand
// to the application with its options, declared next to the command that reads them, and returns what main()
// runs when that subcommand was given.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace phiq::tools {

// A subcommand and its action, which returns the exit status (tools/README.md, "Exit status and errors").
struct Command {
  CLI::App* subcommand = nullptr;
  std::function<int()> run;
};

// In the order `phiq --help` lists them.
Command register_run(CLI::App& app);
Command register_generate(CLI::App& app);
Command register_convert(CLI::App& app);
Command register_batch(CLI::App& app);
Command register_assemble(CLI::App& app);
Command register_check(CLI::App& app);
Command register_plot(CLI::App& app);
Command register_animate(CLI::App& app);
Command register_compare(CLI::App& app);
Command register_sweep_accuracy(CLI::App& app);
Command register_tolerance(CLI::App& app);
Command register_clearance(CLI::App& app);
Command register_modes(CLI::App& app);

}  // namespace phiq::tools
