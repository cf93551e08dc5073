// host_info.hpp: the host's name and CPU model.
#include "host_info.hpp"

#include <unistd.h>

#include <climits>
#include <fstream>

namespace phiq::tools {

std::string host_name() {
  char buf[HOST_NAME_MAX + 1] = {};
  if (gethostname(buf, sizeof buf - 1) != 0 || buf[0] == '\0') return "unknown";
  return buf;
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string key = line.substr(0, colon);
    while (!key.empty() && (key.back() == ' ' || key.back() == '\t')) key.pop_back();
    if (key != "model name" && key != "Hardware" && key != "cpu model") continue;
    std::size_t v = colon + 1;
    while (v < line.size() && line[v] == ' ') ++v;
    if (v < line.size()) return line.substr(v);
  }
  return "unknown";
}

}  // namespace phiq::tools
