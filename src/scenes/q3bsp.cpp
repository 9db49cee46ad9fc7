// Reading Quake 3 IBSP v46 files (from memory, a .bsp file or a .pk3 zip)
// and tessellating their Bézier patches. Every count and index is checked
// before use: a damaged file gives an InputError naming what is wrong.
#include "occull/q3bsp.hpp"

#include "occull/error.hpp"
#include "occull/input_limits.hpp"

#include <fmt/format.h>
#include <minizip/unzip.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <memory>

namespace occull::q3 {
namespace {

enum Lump : int {
  entities = 0, textures = 1, planes = 2, nodes = 3, leafs = 4, leaffaces = 5, vertexes = 10, meshverts = 11,
  faces = 13, visdata = 16, lump_count = 17
};

constexpr std::size_t kHeaderSize = 8 + lump_count * 8;
constexpr std::size_t kTextureSize = 72, kPlaneSize = 16, kNodeSize = 36, kLeafSize = 48, kVertexSize = 44,
                      kFaceSize = 104;

class Reader {
 public:
  Reader(std::span<const std::byte> data, std::string_view source) : data_(data), source_(source) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}: {}", source_, what));
  }

  std::int32_t i32(std::size_t at) const {
    std::uint32_t v = 0;
    for (int b = 3; b >= 0; --b) v = (v << 8) | std::uint32_t(std::to_integer<std::uint8_t>(data_[at + std::size_t(b)]));
    return std::int32_t(v);
  }
  float f32(std::size_t at) const {
    const std::uint32_t bits = std::uint32_t(i32(at));
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
  }
  glm::vec3 vec3(std::size_t at) const { return {f32(at), f32(at + 4), f32(at + 8)}; }

  // Offset and record count of a lump, checked against the file.
  std::pair<std::size_t, std::size_t> lump(int index, std::size_t record, const char* name) const {
    const std::int32_t offset = i32(8 + std::size_t(index) * 8);
    const std::int32_t length = i32(12 + std::size_t(index) * 8);
    if (offset < 0 || length < 0)
      fail(fmt::format("lump {} ({}) has a negative offset or length ({}, {})", index, name, offset, length));
    if (std::size_t(offset) + std::size_t(length) > data_.size())
      fail(fmt::format("lump {} ({}) at {} with {} bytes points outside the file ({} bytes)", index, name,
                       offset, length, data_.size()));
    if (std::size_t(length) % record != 0)
      fail(fmt::format("lump {} ({}) has {} bytes, not a whole number of {}-byte records", index, name,
                       length, record));
    return {std::size_t(offset), std::size_t(length) / record};
  }

  std::string text(std::size_t at, std::size_t max) const {
    std::string s;
    for (std::size_t i = 0; i < max; ++i) {
      const char c = char(std::to_integer<std::uint8_t>(data_[at + i]));
      if (c == '\0') break;
      s += c;
    }
    return s;
  }

  std::span<const std::byte> data_;
  std::string_view source_;
};

