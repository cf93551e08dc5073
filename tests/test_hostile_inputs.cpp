// The hostile-input catalogue (tests/hostile/*.yaml, format in tests/hostile/README.md): one test per case, each
// running the `phiq` command in a fresh directory on the files the case writes, and asserting what phiq promises
// for bad input and faults (tools/README.md, "Exit status and errors"): the documented exit status, one line on
// stderr that says what and where, every pre-existing file left byte for byte, and no file left behind that the
// case does not expect (no partial output, no temporary). Data-driven, so that a new hostile input is a few lines
// of YAML, not a test function; its own executable, since it needs neither the engine nor its headers.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "scratch_path.hpp"

namespace {

namespace fs = std::filesystem;

struct Case {
  std::string file, name;  // the catalogue file (category) and the case's name
  std::map<std::string, std::string> files, copies;
  std::string setup, prefix, run;
  int exit = 0;
  std::string stderr_regex, stdout_regex;
  std::map<std::string, std::string> match;  // file -> regex searched in its bytes afterwards
  int lines = 1;
  std::vector<std::string> keep, absent, created;
  bool any_files = false;  // `created: any`: the command may leave other files (checked by `absent`)
  double timeout = 30;
  bool sanitizers = true;  // `sanitizers: false`: not run in a sanitizer build (limits ASan cannot run under)
};

// `%xHH` in a case's texts is the byte HH, so that a catalogue in UTF-8 can hold the invalid bytes of hostile input.
std::string unescape(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 3 < s.size() && s[i + 1] == 'x' && std::isxdigit(static_cast<unsigned char>(s[i + 2])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 3]))) {
      out += static_cast<char>(std::stoi(s.substr(i + 2, 2), nullptr, 16));
      i += 3;
    } else {
      out += s[i];
    }
  }
  return out;
}

std::vector<std::string> strings(const YAML::Node& n) {
  std::vector<std::string> v;
  if (!n) return v;
  if (n.IsScalar()) return {unescape(n.as<std::string>())};
  for (const auto& e : n) v.push_back(unescape(e.as<std::string>()));
  return v;
}

std::vector<Case> load_catalogue() {
  std::vector<Case> cases;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(PHIQ_SOURCE_DIR) / "tests" / "hostile"))
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::set<std::string> names;
  for (const fs::path& f : files) {
    const YAML::Node doc = YAML::LoadFile(f.string());
    for (const YAML::Node& n : doc) {
      Case c;
      c.file = f.stem().string();
      c.name = n["name"].as<std::string>();
      for (const std::string& id : {c.file, c.name})
        if (id.empty() || id.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos)
          throw std::runtime_error(f.string() + ": '" + id + "': catalogue and case names are [a-z0-9_]");
      if (!names.insert(c.file + "/" + c.name).second)
        throw std::runtime_error(f.string() + ": case '" + c.name + "' twice");
      if (n["files"])
        for (const auto& kv : n["files"]) c.files[kv.first.as<std::string>()] = unescape(kv.second.as<std::string>());
      if (n["copy"])
        for (const auto& kv : n["copy"]) c.copies[kv.first.as<std::string>()] = kv.second.as<std::string>();
      if (n["setup"]) c.setup = unescape(n["setup"].as<std::string>());
      if (n["prefix"]) c.prefix = unescape(n["prefix"].as<std::string>());
      c.run = unescape(n["run"].as<std::string>());
      c.exit = n["exit"].as<int>();
      if (n["stderr"]) c.stderr_regex = unescape(n["stderr"].as<std::string>());
      if (n["stdout"]) c.stdout_regex = unescape(n["stdout"].as<std::string>());
      if (n["match"])
        for (const auto& kv : n["match"])
          c.match[unescape(kv.first.as<std::string>())] = unescape(kv.second.as<std::string>());
      if (n["lines"]) c.lines = n["lines"].as<int>();
      if (n["timeout"]) c.timeout = n["timeout"].as<double>();
      if (n["sanitizers"]) c.sanitizers = n["sanitizers"].as<bool>();
      c.keep = strings(n["keep"]);
      c.absent = strings(n["absent"]);
      if (n["created"] && n["created"].IsScalar() && n["created"].as<std::string>() == "any")
        c.any_files = true;
      else
        c.created = strings(n["created"]);
      if (c.exit != 0 && c.stderr_regex.empty())
        throw std::runtime_error(f.string() + ": case '" + c.name + "' fails without a `stderr` pattern");
      // The Release pass of the whole suite leaves to its sanitizer pass every case that pass runs
      // (tests/CMakeLists.txt): each case runs once, under the strictest build it can
      if (c.sanitizers && std::getenv("PHIQ_HOSTILE_UNSANITIZED_ONLY")) continue;
      cases.push_back(std::move(c));
    }
  }
  return cases;
}

// Whether `s` is well-formed UTF-8 (no stray continuation byte, no truncated or overlong sequence, no surrogate).
bool valid_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    const int len = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
    if (len == 0 || i + len > s.size()) return false;
    unsigned cp = len == 1 ? b : b & (0x7F >> len);
    for (int k = 1; k < len; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      if ((c >> 6) != 0x2) return false;
      cp = (cp << 6) | (c & 0x3F);
    }
    if ((len == 2 && cp < 0x80) || (len == 3 && cp < 0x800) || (len == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
        (cp >= 0xD800 && cp <= 0xDFFF))
      return false;
    i += len;
  }
  return true;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every file under `dir` (relative paths; directories end in '/'), not following links (a link that loops or
// dangles is listed as the link it is).
void list_into(const fs::path& root, const fs::path& dir, std::set<std::string>& v) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string rel = it->path().lexically_relative(root).string();
    if (it->symlink_status(ec).type() == fs::file_type::directory) {
      v.insert(rel + "/");
      list_into(root, it->path(), v);
    } else {
      v.insert(rel);
    }
  }
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> v;
  list_into(dir, dir, v);
  return v;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

