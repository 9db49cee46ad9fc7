// `file:PATH` scenes: any model assimp reads (glTF 2, OBJ, ...). Every mesh
// node becomes objects in world space, meshes larger than a culling-sized
// piece split by spatial clustering; camera paths `orbit` and `through`.
#include "model_file.hpp"

#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "triangle_soup.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <type_traits>

namespace occull::scenes {
namespace {

glm::mat4 to_glm(const aiMatrix4x4& m) {
  // assimp is row-major, glm column-major.
  return glm::mat4(m.a1, m.b1, m.c1, m.d1, m.a2, m.b2, m.c2, m.d2, m.a3, m.b3, m.c3, m.d3, m.a4, m.b4,
                   m.c4, m.d4);
}

void collect(const aiScene* s, const aiNode* node, const glm::mat4& parent, std::vector<SoupTriangle>& out) {
  const glm::mat4 world = parent * to_glm(node->mTransformation);
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(world)));
  for (unsigned k = 0; k < node->mNumMeshes; ++k) {
    const aiMesh* mesh = s->mMeshes[node->mMeshes[k]];
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      SoupTriangle t;
      t.material = std::int32_t(mesh->mMaterialIndex);
      for (int c = 0; c < 3; ++c) {
        const unsigned i = face.mIndices[c];
        if (i >= mesh->mNumVertices) continue;
        const aiVector3D& p = mesh->mVertices[i];
        t.p[c] = glm::vec3(world * glm::vec4(p.x, p.y, p.z, 1.0f));
        const aiVector3D n = mesh->mNormals ? mesh->mNormals[i] : aiVector3D(0, 1, 0);
        t.n[c] = normal_matrix * glm::vec3(n.x, n.y, n.z);
      }
      const glm::vec3 g = glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
      if (glm::dot(g, g) > 0.0f) out.push_back(t);
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) collect(s, node->mChildren[c], world, out);
}

// The leading digits of `token` as a count, or nullopt where there are none;
// more digits than any count a file can back count as "too many".
std::optional<std::uint64_t> leading_count(std::string_view token) {
  std::uint64_t v = 0;
  std::size_t digits = 0;
  for (char c : token) {
    if (c < '0' || c > '9') break;
    if (++digits > 15) return std::numeric_limits<std::uint64_t>::max();
    v = v * 10 + std::uint64_t(c - '0');
  }
  if (digits == 0) return std::nullopt;
  return v;
}

[[noreturn]] void refuse_count(const std::string& path, std::uint64_t count, std::string_view what,
                               std::uint64_t bytes) {
  throw InputError(fmt::format("{}: its header declares {} {} in a file of {} bytes: damaged", path,
                               count == std::numeric_limits<std::uint64_t>::max() ? "over 10^15" : fmt::format("{}", count),
                               what, bytes));
}

