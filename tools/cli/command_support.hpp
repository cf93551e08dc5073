// What the phiq commands share beyond their outputs and signals (cli_support.hpp): the one-line error, the scene
// loaded or its error reported, the wall clock of their timings, and the scene made square for a sweep (run and
// batch both solve on it).
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "phiq/import_asmt.hpp"
#include "phiq/import_model.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

// Prints "phiq: MSG" on standard error, as printable() makes it, and returns `code`, the command's exit status.
int fail(const std::string& msg, int code);

// `text` made one line of valid UTF-8 for standard error: control characters escaped as single_line() does, and
// every byte that is not part of a well-formed UTF-8 sequence (a path or scene name in Latin-1) written `\xNN`, so
// that a terminal or a log shows the bytes rather than mojibake, and a reader of the message can recover them.
std::string printable(const std::string& text);

// JSON text for `value`, with every string that is not valid UTF-8 (a path or a name with Latin-1 bytes) given
// U+FFFD for each invalid byte instead of throwing: a report is never lost to the bytes of a name.
std::string json_text(const nlohmann::ordered_json& value, int indent);

// What the scene read from standard input (`phiq run -`) is called in messages and reports.
inline constexpr const char* kStdinScene = "<stdin>";

// The scene parameters `--set NAME=VALUE` gives (one an occurrence), as overrides whose message about a name
// that is no parameter of the scene starts "--set". Throws phiq::Error "--set TEXT: WHY" for one that is not
// NAME=VALUE with a finite number, or that sets a parameter already set.
SceneOverrides parameter_settings(const std::vector<std::string>& sets);

// Registers `--set NAME=VALUE` (repeatable) on `command`, into `sets`.
void add_set_option(CLI::App* command, std::vector<std::string>* sets);

// `--sensitivity NAME` or `NAME=STEP` (repeatable): the parameters whose sensitivities a run delivers instead of
// the scene's output.sensitivities. Throws phiq::Error for a STEP that is not a number.
std::vector<SensitivityRequest> sensitivity_requests(const std::vector<std::string>& args);
void add_sensitivity_option(CLI::App* command, std::vector<std::string>* args);

// The scene at `path` ("-": standard input, named kStdinScene), with the parameters `sets` gives
// (parameter_settings()) and the sensitivities `sensitivity_args` asks for in place of its output.sensitivities
// (sensitivity_requests(): made as the scene is read, SceneOverrides::sensitivities); on a scene, --set or
// --sensitivity error its one line is printed and the result is empty (the command exits 2).
// The phiq scene of an `.asmt`, URDF, MJCF or SDF file (import_asmt(), import_model_file() with `options`), read
// once as a scene, what it leaves out listed on standard error ("phiq: not mapped: FILE:LINE: ..."); or its error,
// or that scene's ("PATH: the scene it converts to (phiq convert) is refused at LINE:COL: ..."), reported (exit
// status 2) and nothing.
std::optional<std::string> import_or_report(const std::string& path, const ImportOptions& options = {});

// `--drive JOINT=EXPR` (repeatable), `--time START END STEPS` and `--gravity X,Y,Z` on `command` (convert, run),
// into `drives`, `time`, `gravity`; `--rates` and `--forces` into `outputs`' ImportOptions::rates and ::forces.
void add_import_options(CLI::App* command, std::vector<std::string>* drives, std::vector<double>* time,
                        std::string* gravity, ImportOptions* outputs);

// The ImportOptions those options give for the model at `path` (`options` holds the flags' rates and forces); or,
// for a drive that is not JOINT=EXPR, a STEPS that is no whole number from 0 to 1e9, either option on a file that is
// not URDF, MJCF or SDF, a gravity that is not three finite numbers X,Y,Z, or `--rates`, `--forces` or
// `--gravity` on a scene, the one-line error "COMMAND: --drive ...: why" (exit 2).
std::optional<std::string> import_options(const std::string& command, const std::string& path,
                                          const std::vector<std::string>& drives, const std::vector<double>& time,
                                          const std::string& gravity, ImportOptions* options);

std::optional<Scene> load_or_report(const std::string& path, const std::vector<std::string>& sets = {},
                                    const std::vector<std::string>& sensitivity_args = {},
                                    const ImportOptions& import_options_given = {});

// How the scene given as `path` is named in messages: kStdinScene for "-", else the path.
inline std::string scene_label(const std::string& path) { return path == "-" ? kStdinScene : path; }

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The scene's assembly settings (tolerance, iteration budget) for the minimum-norm assembly.
AssemblyOptions assembly_options(const Scene& scene);

// "a, b, c".
std::string joined(const std::vector<std::string>& names);

// The scene made square for the sweep (prepare_scene(): a model with redundant constraints assembled by minimum
// norm and solved on its independent rows), or, when it cannot be (inconsistent, under-driven), the reason with
// the time it applies to.
std::optional<std::string> make_square(const Scene& scene, SquareScene* square);

// The command's exit status, made 3 when what it wrote to standard output was lost (a full disk, a closed
// descriptor): a report that never arrived is not a success.
int with_stdout_checked(int status);

}  // namespace phiq::tools