// What gtest prints of a case (not its bytes).
void PrintTo(const Case& c, std::ostream* os) { *os << c.file << "/" << c.name; }

class Hostile : public ::testing::TestWithParam<Case> {};

TEST_P(Hostile, Case) {
  const Case& c = GetParam();
#ifdef PHIQ_SANITIZED
  // ASan reserves terabytes of address space for its shadow memory at start: an address-space limit kills it first
  if (!c.sanitizers) GTEST_SKIP() << "not run under sanitizers";
#endif
  // the process id in the name: two checkouts (or two runs) testing at once must not share a case's folder
  const fs::path dir = phiq::test::scratch_path("phiq_hostile_" + c.file + "_" + c.name);
  std::error_code ec;
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::add, ec);  // a case may have taken them away
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  for (const auto& [path, text] : c.files) {
    fs::create_directories((dir / path).parent_path());
    std::ofstream(dir / path, std::ios::binary) << text;
  }
  for (const auto& [path, from] : c.copies) fs::copy_file(fs::path(PHIQ_SOURCE_DIR) / from, dir / path);
  if (!c.setup.empty()) {
    const std::string cmd = "cd " + shell_quote(dir.string()) + " && { " + c.setup + "\n}";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << "setup failed: " << c.setup;
  }
  const std::set<std::string> before = listing(dir);
  std::map<std::string, std::string> kept;
  for (const std::string& k : c.keep) kept[k] = slurp(dir / k);

  const fs::path out = dir.parent_path() / ("phiq_hostile_" + c.file + "_" + c.name + ".stdout");
  const fs::path err = dir.parent_path() / ("phiq_hostile_" + c.file + "_" + c.name + ".stderr");
  std::ostringstream cmd;
  cmd << "cd " << shell_quote(dir.string()) << " && { " << c.prefix << " timeout -s KILL " << c.timeout << " "
      << PHIQ_CLI << " " << c.run << " </dev/null >" << shell_quote(out.string()) << " 2>" << shell_quote(err.string())
      << "; }";
  const int st = std::system(cmd.str().c_str());
  const int code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  const std::string stderr_text = slurp(err), stdout_text = slurp(out);
  fs::remove(out, ec), fs::remove(err, ec);

  EXPECT_EQ(code, c.exit) << "phiq " << c.run << "\nstderr: " << stderr_text;
  if (c.exit != 0 || !c.stderr_regex.empty()) {
    const long lines = std::count(stderr_text.begin(), stderr_text.end(), '\n');
    if (c.lines >= 0) {
      EXPECT_EQ(lines, c.lines) << "stderr: " << stderr_text;
    }
    if (c.exit != 0) {
      EXPECT_EQ(stderr_text.rfind("phiq: ", 0), 0u) << "stderr: " << stderr_text;
    }
    // (matched without the final newline, so that `$` ends the line)
    const std::string line =
        stderr_text.empty() || stderr_text.back() != '\n' ? stderr_text : stderr_text.substr(0, stderr_text.size() - 1);
    EXPECT_TRUE(std::regex_search(line, std::regex(c.stderr_regex)))
        << "stderr: " << stderr_text << "does not match: " << c.stderr_regex;
    // what phiq writes on stderr is text a terminal and a log can hold: no NUL, no invalid UTF-8 left raw
    EXPECT_EQ(stderr_text.find('\0'), std::string::npos);
    EXPECT_TRUE(valid_utf8(stderr_text)) << "stderr is not UTF-8: " << stderr_text;
  }
  if (!c.stdout_regex.empty()) {
    EXPECT_TRUE(std::regex_search(stdout_text, std::regex(c.stdout_regex)))
        << "stdout: " << stdout_text << "\ndoes not match: " << c.stdout_regex;
  }
  for (const auto& [path, regex] : c.match)
    EXPECT_TRUE(std::regex_search(slurp(dir / path), std::regex(regex))) << path << " does not match: " << regex;
  for (const auto& [path, bytes] : kept) EXPECT_EQ(slurp(dir / path), bytes) << path << " was changed";
  for (const std::string& a : c.absent) EXPECT_FALSE(fs::exists(fs::symlink_status(dir / a))) << a << " exists";
  for (const std::string& k : c.created) EXPECT_TRUE(fs::exists(dir / k)) << k << " was not written";
  if (!c.any_files) {
    std::set<std::string> expected = before;
    expected.insert(c.created.begin(), c.created.end());
    for (const std::string& f : listing(dir))
      EXPECT_TRUE(expected.count(f)) << "left behind: " << f << " (partial output or temporary)";
  }
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::add, ec);
  fs::remove_all(dir, ec);
}

INSTANTIATE_TEST_SUITE_P(Catalogue, Hostile, ::testing::ValuesIn(load_catalogue()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return info.param.file + "_" + info.param.name;
                         });

}  // namespace