// A PLY header as the format defines it: "ply", "format KIND VERSION", then
// comment, obj_info, "element NAME COUNT" and "property TYPE NAME" or
// "property list TYPE TYPE NAME" lines, then "end_header". assimp's PLY
// reader never returned from headers without end_header, with a NUL byte or
// with a line glued to end_header, and aborted the process on one with
// unknown types (fuzz_model); anything else is refused here first.
void check_ply_header(const std::string& path, const std::string& head, std::uint64_t bytes) {
  static constexpr std::array<std::string_view, 16> kTypes = {
      "char", "uchar", "short", "ushort", "int", "uint", "float", "double",
      "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  const auto is_type = [](const std::string& t) { return std::find(kTypes.begin(), kTypes.end(), t) != kTypes.end(); };
  const auto damaged = [&](std::size_t line, std::string_view why) {
    throw InputError(fmt::format("{}: line {} of its PLY header {}: damaged", path, line, why));
  };
  std::set<std::string> elements;
  std::size_t pos = 0;
  for (std::size_t line_no = 1;; ++line_no) {
    const std::size_t eol = head.find('\n', pos);
    if (eol == std::string::npos)
      damaged(line_no, fmt::format("is not there: no end_header line in the first {} bytes", head.size()));
    std::string line = head.substr(pos, eol - pos);
    pos = eol + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find('\0') != std::string::npos) damaged(line_no, "has a NUL byte");
    std::istringstream in(line);
    std::vector<std::string> w;
    for (std::string t; in >> t;) w.push_back(t);
    if (line_no == 1) {
      if (w.size() != 1 || w[0] != "ply") damaged(line_no, "is not 'ply'");
      continue;
    }
    if (line_no == 2) {
      if (w.size() != 3 || w[0] != "format" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        damaged(line_no, "is not 'format ascii|binary_little_endian|binary_big_endian VERSION'");
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (w.size() != 1) damaged(line_no, "has more than end_header");
      if (elements.empty()) damaged(line_no, "ends a header that declares no element");
      return;
    }
    if (w[0] == "element") {
      const auto n = w.size() == 3 && w[2].find_first_not_of("0123456789") == std::string::npos
                         ? leading_count(w[2]) : std::nullopt;
      if (!n) damaged(line_no, "is not 'element NAME COUNT'");
      if (*n > bytes) refuse_count(path, *n, fmt::format("'{}' elements", w[1]), bytes);
      if (!elements.insert(w[1]).second) damaged(line_no, fmt::format("declares element '{}' again", w[1]));
      continue;
    }
    if (w[0] == "property") {
      if (elements.empty()) damaged(line_no, "declares a property before any element");
      if ((w.size() == 3 && is_type(w[1])) || (w.size() == 5 && w[1] == "list" && is_type(w[2]) && is_type(w[3])))
        continue;
      damaged(line_no, "is not 'property TYPE NAME' or 'property list TYPE TYPE NAME' with TYPE one of PLY's");
    }
    damaged(line_no, fmt::format("starts with '{}', which no PLY header line does", w[0].substr(0, 40)));
  }
}

// assimp's OFF and PLY importers allocate the vertices, faces and elements
// their headers declare before reading any: a 140-byte OFF file declaring
// 1.4 billion vertices took 16 GB (found by fuzz_model). Every declared item
// takes at least one byte of the file, so a count past its size is damage,
// refused before assimp sees it. The header is read as assimp does, loosely:
// a keyword (OFF with its optional prefixes, or ply), then counts.
void check_declared_counts(const std::string& path) {
  const std::uint64_t bytes = std::filesystem::file_size(path);
  std::ifstream in(path, std::ios::binary);
  std::string head(std::size_t(std::min<std::uint64_t>(bytes, 1 << 16)), '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(std::size_t(in.gcount()));
  std::istringstream lines(head);
  std::string first;
  lines >> first;
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  // assimp reads a file as PLY by its extension, or by its first three bytes.
  if (extension == ".ply" || head.rfind("ply", 0) == 0) {
    check_ply_header(path, head, bytes);
    return;
  }
  const std::size_t off = first.find("OFF");
  const bool keyword = off != std::string::npos && off <= 6 &&
                       first.find_first_not_of("STCN4n") >= off;  // [ST][C][N][4][n]OFF
  if (!keyword && extension != ".off") return;
  // Up to four counts: an optional dimension, vertices, faces, edges.
  std::vector<std::string> tokens;
  if (keyword) {
    if (first.size() > off + 3) tokens.push_back(first.substr(off + 3));
  } else {
    tokens.push_back(first);
  }
  for (std::string t; tokens.size() < 4 && lines >> t;) tokens.push_back(t);
  for (const std::string& t : tokens) {
    const auto n = leading_count(t);
    if (!n) break;
    if (*n > bytes) refuse_count(path, *n, "vertices, faces or edges", bytes);
  }
}

// What the import child sends back: the materials (at least one), then the
// triangles in world space, in this process's own layout.
struct ImportedMaterial {
  glm::vec4 diffuse{0.7f, 0.7f, 0.7f, 1.0f};
  float opacity = 1.0f;
  std::string name = "material";
};
static_assert(std::is_trivially_copyable_v<SoupTriangle>);

template <class T>
void put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

// Runs in the import child: assimp reads the file, and what occull needs of
// it is written out as bytes.
std::string import_with_assimp(const std::string& path) {
  Assimp::Importer importer;
  // ValidateDataStructure runs before the other steps and rejects what an
  // importer made of a malformed file (e.g. faces of an OFF file naming
  // vertices it lacks), on which assimp's own steps assert and abort the
  // process (found by fuzz_model).
  const aiScene* s = importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                                 aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices |
                                                 aiProcess_SortByPType);
  if (!s || !s->mRootNode || (s->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
    // assimp catches std::bad_alloc and reports it as text; the child's
    // limit should be named instead.
    if (std::string_view(importer.GetErrorString()).find("bad_alloc") != std::string_view::npos) throw std::bad_alloc();
    throw InputError(fmt::format("{}: cannot be read as a model ({})", path, importer.GetErrorString()));
  }
  std::vector<SoupTriangle> tris;
  collect(s, s->mRootNode, glm::mat4(1.0f), tris);
  if (tris.empty()) throw InputError(fmt::format("{}: has no triangles", path));

  std::string out;
  const std::uint64_t materials = std::max(1u, s->mNumMaterials);
  put(out, materials);
  for (unsigned m = 0; m < materials; ++m) {
    aiColor4D diffuse(0.7f, 0.7f, 0.7f, 1.0f);
    float opacity = 1.0f;
    aiString name("material");
    if (m < s->mNumMaterials) {
      s->mMaterials[m]->Get(AI_MATKEY_COLOR_DIFFUSE, diffuse);
      s->mMaterials[m]->Get(AI_MATKEY_OPACITY, opacity);
      s->mMaterials[m]->Get(AI_MATKEY_NAME, name);
    }
    put(out, glm::vec4(diffuse.r, diffuse.g, diffuse.b, diffuse.a));
    put(out, opacity);
    put(out, std::uint32_t(name.length));
    out.append(name.C_Str(), name.length);
  }
  put(out, std::uint64_t(tris.size()));
  out.append(reinterpret_cast<const char*>(tris.data()), tris.size() * sizeof(SoupTriangle));
  return out;
}

// Reads import_with_assimp's bytes back. They come from our own code in the
// child, so a short read is a bug of ours, not damage.
class ImportReader {
 public:
  explicit ImportReader(const std::string& bytes) : bytes_(bytes) {}
  const char* take(std::uint64_t size) {
    if (size > bytes_.size() - at_)
      throw std::logic_error(fmt::format("model import: its result is {} bytes, cut short at {}", bytes_.size(), at_));
    const char* p = bytes_.data() + at_;
    at_ += std::size_t(size);
    return p;
  }
  template <class T>
  T get() {
    T value;
    std::memcpy(&value, take(sizeof value), sizeof value);
    return value;
  }

 private:
  const std::string& bytes_;
  std::size_t at_ = 0;
};

}  // namespace

SceneBundle load_model_file(const std::string& path, std::uint32_t object_triangles, const ChildLimits& import_limits) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(fmt::format("{}: no such file", path));
  limits::check_file_size(path, limits::model_bytes, "a model (occull::limits::model_bytes)");
  check_declared_counts(path);
  const std::string bytes = run_in_child([&] { return import_with_assimp(path); }, import_limits,
                                         fmt::format("{}: assimp's import", path));
  ImportReader in(bytes);
  std::vector<ImportedMaterial> imported(in.get<std::uint64_t>());
  for (ImportedMaterial& m : imported) {
    m.diffuse = in.get<glm::vec4>();
    m.opacity = in.get<float>();
    const auto length = in.get<std::uint32_t>();
    m.name.assign(in.take(length), length);
  }
  std::vector<SoupTriangle> tris(in.get<std::uint64_t>());
  std::memcpy(static_cast<void*>(tris.data()), in.take(tris.size() * sizeof(SoupTriangle)), tris.size() * sizeof(SoupTriangle));

  const std::string name = std::filesystem::path(path).filename().string();
  SceneBundle bundle{Scene("file:" + name), {}, Lens{}};
  Scene& scene = bundle.scene;
  std::vector<MaterialId> materials;
  for (const ImportedMaterial& m : imported) {
    const bool translucent = m.opacity < 0.99f;
    materials.push_back(scene.add_material(
        {m.name, {m.diffuse.r, m.diffuse.g, m.diffuse.b, translucent ? m.opacity : 1.0f}, translucent, 0}));
  }
  std::vector<std::pair<std::size_t, std::size_t>> groups;
  // Cluster per material, so objects keep their own colour.
  std::stable_sort(tris.begin(), tris.end(), [](const SoupTriangle& a, const SoupTriangle& b) { return a.material < b.material; });
  for (std::size_t begin = 0; begin < tris.size();) {
    std::size_t end = begin;
    while (end < tris.size() && tris[end].material == tris[begin].material) ++end;
    cluster_triangles(tris, begin, end, std::max<std::uint32_t>(object_triangles, 16), groups);
    begin = end;
  }
  for (const auto& [begin, end] : groups) {
    auto [mesh, material] = mesh_of(tris, begin, end);
    const MaterialId m = materials[std::size_t(std::min<std::int32_t>(material, std::int32_t(materials.size()) - 1))];
    scene.add_object(scene.add_mesh(std::move(mesh)), m, glm::mat4(1.0f),
                     scene.material(m).translucent ? OccluderClass::never : OccluderClass::always);
  }

  add_model_views(bundle);
  return bundle;
}

}  // namespace occull::scenes

