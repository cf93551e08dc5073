// A reader of glTF 2.0 binaries (.glb) for the tests of `phiq animate`, written from the specification apart from
// the writer (tools/animate/glb.cpp): it checks the container (magic, version, lengths, chunk types and padding)
// and the buffer's views and accessors against the BIN chunk, and reads accessor elements as the float32 they are.
#pragma once

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace phiq::test {

struct Glb {
  nlohmann::json doc;
  std::string bin;

  // Element k of float accessor `a` (its components).
  std::vector<double> floats(int a, std::size_t k) const {
    const nlohmann::json& acc = doc["accessors"][a];
    const nlohmann::json& view = doc["bufferViews"][acc["bufferView"].get<int>()];
    const std::string type = acc["type"];
    const std::size_t n = type == "SCALAR" ? 1 : (type == "VEC3" ? 3 : 4);
    EXPECT_EQ(acc["componentType"], 5126);
    const std::size_t at =
        view["byteOffset"].get<std::size_t>() + acc.value("byteOffset", std::size_t{0}) + k * n * sizeof(float);
    std::vector<double> v(n);
    for (std::size_t c = 0; c < n; ++c) {
      float f;
      std::memcpy(&f, bin.data() + at + c * sizeof(float), sizeof f);
      v[c] = f;
    }
    return v;
  }
  // The index of the node named `name` (−1: none).
  int node(const std::string& name) const {
    for (std::size_t k = 0; k < doc["nodes"].size(); ++k)
      if (doc["nodes"][k]["name"] == name) return static_cast<int>(k);
    return -1;
  }
  // The sampler's (input, output) accessors of node `n`'s channel `path` ({-1, -1}: none).
  std::pair<int, int> channel(int n, const std::string& path) const {
    const nlohmann::json& anim = doc["animations"][0];
    for (const auto& c : anim["channels"])
      if (c["target"]["node"] == n && c["target"]["path"] == path) {
        const auto& s = anim["samplers"][c["sampler"].get<int>()];
        return {s["input"].get<int>(), s["output"].get<int>()};
      }
    return {-1, -1};
  }
};

inline std::uint32_t u32(const std::string& s, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}

// Parses `file` (the bytes of a .glb), checking its container and the extent of every view and accessor.
inline Glb parse_glb(const std::string& file) {
  Glb g;
  EXPECT_GE(file.size(), 28u);
  if (file.size() < 28) return g;
  EXPECT_EQ(file.substr(0, 4), "glTF");
  EXPECT_EQ(u32(file, 4), 2u);
  EXPECT_EQ(u32(file, 8), file.size());
  const std::uint32_t json_len = u32(file, 12);
  EXPECT_EQ(file.substr(16, 4), "JSON");
  EXPECT_EQ(json_len % 4, 0u);
  g.doc = nlohmann::json::parse(file.substr(20, json_len));
  const std::size_t bin_at = 20 + json_len;
  const std::uint32_t bin_len = u32(file, bin_at);
  EXPECT_EQ(file.substr(bin_at + 4, 4), std::string("BIN\0", 4));
  EXPECT_EQ(bin_len % 4, 0u);
  EXPECT_EQ(bin_at + 8 + bin_len, file.size());
  g.bin = file.substr(bin_at + 8, bin_len);
  EXPECT_EQ(g.doc["buffers"].size(), 1u);
  EXPECT_EQ(g.doc["buffers"][0]["byteLength"].get<std::size_t>(), g.bin.size());
  for (const auto& v : g.doc["bufferViews"])
    EXPECT_LE(v["byteOffset"].get<std::size_t>() + v["byteLength"].get<std::size_t>(), g.bin.size());
  for (const auto& a : g.doc["accessors"]) {
    const auto& v = g.doc["bufferViews"][a["bufferView"].get<int>()];
    const std::string type = a["type"];
    const std::size_t n = type == "SCALAR" ? 1 : (type == "VEC3" ? 3 : 4);
    const std::size_t size = a["componentType"] == 5126 ? 4 : 2;
    EXPECT_EQ(a.value("byteOffset", std::size_t{0}) % size, 0u);
    EXPECT_LE(a.value("byteOffset", std::size_t{0}) + a["count"].get<std::size_t>() * n * size,
              v["byteLength"].get<std::size_t>());
  }
  return g;
}

}  // namespace phiq::test
