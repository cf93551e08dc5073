// Where a command ran, for the reports a harness keeps (`run --summary`, `sweep-accuracy --json`): timings mean
// little without the machine that measured them.
#pragma once

#include <string>

namespace phiq::tools {

// The host's name (gethostname), or "unknown".
std::string host_name();

// The CPU's model as /proc/cpuinfo names it (its first `model name`, or on machines that have none, such as some
// ARM kernels, `Hardware` or `cpu model`), or "unknown".
std::string cpu_model();

}  // namespace phiq::tools
