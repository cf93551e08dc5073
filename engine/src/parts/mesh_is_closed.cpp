// Whether a triangle mesh is a closed, consistently oriented surface (shapes.hpp: mesh_is_closed).
#include <cmath>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "phiq/shapes.hpp"

namespace phiq {

bool mesh_is_closed(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return false;
  // Vertices that coincide exactly are one (an STL file repeats each corner in every triangle that has it).
  std::map<std::tuple<double, double, double>, int> first_at;
  std::vector<int> merged(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const kin3::V3& v = mesh.vertices[i];
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return false;
    merged[i] = first_at.try_emplace({v.x, v.y, v.z}, static_cast<int>(i)).first->second;
  }
  // Every directed edge once, and its reverse once: each edge is shared by two triangles that traverse it in
  // opposite directions. A triangle that names one point twice has no area and bounds nothing: left out.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : mesh.triangles) {
    int v[3];
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || static_cast<std::size_t>(t[k]) >= mesh.vertices.size()) return false;
      v[k] = merged[t[k]];
    }
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;
    for (int k = 0; k < 3; ++k)
      if (++directed[{v[k], v[(k + 1) % 3]}] > 1) return false;
  }
  if (directed.empty()) return false;
  for (const auto& [edge, count] : directed)
    if (!directed.contains({edge.second, edge.first})) return false;
  return true;
}

}  // namespace phiq
