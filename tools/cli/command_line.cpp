// Validators with readable one-line messages, and CLI11's errors made one line (command_line.hpp).
#include "command_line.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>

#include <tbb/info.h>

#include "command_support.hpp"
#include "phiq/text.hpp"

namespace phiq::tools {

CLI::Validator whole_number(long long lo, long long hi, const std::string& lo_means) {
  const std::string range = "a whole number from " + std::to_string(lo) +
                            (lo_means.empty() ? "" : " (" + lo_means + ")") + " to " + std::to_string(hi);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        long long v = 0;
        const char* end = text.data() + text.size();
        const auto [p, ec] = std::from_chars(text.data(), end, v);
        if (ec != std::errc() || p != end || v < lo || v > hi) return "expected " + range + ", got '" + text + "'";
        return "";
      },
      "INT");
}

CLI::Validator any_whole_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        long long v = 0;
        const char* end = text.data() + text.size();
        const auto [p, ec] = std::from_chars(text.data(), end, v);
        if (ec != std::errc() || p != end) return "expected a whole number, got '" + text + "'";
        return "";
      },
      "INT");
}

CLI::Validator number(double lo, double hi, bool allow_inf, const std::string& what) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const char* first = text.data() + (!text.empty() && text.front() == '+');
        const char* end = text.data() + text.size();
        double v = 0.0;
        const auto [p, ec] = std::from_chars(first, end, v);
        const bool ok = ec == std::errc() && p == end && first != end && !std::isnan(v) &&
                        (std::isfinite(v) || (allow_inf && v > 0)) && v >= lo && v <= hi;
        return ok ? "" : "expected " + what + ", got '" + text + "'";
      },
      "NUMBER");
}

CLI::Validator any_number() { return number(-HUGE_VAL, HUGE_VAL, false, "a finite number"); }

CLI::Validator one_of(const std::vector<std::string>& words) {
  std::string list;
  for (std::size_t k = 0; k < words.size(); ++k)
    list += (k == 0 ? "" : k + 1 == words.size() ? " or " : ", ") + words[k];
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        if (std::find(words.begin(), words.end(), text) != words.end()) return "";
        return "expected " + list + ", got '" + text + "'";
      },
      "WORD");
}

CLI::Validator output_path(const std::string& instead, bool spooled) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        if (text.empty()) return "the path is empty" + instead;
        if (text == "-") text = spooled ? "" : "/dev/stdout";
        return "";
      },
      "PATH");
}

CLI::Validator thread_count() { return whole_number(0, 1000000, "all cores"); }

int cap_threads(const std::string& command, int threads, bool quiet) {
  const int cores = tbb::info::default_concurrency();
  if (threads <= cores) return threads;
  if (!quiet)
    std::cerr << "phiq: " << command << ": --threads " << threads << ": " << cores << " cores here; running on "
              << cores << " threads\n";
  return cores;
}

int usage_error(CLI::App& app, int argc, char** argv, const CLI::ParseError& e) {
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) commands.push_back(sub->get_name());
  std::string command_list;
  for (const auto& c : commands) command_list += (command_list.empty() ? "" : ", ") + c;
  std::string command;  // the first word that is not an option: the command
  for (int i = 1; i < argc && command.empty(); ++i)
    if (argv[i][0] != '-' || std::string(argv[i]) == "-") command = argv[i];
  if (!command.empty() && std::find(commands.begin(), commands.end(), command) == commands.end())
    return fail("unknown command '" + phiq::single_line(command) + "' (commands: " + command_list + ")", 2);
  std::string what = e.what();
  std::replace(what.begin(), what.end(), '\n', ' ');
  while (!what.empty() && what.back() == ' ') what.pop_back();
  auto after = [&](const std::string& head) {
    const std::size_t at = what.find(head);
    return at == std::string::npos ? std::string() : what.substr(at + head.size());
  };
  // (by type: an error's get_name() is sometimes the subcommand's name)
  if (command.empty() && dynamic_cast<const CLI::RequiredError*>(&e)) {
    std::string option;  // `phiq --bogus`: CLI11 says only that a command is required
    for (int i = 1; i < argc && option.empty(); ++i) option = argv[i];
    what = option.empty() ? "a command is required (" + command_list + "); phiq --help says more"
                          : "unknown option " + phiq::single_line(option) + " (commands: " + command_list + ")";
  } else if (dynamic_cast<const CLI::ExtrasError*>(&e)) {
    const std::string extras = after("not expected: ");
    what = (extras.empty() || extras[0] == '-' ? "unknown option " : "unexpected argument ") + extras;
  } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) && what.find(" required ") != std::string::npos &&
             what.find("missing") != std::string::npos) {
    what = what.substr(0, what.find(':')) + ": a value is required";
  } else if (dynamic_cast<const CLI::ConversionError*>(&e) && what.rfind("Could not convert: ", 0) == 0) {
    const std::string rest = after("Could not convert: ");
    const std::size_t eq = rest.find(" = ");
    what = eq == std::string::npos ? "cannot read " + rest
                                   : rest.substr(0, eq) + ": cannot read '" + rest.substr(eq + 3) + "'";
  }
  return fail((command.empty() ? "" : command + ": ") + phiq::single_line(what), 2);
}

}  // namespace phiq::tools
