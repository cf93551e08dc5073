// The clock of phiq_bench's manually timed benchmarks (bench_kinematics*.cpp): what each of its sources times
// its regions with, so that the three read one clock the same way.
#pragma once

#include <chrono>

namespace phiq_bench {

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace phiq_bench
