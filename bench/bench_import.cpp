// What reading a robot description costs: a generated URDF and MJCF of N/2 two-link arms (N revolute joints, each arm
// hanging from the ground, so that nesting stays shallow for any N), converted to a phiq scene and loaded, against
// loading that same scene's text (the model built in both). Counter `ratio`: import + load ÷ load of the scene,
// interleaved iteration by iteration and summed.
//
//   build/bench/phiq_bench --benchmark_filter=Import --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "phiq/import_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;

// URDF requires a revolute joint's limits (urdfdom refuses one without); phiq lists them as not mapped.
const std::string kLimit = "<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/>";

std::string import_bench_urdf(int joints) {
  std::string s = "<robot name=\"arms\">\n<link name=\"base\"/>\n";
  for (int k = 0; k < joints / 2; ++k) {
    const std::string i = std::to_string(k);
    s += "<link name=\"upper" + i + "\"/><link name=\"lower" + i + "\"/>\n<joint name=\"shoulder" + i +
         "\" type=\"revolute\"><parent link=\"base\"/><child link=\"upper" + i + "\"/><origin xyz=\"" + i +
         " 0 0\"/><axis xyz=\"0 0 1\"/>" + kLimit + "</joint>\n<joint name=\"elbow" + i +
         "\" type=\"revolute\"><parent link=\"upper" + i + "\"/><child link=\"lower" + i +
         "\"/><origin xyz=\"0.5 0 0\" rpy=\"0 0 0.3\"/><axis xyz=\"0 0 1\"/>" + kLimit + "</joint>\n";
  }
  return s + "</robot>\n";
}

std::string import_bench_mjcf(int joints) {
  std::string s = "<mujoco model=\"arms\">\n<worldbody>\n";
  for (int k = 0; k < joints / 2; ++k) {
    const std::string i = std::to_string(k);
    s += "<body name=\"upper" + i + "\" pos=\"" + i + " 0 0\"><joint name=\"shoulder" + i +
         "\" axis=\"0 0 1\"/><body name=\"lower" + i + "\" pos=\"0.5 0 0\" euler=\"0 0 17\"><joint name=\"elbow" + i +
         "\" axis=\"0 0 1\"/></body></body>\n";
  }
  return s + "</worldbody>\n</mujoco>\n";
}

template <class Import>
void import_vs_scene(benchmark::State& state, const std::string& text, const std::string& path, Import import) {
  const std::string yaml = import(text, path).yaml;
  double imported = 0.0, scene = 0.0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    const Scene a = parse_scene(import(text, path).yaml, path);
    auto t1 = std::chrono::steady_clock::now();
    const Scene b = parse_scene(yaml, "arms.yaml");
    auto t2 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(a.model.get());
    benchmark::DoNotOptimize(b.model.get());
    imported += std::chrono::duration<double>(t1 - t0).count();
    scene += std::chrono::duration<double>(t2 - t1).count();
  }
  state.counters["import_s"] = imported / static_cast<double>(state.iterations());
  state.counters["scene_s"] = scene / static_cast<double>(state.iterations());
  state.counters["ratio"] = imported / scene;
}

void BM_ImportUrdf(benchmark::State& state) {
  import_vs_scene(state, import_bench_urdf(static_cast<int>(state.range(0))), "arms.urdf",
                  [](const std::string& t, const std::string& p) { return import_urdf(t, p); });
}
void BM_ImportMjcf(benchmark::State& state) {
  import_vs_scene(state, import_bench_mjcf(static_cast<int>(state.range(0))), "arms.xml",
                  [](const std::string& t, const std::string& p) { return import_mjcf(t, p); });
}
BENCHMARK(BM_ImportUrdf)->ArgName("joints")->Arg(100)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ImportMjcf)->ArgName("joints")->Arg(100)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace
