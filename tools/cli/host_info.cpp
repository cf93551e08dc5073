// host_info.hpp: the host's name, CPU model and memory available.
#include "host_info.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

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

double memory_available() {
  double available = 0.0;
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    double kb = 0.0;
    while (std::fgets(line, sizeof line, f))
      if (std::sscanf(line, "MemAvailable: %lf kB", &kb) == 1) break;
    std::fclose(f);
    available = 1024.0 * kb;
  }
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return available;
  double mapped = 0.0;  // the address space the process holds already (/proc/self/statm: its size in pages)
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%lf", &mapped) == 1) mapped *= static_cast<double>(sysconf(_SC_PAGESIZE));
    std::fclose(f);
  }
  const double left = std::max(static_cast<double>(limit.rlim_cur) - mapped, 1.0);
  return available > 0.0 ? std::min(available, left) : left;
}

}  // namespace phiq::tools
