// Parts (issue 48, "Measure"): a scene whose part is a mesh of about 10⁵ triangles, read as `phiq check` and `phiq
// run` read it (the STL through Assimp, its vertices joined, its mass properties from the divergence theorem), and
// the mass properties alone. The STL is a binary UV sphere written to the temporary folder before the clock starts.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"
#include "phiq/shapes.hpp"

namespace {

using namespace phiq;

// A binary STL of a UV sphere of radius 0.1 with `rings` × `segments` quads (2 triangles each, but 1 at the poles):
// 2 rings (segments − 1) triangles.
std::string write_sphere(int rings, int segments) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("phiq_bench_sphere_" + std::to_string(rings) + "x" + std::to_string(segments) + ".stl"))
                               .string();
  auto at = [&](int i, int j) {
    if (i == 0 || i == rings) return std::array<float, 3>{0.0f, 0.0f, i == 0 ? 0.1f : -0.1f};  // one vertex a pole
    const double th = M_PI * i / rings, ph = 2 * M_PI * (j % segments) / segments;  // the seam: the same floats
    return std::array<float, 3>{static_cast<float>(0.1 * std::sin(th) * std::cos(ph)),
                                static_cast<float>(0.1 * std::sin(th) * std::sin(ph)),
                                static_cast<float>(0.1 * std::cos(th))};
  };
  std::vector<std::array<std::array<float, 3>, 3>> tris;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const auto a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if (i != rings - 1) tris.push_back({a, b, c});
      if (i != 0) tris.push_back({a, c, d});
    }
  std::ofstream out(path, std::ios::binary);
  char header[80] = {};
  out.write(header, 80);
  const auto n = static_cast<std::uint32_t>(tris.size());
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : tris) {
    const float normal[3] = {0, 0, 0};
    out.write(reinterpret_cast<const char*>(normal), 12);
    for (const auto& v : t) out.write(reinterpret_cast<const char*>(v.data()), 12);
    const std::uint16_t attribute = 0;
    out.write(reinterpret_cast<const char*>(&attribute), 2);
  }
  return path;
}

// A one-body planar scene whose part is the sphere at steel's density.
std::string scene_text(const std::string& stl) {
  return "phiq: 1\ncoordinates: {x: 0}\nbodies: {b: [x, 0, 0]}\n"
         "drivers: [{coordinate: x, law: {type: linear, initial: 0, rate: 1}}]\n"
         "time: {start: 0, end: 1, steps: 1}\n"
         "parts: {b: {density: 7850, shapes: [{type: mesh, file: '" +
         stl + "'}]}}\n";
}

// Argument: segments around the sphere (rings = segments / 2): segments (2 rings − 2) triangles, 100 488 at 318.
void BM_LoadSceneWithMesh(benchmark::State& state) {
  const int segments = static_cast<int>(state.range(0));
  const std::string stl = write_sphere(segments / 2, segments);
  const std::string text = scene_text(stl);
  std::size_t triangles = 0;
  for (auto _ : state) {
    Scene s = parse_scene(text, "bench.yaml");
    triangles = s.parts[0].shapes[0].mesh->triangles.size();
    benchmark::DoNotOptimize(s.parts[0].mass.mass);
  }
  state.counters["triangles"] = static_cast<double>(triangles);
  std::filesystem::remove(stl);
}
BENCHMARK(BM_LoadSceneWithMesh)->ArgName("segments")->Arg(64)->Arg(318)->Unit(benchmark::kMillisecond);

// The divergence theorem's sums alone, over the mesh as read.
void BM_MeshMassProperties(benchmark::State& state) {
  const int segments = static_cast<int>(state.range(0));
  const std::string stl = write_sphere(segments / 2, segments);
  const TriangleMesh mesh = load_mesh_file(stl);
  for (auto _ : state) benchmark::DoNotOptimize(mesh_mass_properties(mesh).mass);
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  std::filesystem::remove(stl);
}
BENCHMARK(BM_MeshMassProperties)->ArgName("segments")->Arg(318)->Unit(benchmark::kMillisecond);

}  // namespace
