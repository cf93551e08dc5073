// The nodes of `phiq animate`'s .glb before they are written: meshes (a primitive per shape, each with its
// material's name and colour), and a track per node (its mesh and its transform at every row), from the sketch
// (gltf_motion.cpp) and from the parts (PartTracks), and the writer of the document and its buffer.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "phiq/parts.hpp"

namespace phiq::tools::gltf {

struct Primitive {
  std::string name;                // the shape's name (the primitive's extras)
  std::string material;            // materials are made once per name
  std::array<double, 4> colour{};  // RGBA
  std::vector<float> pos, nrm;     // x, y, z per vertex
  std::vector<std::uint32_t> idx;  // three per triangle
};

struct Mesh {
  std::string name;
  std::vector<Primitive> primitives;
};

// A node: its mesh and its translation, rotation (x, y, z, w) and scale at every row (r, s empty: none).
struct Track {
  std::string name;
  int mesh = -1;
  std::vector<float> t, r, s;
  bool still = false;               // no animation channel: it does not move
  nlohmann::json extras = nullptr;  // the node's extras (null: none)
};

struct Nodes {
  std::vector<Mesh> meshes;
  std::vector<Track> tracks;
};

// A node per part, its mesh the part's shapes (shape_triangles(), lit: part_drawing.hpp), keyframed at every row
// from part_pose(); a part whose pose never changes is still.
class PartTracks {
 public:
  PartTracks(const std::vector<Part>& parts, Nodes& nodes);
  // The parts' poses at (q, t): one keyframe each (rotations on the side of the previous keyframe's sign).
  void row(const double* q, double t);
  // Marks still the parts whose keyframes are all alike.
  void finish();

 private:
  const std::vector<Part>& parts_;
  Nodes& nodes_;
  std::size_t first_ = 0;  // the first part's track
};

// The .glb: `asset`, one scene named `title` of the nodes (under a root node turning phiq's z up to glTF's +y when
// `z_up`), the meshes, and one animation over `times`. Throws phiq::Error for a buffer over 2 GiB (naming `result`).
std::string write_glb(const std::string& title, const std::string& generator, Nodes& nodes,
                      const std::vector<float>& times, bool z_up, const std::string& result);

}  // namespace phiq::tools::gltf
