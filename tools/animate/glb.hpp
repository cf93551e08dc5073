// The glTF 2.0 binary container (.glb) and the binary buffer behind it, written by hand with nlohmann-json (see
// tools/README.md, "phiq animate", for why not tinygltf): a 12-byte header, the JSON chunk padded with spaces, the
// BIN chunk padded with zeros, each to 4 bytes (glTF 2.0 specification, section "Binary glTF Layout").
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace phiq::tools::gltf {

// Component types and buffer view targets of the specification.
constexpr int kFloat = 5126, kUnsignedShort = 5123, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// The one buffer of a .glb and its views: accessors are appended to a view, each at a 4-byte aligned offset, and
// described in the JSON's "accessors" with their count, type and (where the specification asks) min and max.
class BufferBuilder {
 public:
  explicit BufferBuilder(nlohmann::json& doc) : doc_(doc) {}
  // Starts a new buffer view (target 0: none, as for animation data); accessors added next go into it. A view of
  // vertex attributes that several accessors share needs its byteStride (the specification's rule).
  void begin_view(int target, int byte_stride = 0);
  // A float accessor of `count` elements of `components` (1: SCALAR, 3: VEC3, 4: VEC4); with_bounds writes its
  // min and max (needed for POSITION and animation inputs). Returns its index.
  int add_floats(const std::vector<float>& v, int components, bool with_bounds);
  // An accessor of indices: unsigned short when every one fits, else unsigned int. Returns its index.
  int add_indices(const std::vector<std::uint32_t>& v);
  // Closes the last view and writes "buffers" and "bufferViews"; returns the BIN chunk's content.
  std::string finish();

 private:
  void close_view();
  nlohmann::json& doc_;
  std::string bin_;
  std::size_t view_start_ = 0;
  int view_target_ = -1;  // -1: no view open
  int view_stride_ = 0;
};

// The .glb file: header, JSON chunk, BIN chunk.
std::string glb_file(const nlohmann::json& doc, const std::string& bin);

}  // namespace phiq::tools::gltf