// Entities lump: { "key" "value" ... } blocks.
std::vector<Entity> parse_entities(std::string_view text, const Reader& r) {
  std::vector<Entity> out;
  std::size_t i = 0;
  const auto skip_space = [&] {
    while (i < text.size() && (std::isspace(static_cast<unsigned char>(text[i])) || text[i] == '\0')) ++i;
  };
  const auto quoted = [&]() -> std::string {
    if (i >= text.size() || text[i] != '"') r.fail(fmt::format("entities: expected '\"' at offset {}", i));
    const std::size_t end = text.find('"', i + 1);
    if (end == std::string_view::npos) r.fail("entities: unterminated string");
    std::string s(text.substr(i + 1, end - i - 1));
    i = end + 1;
    return s;
  };
  for (skip_space(); i < text.size(); skip_space()) {
    if (text[i] != '{') r.fail(fmt::format("entities: expected '{{' at offset {}", i));
    ++i;
    Entity e;
    for (skip_space(); i < text.size() && text[i] != '}'; skip_space()) {
      std::string key = quoted();
      skip_space();
      e[std::move(key)] = quoted();
    }
    if (i >= text.size()) r.fail("entities: unterminated block");
    ++i;
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace

Map read_bsp(std::span<const std::byte> data, std::string_view source) {
  const Reader r(data, source);
  if (data.size() < kHeaderSize)
    r.fail(fmt::format("truncated: {} bytes, an IBSP header needs {}", data.size(), kHeaderSize));
  if (std::memcmp(data.data(), "IBSP", 4) != 0) r.fail("not a Quake 3 map (magic is not IBSP)");
  if (const std::int32_t v = r.i32(4); v != 46)
    r.fail(fmt::format("IBSP version {} is not supported (Quake 3 maps are version 46)", v));

  Map map;
  {
    const auto [at, n] = r.lump(textures, kTextureSize, "textures");
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t p = at + i * kTextureSize;
      map.textures.push_back({r.text(p, 64), r.i32(p + 64), r.i32(p + 68)});
    }
  }
  {
    const auto [at, n] = r.lump(vertexes, kVertexSize, "vertexes");
    map.vertices.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t p = at + i * kVertexSize;
      map.vertices.push_back({r.vec3(p), r.vec3(p + 28)});
    }
  }
  {
    const auto [at, n] = r.lump(meshverts, 4, "meshverts");
    map.meshverts.reserve(n);
    for (std::size_t i = 0; i < n; ++i) map.meshverts.push_back(r.i32(at + i * 4));
  }
  {
    const auto [at, n] = r.lump(faces, kFaceSize, "faces");
    map.faces.reserve(n);
    const auto count = [](std::size_t c) { return std::int64_t(c); };
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t p = at + i * kFaceSize;
      Face f;
      f.texture = r.i32(p);
      const std::int32_t type = r.i32(p + 8);
      f.first_vertex = r.i32(p + 12);
      f.vertex_count = r.i32(p + 16);
      f.first_meshvert = r.i32(p + 20);
      f.meshvert_count = r.i32(p + 24);
      f.patch_width = r.i32(p + 96);
      f.patch_height = r.i32(p + 100);
      if (type < 1 || type > 4) r.fail(fmt::format("face {} has unknown type {}", i, type));
      f.type = FaceType(type);
      if (f.texture < 0 || f.texture >= count(map.textures.size()))
        r.fail(fmt::format("face {} uses texture {} of {}", i, f.texture, map.textures.size()));
      if (f.first_vertex < 0 || f.vertex_count < 0 ||
          std::int64_t(f.first_vertex) + f.vertex_count > count(map.vertices.size()))
        r.fail(fmt::format("face {} has vertices {}..+{} outside the {} vertices", i, f.first_vertex,
                           f.vertex_count, map.vertices.size()));
      if (f.type == FaceType::polygon || f.type == FaceType::mesh) {
        if (f.first_meshvert < 0 || f.meshvert_count < 0 || f.meshvert_count % 3 != 0 ||
            std::int64_t(f.first_meshvert) + f.meshvert_count > count(map.meshverts.size()))
          r.fail(fmt::format("face {} has mesh vertices {}..+{} outside the {} mesh vertices (or not "
                             "whole triangles)",
                             i, f.first_meshvert, f.meshvert_count, map.meshverts.size()));
        for (std::int32_t k = 0; k < f.meshvert_count; ++k) {
          const std::int32_t v = map.meshverts[std::size_t(f.first_meshvert + k)];
          if (v < 0 || v >= f.vertex_count)
            r.fail(fmt::format("face {}: mesh vertex {} points to vertex {} of its {}", i, k, v, f.vertex_count));
        }
      }
      if (f.type == FaceType::patch &&
          (f.patch_width < 3 || f.patch_height < 3 || f.patch_width % 2 == 0 || f.patch_height % 2 == 0 ||
           std::int64_t(f.patch_width) * f.patch_height != f.vertex_count))
        r.fail(fmt::format("face {}: a {} x {} patch with {} control points (needs odd sizes >= 3 that "
                           "multiply to the count)",
                           i, f.patch_width, f.patch_height, f.vertex_count));
      map.faces.push_back(f);
    }
  }
  {
    const auto [at, n] = r.lump(leaffaces, 4, "leaffaces");
    for (std::size_t i = 0; i < n; ++i) {
      const std::int32_t face = r.i32(at + i * 4);
      if (face < 0 || std::size_t(face) >= map.faces.size())
        r.fail(fmt::format("leaf face {} points to face {} of {}", i, face, map.faces.size()));
      map.leaf_faces.push_back(face);
    }
  }
  {
    const auto [at, n] = r.lump(leafs, kLeafSize, "leafs");
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t p = at + i * kLeafSize;
      Leaf l;
      l.cluster = r.i32(p);
      l.area = r.i32(p + 4);
      l.mins = {r.i32(p + 8), r.i32(p + 12), r.i32(p + 16)};
      l.maxs = {r.i32(p + 20), r.i32(p + 24), r.i32(p + 28)};
      l.first_face = r.i32(p + 32);
      l.face_count = r.i32(p + 36);
      if (l.first_face < 0 || l.face_count < 0 ||
          std::int64_t(l.first_face) + l.face_count > std::int64_t(map.leaf_faces.size()))
        r.fail(fmt::format("leaf {} has faces {}..+{} outside the {} leaf faces", i, l.first_face,
                           l.face_count, map.leaf_faces.size()));
      map.leaves.push_back(l);
    }
  }
  {
    const auto [at, n] = r.lump(entities, 1, "entities");
    map.entities = parse_entities(r.text(at, n), r);
  }
  {
    const auto [at, n] = r.lump(planes, kPlaneSize, "planes");
    map.planes.reserve(n);
    for (std::size_t i = 0; i < n; ++i) map.planes.push_back({r.vec3(at + i * kPlaneSize), r.f32(at + i * kPlaneSize + 12)});
  }
  {
    const auto [at, n] = r.lump(nodes, kNodeSize, "nodes");
    map.nodes.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t p = at + i * kNodeSize;
      Node node{r.i32(p), {r.i32(p + 4), r.i32(p + 8)}};
      if (node.plane < 0 || std::size_t(node.plane) >= map.planes.size())
        r.fail(fmt::format("node {} uses plane {} of {}", i, node.plane, map.planes.size()));
      for (std::int32_t child : node.children) {
        // Children come after their parent, so the walk from node 0 always ends.
        const bool ok = child >= 0 ? std::size_t(child) > i && std::size_t(child) < n
                                   : std::size_t(-(std::int64_t(child) + 1)) < map.leaves.size();
        if (!ok)
          r.fail(fmt::format("node {} has child {} (nodes must point to later nodes or to one of the {} leaves)", i,
                             child, map.leaves.size()));
      }
      map.nodes.push_back(node);
    }
  }
  {
    const auto [at, n] = r.lump(visdata, 1, "visdata");
    if (n > 0) {
      if (n < 8) r.fail(fmt::format("visdata of {} bytes has no header", n));
      VisData& v = map.vis;
      v.clusters = r.i32(at);
      v.bytes_per_row = r.i32(at + 4);
      if (v.clusters < 0 || v.bytes_per_row < 0 || std::int64_t(v.bytes_per_row) * 8 < v.clusters ||
          8 + std::int64_t(v.clusters) * v.bytes_per_row > std::int64_t(n))
        r.fail(fmt::format("visdata claims {} clusters of {} bytes in {} bytes", v.clusters, v.bytes_per_row, n));
      v.bits.resize(std::size_t(v.clusters) * std::size_t(v.bytes_per_row));
      for (std::size_t i = 0; i < v.bits.size(); ++i) v.bits[i] = std::to_integer<std::uint8_t>(data[at + 8 + i]);
      for (std::size_t i = 0; i < map.leaves.size(); ++i)
        if (map.leaves[i].cluster >= v.clusters)
          r.fail(fmt::format("leaf {} is in cluster {} of the visdata's {}", i, map.leaves[i].cluster, v.clusters));
    }
  }
  return map;
}