namespace occull {

void add_model_views(SceneBundle& bundle) {
  const Aabb box = bundle.scene.bounds();
  const glm::vec3 c = box.center();
  const float radius = std::max(0.5f * glm::length(box.extent()), 1e-3f);
  bundle.lens = Lens{60.0f, radius * 1e-3f, radius * 20.0f};
  std::vector<CameraPath::Key> orbit;
  for (int k = 0; k <= 16; ++k) {
    const float a = glm::two_pi<float>() * float(k) / 16.0f;
    const glm::vec3 eye = c + glm::vec3(1.6f * radius * std::sin(a), 0.45f * radius, 1.6f * radius * std::cos(a));
    const glm::vec3 d = c - eye;
    orbit.push_back({1.0 * k, {eye, std::atan2(-d.x, -d.z), std::atan2(d.y, std::hypot(d.x, d.z))}, false});
  }
  bundle.paths.emplace_back("orbit", "circles the model at 1.6 radii, looking at its centre", std::move(orbit));
  bundle.paths.emplace_back("through", "flies straight through the middle of the model",
                            std::vector<CameraPath::Key>{{0.0, {c + glm::vec3(0, 0, 1.5f * radius), 0.0f, 0.0f}, false},
                                                         {8.0, {c - glm::vec3(0, 0, 1.5f * radius), 0.0f, 0.0f}, false}});
}

}  // namespace occull
