// Where a command ran, for the reports a harness keeps (`run --summary`, `sweep-accuracy --json`): timings mean
// little without the machine that measured them; and the memory a command may still take there.
#pragma once

#include <string>

namespace phiq::tools {

// The host's name (gethostname), or "unknown".
std::string host_name();

// The CPU's model as /proc/cpuinfo names it (its first `model name`, or on machines that have none, such as some
// ARM kernels, `Hardware` or `cpu model`), or "unknown".
std::string cpu_model();

// The bytes this process may still allocate: what the system reports available (MemAvailable of /proc/meminfo),
// or less what an address-space limit (`ulimit -v`) leaves beside the process's own; 0 when neither is known.
double memory_available();

}  // namespace phiq::tools
