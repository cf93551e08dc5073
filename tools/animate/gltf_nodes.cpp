#include "gltf_nodes.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

#include "glb.hpp"
#include "part_drawing.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools::gltf {

PartTracks::PartTracks(const std::vector<Part>& parts, Nodes& nodes)
    : parts_(parts), nodes_(nodes), first_(nodes.tracks.size()) {
  for (const Part& part : parts) {
    Mesh mesh{part.name, {}};
    for (const Shape& shape : part.shapes) {
      LitMesh lit = lit_mesh(shape_triangles(shape, kPartSegments));
      const std::array<double, 4> c = shape_colour(part, shape);
      std::string material = hex_colour(c);
      if (c[3] < 1.0) material += " " + std::to_string(static_cast<int>(std::lround(100 * c[3]))) + "%";
      mesh.primitives.push_back({shape.name, material, c, std::move(lit.pos), std::move(lit.nrm), std::move(lit.idx)});
    }
    // a part without a shape (one that only states a mass) is a node without a mesh
    const int index = mesh.primitives.empty() ? -1 : static_cast<int>(nodes.meshes.size());
    if (index >= 0) nodes.meshes.push_back(std::move(mesh));
    nodes.tracks.push_back({part.name, index, {}, {}, {}, part.fixed});
  }
}

void PartTracks::row(const double* q, double t) {
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    Track& tr = nodes_.tracks[first_ + k];
    const Pose p = part_pose(parts_[k].frame, q, t);
    std::array<double, 4> r = quaternion(p.rotation);
    const std::size_t n = tr.r.size();
    if (n >= 4 && r[0] * tr.r[n - 4] + r[1] * tr.r[n - 3] + r[2] * tr.r[n - 2] + r[3] * tr.r[n - 1] < 0)
      for (double& c : r) c = -c;  // the same rotation, on the side of the previous keyframe
    for (double c : {p.at.x, p.at.y, p.at.z}) tr.t.push_back(static_cast<float>(c));
    for (double c : r) tr.r.push_back(static_cast<float>(c));
  }
}

void PartTracks::finish() {
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    Track& tr = nodes_.tracks[first_ + k];
    bool moves = false;
    for (std::size_t i = 3; i < tr.t.size() && !moves; ++i) moves = tr.t[i] != tr.t[i % 3];
    for (std::size_t i = 4; i < tr.r.size() && !moves; ++i) moves = tr.r[i] != tr.r[i % 4];
    tr.still = tr.still || !moves;
  }
}

std::string write_glb(const std::string& title, const std::string& generator, Nodes& nodes,
                      const std::vector<float>& times, bool z_up, const std::string& result) {
  nlohmann::json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", generator}, {"extras", {{"scene", title}}}};
  doc["accessors"] = doc["bufferViews"] = nlohmann::json::array();
  BufferBuilder buffer(doc);
  // geometry: positions and normals (float VEC3 each) in one view, the indices in another
  std::vector<std::vector<std::array<int, 3>>> prims(nodes.meshes.size());  // position, normal, indices accessors
  buffer.begin_view(kArrayBuffer, 3 * sizeof(float));
  for (std::size_t m = 0; m < nodes.meshes.size(); ++m)
    for (const Primitive& p : nodes.meshes[m].primitives)
      prims[m].push_back({buffer.add_floats(p.pos, 3, true), buffer.add_floats(p.nrm, 3, false), 0});
  buffer.begin_view(kElementArrayBuffer);
  for (std::size_t m = 0; m < nodes.meshes.size(); ++m)
    for (std::size_t k = 0; k < prims[m].size(); ++k)
      prims[m][k][2] = buffer.add_indices(nodes.meshes[m].primitives[k].idx);
  std::map<std::string, int> materials;  // made when first used (the validator notes unused objects)
  for (std::size_t m = 0; m < nodes.meshes.size(); ++m) {
    nlohmann::json primitives = nlohmann::json::array();
    for (std::size_t k = 0; k < prims[m].size(); ++k) {
      const Primitive& p = nodes.meshes[m].primitives[k];
      auto [it, fresh] = materials.emplace(p.material, static_cast<int>(materials.size()));
      if (fresh) {
        nlohmann::json mat = {{"name", p.material},
                              {"pbrMetallicRoughness",
                               {{"baseColorFactor", p.colour}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.6}}}};
        if (p.colour[3] < 1.0) mat["alphaMode"] = "BLEND";
        doc["materials"].push_back(mat);
      }
      nlohmann::json prim = {{"attributes", {{"POSITION", prims[m][k][0]}, {"NORMAL", prims[m][k][1]}}},
                             {"indices", prims[m][k][2]},
                             {"material", it->second}};
      if (!p.name.empty()) prim["extras"] = {{"name", p.name}};
      primitives.push_back(prim);
    }
    doc["meshes"].push_back({{"name", nodes.meshes[m].name}, {"primitives", primitives}});
  }
  buffer.begin_view(0);
  const int input = buffer.add_floats(times, 1, true);
  nlohmann::json channels = nlohmann::json::array(), samplers = nlohmann::json::array(), top = nlohmann::json::array();
  const bool moves = times.size() > 1;  // one row: a still pose, no animation
  for (std::size_t k = 0; k < nodes.tracks.size(); ++k) {
    const Track& tr = nodes.tracks[k];
    nlohmann::json node = {{"name", tr.name}};
    if (tr.mesh >= 0) node["mesh"] = tr.mesh;
    node["translation"] = {tr.t[0], tr.t[1], tr.t[2]};
    if (!tr.r.empty()) node["rotation"] = {tr.r[0], tr.r[1], tr.r[2], tr.r[3]};
    if (!tr.s.empty()) node["scale"] = {tr.s[0], tr.s[1], tr.s[2]};
    if (!tr.extras.is_null()) node["extras"] = tr.extras;
    doc["nodes"].push_back(node);
    top.push_back(k);
    if (!moves || tr.still) continue;
    auto channel = [&](const std::vector<float>& v, int components, const char* path) {
      if (v.empty()) return;
      samplers.push_back(
          {{"input", input}, {"output", buffer.add_floats(v, components, false)}, {"interpolation", "LINEAR"}});
      channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", k}, {"path", path}}}});
    };
    channel(tr.t, 3, "translation");
    channel(tr.r, 4, "rotation");
    channel(tr.s, 3, "scale");
  }
  if (z_up) {  // phiq's world (x, y, z) is glTF's (x, z, −y): a quarter turn about x, −90°, at the root
    const double h = std::sqrt(0.5);
    doc["nodes"].push_back({{"name", "world (phiq z up)"}, {"rotation", {-h, 0.0, 0.0, h}}, {"children", top}});
    top = {nodes.tracks.size()};
  }
  doc["scenes"][0]["nodes"] = top;
  doc["scenes"][0]["name"] = title;
  doc["scene"] = 0;
  if (!channels.empty()) doc["animations"] = {{{"name", title}, {"channels", channels}, {"samplers", samplers}}};
  const std::string bin = buffer.finish();
  if (bin.size() > (std::size_t{1} << 31))
    throw Error(result + ": the motion needs " + std::to_string(bin.size() >> 20) +
                " MiB of keyframes, more than a .glb holds (2 GiB here): write fewer rows");
  return glb_file(doc, bin);
}

}  // namespace phiq::tools::gltf