std::int32_t find_cluster(const Map& map, const glm::vec3& point) {
  if (map.nodes.empty()) return map.leaves.empty() ? -1 : map.leaves.front().cluster;
  std::int32_t index = 0;
  while (index >= 0) {  // children always point forward: at most nodes.size() steps
    const Node& node = map.nodes[std::size_t(index)];
    const Plane& plane = map.planes[std::size_t(node.plane)];
    index = node.children[glm::dot(plane.normal, point) - plane.dist >= 0.0f ? 0 : 1];
  }
  return map.leaves[std::size_t(-(std::int64_t(index) + 1))].cluster;
}

bool cluster_sees(const Map& map, std::int32_t from, std::int32_t to) {
  const VisData& v = map.vis;
  if (from < 0 || to < 0 || v.clusters == 0 || from >= v.clusters || to >= v.clusters) return true;
  const std::uint8_t byte = v.bits[std::size_t(from) * std::size_t(v.bytes_per_row) + std::size_t(to) / 8];
  return (byte >> (to % 8)) & 1;
}

namespace {

struct ZipCloser {
  void operator()(void* z) const { unzClose(z); }
};
using Zip = std::unique_ptr<void, ZipCloser>;

Zip open_zip(const std::string& pk3) {
  {
    std::ifstream f(pk3, std::ios::binary);
    if (!f) throw InputError(fmt::format("{}: cannot be opened", pk3));
  }
  limits::check_file_size(pk3, limits::archive_bytes, "a .pk3 archive (occull::limits::archive_bytes)");
  Zip z(unzOpen64(pk3.c_str()));
  if (!z) throw InputError(fmt::format("{}: not a zip archive (a .pk3 is a zip of game files)", pk3));
  return z;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::vector<std::string> list_maps(const std::string& pk3) {
  Zip z = open_zip(pk3);
  std::vector<std::string> out;
  for (int rc = unzGoToFirstFile(z.get()); rc == UNZ_OK; rc = unzGoToNextFile(z.get())) {
    char name[512];
    unz_file_info64 info;
    if (unzGetCurrentFileInfo64(z.get(), &info, name, sizeof name, nullptr, 0, nullptr, 0) != UNZ_OK)
      throw InputError(fmt::format("{}: damaged zip directory", pk3));
    const std::string n = lower(name);
    if (n.rfind("maps/", 0) == 0 && n.size() > 9 && n.substr(n.size() - 4) == ".bsp" &&
        n.find('/', 5) == std::string::npos)
      out.push_back(std::string(name).substr(5, n.size() - 9));
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::byte> read_map_from_pk3(const std::string& pk3, std::string_view map) {
  Zip z = open_zip(pk3);
  const std::string entry = fmt::format("maps/{}.bsp", map);
  if (unzLocateFile(z.get(), entry.c_str(), 2 /* case-insensitive */) != UNZ_OK) {
    std::string names;
    for (const auto& m : list_maps(pk3)) names += (names.empty() ? "" : ", ") + m;
    throw InputError(fmt::format("{}: no map '{}'; maps in it: {}", pk3, map, names.empty() ? "(none)" : names));
  }
  unz_file_info64 info;
  if (unzGetCurrentFileInfo64(z.get(), &info, nullptr, 0, nullptr, 0, nullptr, 0) != UNZ_OK)
    throw InputError(fmt::format("{}: damaged entry {}", pk3, entry));
  const std::uint64_t claimed = info.uncompressed_size;
  if (claimed > limits::map_bytes)
    throw InputError(fmt::format("{}: {} claims {} bytes, past the limit of {} bytes for a map "
                                 "(occull::limits::map_bytes)",
                                 pk3, entry, claimed, limits::map_bytes));
  if (unzOpenCurrentFile(z.get()) != UNZ_OK) throw InputError(fmt::format("{}: cannot open {}", pk3, entry));
  // The buffer grows with what inflates, not with the size the directory
  // claims: a few bytes of zip may claim gigabytes (found by fuzz_pk3).
  std::vector<std::byte> bytes;
  constexpr std::size_t kPiece = std::size_t(1) << 20;
  int read = 0;
  do {
    const std::size_t at = bytes.size();
    bytes.resize(at + kPiece);
    read = unzReadCurrentFile(z.get(), bytes.data() + at, unsigned(kPiece));
    bytes.resize(at + std::size_t(std::max(read, 0)));
  } while (read > 0 && bytes.size() <= claimed);
  const int close = unzCloseCurrentFile(z.get());
  if (read < 0 || bytes.size() != claimed || close != UNZ_OK)
    throw InputError(fmt::format("{}: {} is damaged (inflates to {}{} bytes, its directory says {})", pk3, entry,
                                 bytes.size(), read > 0 ? " or more" : "", claimed));
  return bytes;
}

void tessellate_patch(std::span<const Vertex> control, int width, int height, int level,
                      std::vector<Vertex>& vertices, std::vector<std::uint32_t>& indices) {
  const auto bernstein = [](float t) {
    return glm::vec3((1 - t) * (1 - t), 2 * t * (1 - t), t * t);
  };
  for (int py = 0; py + 2 < height; py += 2) {
    for (int px = 0; px + 2 < width; px += 2) {
      const auto base = std::uint32_t(vertices.size());
      for (int b = 0; b <= level; ++b) {
        const glm::vec3 bv = bernstein(float(b) / float(level));
        for (int a = 0; a <= level; ++a) {
          const glm::vec3 bu = bernstein(float(a) / float(level));
          Vertex v{glm::vec3(0.0f), glm::vec3(0.0f)};
          for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 3; ++i) {
              const Vertex& c = control[std::size_t((py + j) * width + px + i)];
              v.position += bu[i] * bv[j] * c.position;
              v.normal += bu[i] * bv[j] * c.normal;
            }
          const float len = glm::length(v.normal);
          v.normal = len > 0 ? v.normal / len : glm::vec3(0, 0, 1);
          vertices.push_back(v);
        }
      }
      const auto at = [&](int a, int b) { return base + std::uint32_t(b * (level + 1) + a); };
      for (int b = 0; b < level; ++b)
        for (int a = 0; a < level; ++a)
          indices.insert(indices.end(), {at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b),
                                         at(a + 1, b + 1), at(a, b + 1)});
    }
  }
}

}  // namespace occull::q3
