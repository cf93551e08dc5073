#include "glb.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace phiq::tools::gltf {

namespace {

const char* type_of(int components) { return components == 1 ? "SCALAR" : (components == 3 ? "VEC3" : "VEC4"); }

void put_u32(std::string& s, std::uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);  // little-endian hosts only (x86-64, aarch64), as the format is
  s.append(b, 4);
}

void pad(std::string& s, char with) {
  while (s.size() % 4) s += with;
}

}  // namespace

void BufferBuilder::begin_view(int target, int byte_stride) {
  close_view();
  view_start_ = bin_.size();
  view_target_ = target;
  view_stride_ = byte_stride;
}

void BufferBuilder::close_view() {
  if (view_target_ < 0) return;
  nlohmann::json v = {{"buffer", 0}, {"byteOffset", view_start_}, {"byteLength", bin_.size() - view_start_}};
  if (view_target_ > 0) v["target"] = view_target_;
  if (view_stride_ > 0) v["byteStride"] = view_stride_;
  doc_["bufferViews"].push_back(v);
  view_target_ = -1;
  pad(bin_, '\0');  // the next view starts aligned
}

int BufferBuilder::add_floats(const std::vector<float>& v, int components, bool with_bounds) {
  pad(bin_, '\0');
  nlohmann::json a = {{"bufferView", doc_["bufferViews"].size()},
                      {"byteOffset", bin_.size() - view_start_},
                      {"componentType", kFloat},
                      {"count", v.size() / static_cast<std::size_t>(components)},
                      {"type", type_of(components)}};
  if (with_bounds) {
    std::vector<float> lo(components, std::numeric_limits<float>::infinity()), hi(components, -lo[0]);
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::size_t c = i % static_cast<std::size_t>(components);
      lo[c] = std::min(lo[c], v[i]), hi[c] = std::max(hi[c], v[i]);
    }
    a["min"] = lo, a["max"] = hi;
  }
  bin_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(float));
  doc_["accessors"].push_back(a);
  return static_cast<int>(doc_["accessors"].size()) - 1;
}

int BufferBuilder::add_indices(const std::vector<std::uint32_t>& v) {
  pad(bin_, '\0');
  const bool narrow = std::all_of(v.begin(), v.end(), [](std::uint32_t i) { return i < 65535; });
  doc_["accessors"].push_back({{"bufferView", doc_["bufferViews"].size()},
                               {"byteOffset", bin_.size() - view_start_},
                               {"componentType", narrow ? kUnsignedShort : kUnsignedInt},
                               {"count", v.size()},
                               {"type", "SCALAR"}});
  if (narrow) {
    for (std::uint32_t i : v) {
      const auto s = static_cast<std::uint16_t>(i);
      bin_.append(reinterpret_cast<const char*>(&s), sizeof s);
    }
  } else {
    bin_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(std::uint32_t));
  }
  return static_cast<int>(doc_["accessors"].size()) - 1;
}

std::string BufferBuilder::finish() {
  close_view();
  pad(bin_, '\0');
  doc_["buffers"] = nlohmann::json::array({{{"byteLength", bin_.size()}}});
  return std::move(bin_);
}

std::string glb_file(const nlohmann::json& doc, const std::string& bin) {
  std::string json = doc.dump();
  pad(json, ' ');
  std::string out;
  out.reserve(28 + json.size() + bin.size());
  out += "glTF";
  put_u32(out, 2);
  put_u32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  put_u32(out, static_cast<std::uint32_t>(json.size()));
  out += "JSON";
  out += json;
  put_u32(out, static_cast<std::uint32_t>(bin.size()));
  out.append("BIN\0", 4);
  out += bin;
  return out;
}

}  // namespace phiq::tools::gltf
