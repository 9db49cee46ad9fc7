// Test helper: writes small IBSP v46 files byte by byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <array>
#include <cstring>
#include <string>
#include <vector>

namespace occull::test {

class TinyBsp {
 public:
  struct V {
    float x, y, z, nx, ny, nz;
  };

  std::vector<std::pair<std::string, std::int32_t>> textures{{"textures/base_wall/concrete", 1}};
  std::vector<V> vertices;
  std::vector<std::int32_t> meshverts;
  // texture, type, first_vertex, vertex_count, first_meshvert, meshvert_count, patch w, patch h
  std::vector<std::array<std::int32_t, 8>> faces;
  std::vector<std::int32_t> leaf_faces;
  std::string entities;

  /// A unit quad (2 triangles) at z = 0 and a flat 3 x 3 patch next to it,
  /// one leaf holding both, one spawn point.
  static TinyBsp example() {
    TinyBsp b;
    for (auto [x, y] : {std::pair{0.f, 0.f}, {64.f, 0.f}, {64.f, 64.f}, {0.f, 64.f}})
      b.vertices.push_back({x, y, 0, 0, 0, 1});
    b.meshverts = {0, 1, 2, 0, 2, 3};
    b.faces.push_back({0, 1, 0, 4, 0, 6, 0, 0});
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) b.vertices.push_back({100.f + 32.f * float(i), 32.f * float(j), 0, 0, 0, 1});
    b.faces.push_back({0, 2, 4, 9, 0, 0, 3, 3});
    b.leaf_faces = {0, 1};
    b.entities = "{\n\"classname\" \"worldspawn\"\n}\n{\n\"classname\" \"info_player_deathmatch\"\n"
                 "\"origin\" \"32 32 24\"\n\"angle\" \"90\"\n}\n";
    return b;
  }

  std::vector<std::byte> bytes() const {
    std::vector<std::byte> out(8 + 17 * 8);
    std::memcpy(out.data(), "IBSP", 4);
    put(out, 4, 46);
    const auto lump = [&](int index, const std::vector<std::byte>& data) {
      put(out, 8 + std::size_t(index) * 8, std::int32_t(out.size()));
      put(out, 12 + std::size_t(index) * 8, std::int32_t(data.size()));
      out.insert(out.end(), data.begin(), data.end());
    };
    std::vector<std::byte> d;
    d.assign(entities.size() + 1, std::byte{0});
    std::memcpy(d.data(), entities.data(), entities.size());
    lump(0, d);
    d.clear();
    for (const auto& [name, contents] : textures) {
      std::vector<std::byte> t(72);
      std::memcpy(t.data(), name.data(), std::min<std::size_t>(name.size(), 63));
      put(t, 64, 0);
      put(t, 68, contents);
      d.insert(d.end(), t.begin(), t.end());
    }
    lump(1, d);
    for (int empty : {2, 3}) lump(empty, {});
    d.assign(48, std::byte{0});  // one leaf: cluster 0, faces 0..leaf_faces.size()
    put(d, 36, std::int32_t(leaf_faces.size()));
    lump(4, d);
    d.clear();
    for (std::int32_t f : leaf_faces) append(d, f);
    lump(5, d);
    for (int empty : {6, 7, 8, 9}) lump(empty, {});
    d.clear();
    for (const V& v : vertices) {
      std::vector<std::byte> r(44);
      putf(r, 0, v.x), putf(r, 4, v.y), putf(r, 8, v.z);
      putf(r, 28, v.nx), putf(r, 32, v.ny), putf(r, 36, v.nz);
      d.insert(d.end(), r.begin(), r.end());
    }
    lump(10, d);
    d.clear();
    for (std::int32_t m : meshverts) append(d, m);
    lump(11, d);
    lump(12, {});
    d.clear();
    for (const auto& f : faces) {
      std::vector<std::byte> r(104);
      put(r, 0, f[0]);
      put(r, 8, f[1]);
      put(r, 12, f[2]), put(r, 16, f[3]), put(r, 20, f[4]), put(r, 24, f[5]);
      put(r, 96, f[6]), put(r, 100, f[7]);
      d.insert(d.end(), r.begin(), r.end());
    }
    lump(13, d);
    for (int empty : {14, 15, 16}) lump(empty, {});
    return out;
  }

  static void put(std::vector<std::byte>& b, std::size_t at, std::int32_t v) {
    for (int i = 0; i < 4; ++i) b[at + std::size_t(i)] = std::byte((std::uint32_t(v) >> (8 * i)) & 0xff);
  }
  static void putf(std::vector<std::byte>& b, std::size_t at, float f) {
    std::int32_t v;
    std::memcpy(&v, &f, 4);
    put(b, at, v);
  }
  static void append(std::vector<std::byte>& b, std::int32_t v) {
    b.resize(b.size() + 4);
    put(b, b.size() - 4, v);
  }
};

}  // namespace occull::test
