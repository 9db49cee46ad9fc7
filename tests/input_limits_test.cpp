// The caps on input (occull/input_limits.hpp): a file, string or scene past
// one is an InputError naming it, its size and the limit, before anything
// that size is allocated.
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "occull/q3bsp.hpp"
#include "occull/scene.hpp"
#include "occull/scenes.hpp"
#include "occull/view.hpp"
#include "scenes/model_file.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

using namespace occull;

namespace {

// `text` as the file NAME in the test's temporary folder; returns its path.
std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string file_of(const std::string& name, std::size_t bytes) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << std::string(bytes, '#');
  return path;
}

}  // namespace

TEST(InputLimits, AFileLargerThanItsLimitIsRefusedNamingTheFileItsSizeAndTheLimit) {
  const std::string path = file_of("occull_limits_big.txt", 1000);
  const std::string e = error_of([&] { (void)limits::read_file(path, 999, "a test file"); });
  EXPECT_EQ(e, path + ": 1000 bytes is past the limit of 999 bytes for a test file");
  EXPECT_EQ(limits::read_file(path, 1000, "a test file").size(), 1000u);
}

TEST(InputLimits, AFolderOrAMissingFileIsAnErrorNamingIt) {
  const std::string dir = ::testing::TempDir();
  EXPECT_NE(error_of([&] { (void)limits::read_file(dir, 10, "x"); }).find("is a folder"), std::string::npos);
  EXPECT_NE(error_of([&] { (void)limits::read_file(dir + "/no-such-file", 10, "x"); }).find("cannot be opened"),
            std::string::npos);
}

TEST(InputLimits, APathFilePastTheTextLimitIsRefusedBeforeItIsParsed) {
  const std::string path = file_of("occull_limits_big.path", limits::text_file_bytes + 1);
  const std::string e = error_of([&] { (void)read_path_file(path); });
  EXPECT_NE(e.find("past the limit of 16777216 bytes for a path file (occull::limits::text_file_bytes)"),
            std::string::npos) << e;
  std::filesystem::remove(path);
}

TEST(InputLimits, SpecsLongerThanTheLimitAreRefusedShowingTheirStart) {
  const std::string scene = "city:" + std::string(limits::spec_chars, 'x');
  const std::string e = error_of([&] { (void)make_scene(scene); });
  EXPECT_NE(e.find("scene spec 'city:xxx"), std::string::npos) << e;
  EXPECT_NE(e.find("4101 characters is past the limit of 4096 (occull::limits::spec_chars)"), std::string::npos) << e;
  const std::string algo = "chcpp:" + std::string(limits::spec_chars, 'x');
  EXPECT_NE(error_of([&] { (void)parse_algorithm_spec(algo); }).find("is past the limit of 4096"), std::string::npos);
}

TEST(InputLimits, ASceneRefusesObjectsPastItsLimit) {
  Scene s("capped", SceneLimits{2, 100});
  const MaterialId m = s.add_material({});
  const MeshId mesh = s.add_mesh(test::box_mesh({{0, 0, 0}, {1, 1, 1}}));
  s.add_object(mesh, m, glm::mat4(1.0f), OccluderClass::always);
  s.add_object(mesh, m, glm::mat4(1.0f), OccluderClass::always);
  const std::string e = error_of([&] { s.add_object(mesh, m, glm::mat4(1.0f), OccluderClass::always); });
  EXPECT_EQ(e, "scene capped: more than 2 objects, the limit (occull::limits::objects)");
  EXPECT_EQ(s.objects().size(), 2u);
}

TEST(InputLimits, ASceneRefusesMeshTrianglesPastItsLimitCountingEachMeshOnce) {
  Scene s("capped", SceneLimits{100, 20});
  (void)s.add_mesh(test::box_mesh({{0, 0, 0}, {1, 1, 1}}));  // 12 triangles
  const std::string e = error_of([&] { (void)s.add_mesh(test::box_mesh({{0, 0, 0}, {1, 1, 1}})); });
  EXPECT_EQ(e, "scene capped: 24 triangles in its meshes is past the limit of 20 (occull::limits::mesh_triangles)");
  EXPECT_EQ(s.meshes().size(), 1u);
}

TEST(InputLimits, AMapWhosePatchesTessellatePastTheTriangleLimitIsRefusedBeforeTessellating) {
  // 32769 faces sharing one 3x3 patch: 2 x 32^2 triangles each at level 32,
  // 2^26 + 2048 in all, from a few kilobytes of map.
  q3::Map map;
  map.textures.push_back({"textures/test", 0, 1});
  for (int i = 0; i < 9; ++i) map.vertices.push_back({glm::vec3(float(i % 3), float(i / 3), 0.0f), glm::vec3(0, 0, 1)});
  q3::Face patch;
  patch.type = q3::FaceType::patch;
  patch.vertex_count = 9;
  patch.patch_width = patch.patch_height = 3;
  map.faces.assign((std::size_t(1) << 15) + 1, patch);
  const std::string e = error_of([&] { (void)q3::build_scene(map, "q3:patches", {32, 500}); });
  EXPECT_EQ(e, "q3:patches: its faces tessellate to 67110912 triangles at patch level 32, past the limit of "
               "67108864 (occull::limits::mesh_triangles)");
  map.faces.resize(4);
  EXPECT_EQ(q3::build_scene(map, "q3:patches", {32, 500}).scene.triangle_count(), 4u * 2048u);
}

// Found by fuzz_model: assimp's OFF importer allocated the 1.4 billion
// vertices a 140-byte file's header declared (16 GB) before reading any.
TEST(InputLimits, AModelHeaderDeclaringMoreItemsThanTheFileHasBytesIsRefusedBeforeAssimp) {
  // The fuzz input: its first byte picks the extension (3: off), the rest is the file.
  std::ifstream corpus(std::string(OCCULL_SOURCE_DIR) + "/tests/corpus/model/off-declares-billions.off", std::ios::binary);
  const std::string input((std::istreambuf_iterator<char>(corpus)), std::istreambuf_iterator<char>());
  ASSERT_EQ(input.size(), 140u);
  const std::string fuzzed = write_temp("occull_fuzzed.off", input.substr(1));
  EXPECT_NE(error_of([&] { (void)make_scene("file:" + fuzzed); }).find("its header declares over 10^15 vertices, faces or edges in a file of 139 bytes"),
            std::string::npos);
  const std::string off = write_temp("occull_many.off", "OFF\n3000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(error_of([&] { (void)make_scene("file:" + off); }),
            off + ": its header declares 3000000000 vertices, faces or edges in a file of 45 bytes: damaged");
  const std::string ply = write_temp("occull_many.ply",
                                "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NE(error_of([&] { (void)make_scene("file:" + ply); }).find("declares 4000000000 'vertex' elements"),
            std::string::npos);
  // The same files with true counts load.
  const std::string good_off = write_temp("occull_one.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(make_scene("file:" + good_off).scene.objects().size(), 1u);
  const std::string good_ply = write_temp("occull_one.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                     "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(make_scene("file:" + good_ply).scene.objects().size(), 1u);
}

// Found by fuzz_model: assimp's PLY reader never returned from the first
// three and the fifth, and aborted the process on the fourth.
TEST(InputLimits, APlyHeaderOutsideTheFormatIsRefusedBeforeAssimpNamingItsLine) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 1\nproperty list uchar int vertex_indices\n";
  const std::string data = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const auto error = [&](const std::string& name, const std::string& text) {
    const std::string path = write_temp(name, text);
    const std::string e = error_of([&] { (void)make_scene("file:" + path); });
    return e.rfind(path + ": ", 0) == 0 ? e.substr(path.size() + 2) : e;
  };
  EXPECT_EQ(error("occull_no_end.ply", header),
            "line 9 of its PLY header is not there: no end_header line in the first 143 bytes: damaged");
  EXPECT_EQ(error("occull_nul.ply", std::string("ply\nformat ascii 1.0\nelem\0v 0 0 0\nend_header\n", 45)),
            "line 3 of its PLY header has a NUL byte: damaged");
  EXPECT_EQ(error("occull_glued.ply", header + "end_headerrtex 3\n" + data),
            "line 9 of its PLY header starts with 'end_headerrtex', which no PLY header line does: damaged");
  EXPECT_EQ(error("occull_type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty floatcii 1.0\nend_header\n0\n"),
            "line 4 of its PLY header is not 'property TYPE NAME' or 'property list TYPE TYPE NAME' with TYPE one of "
            "PLY's: damaged");
  EXPECT_EQ(error("occull_magic.PLY", "ply\xff\xff\nformat ascii 1.0\nelement vertex 3\nproperty float3 0 1 2\n"),
            "line 1 of its PLY header is not 'ply': damaged");
  EXPECT_EQ(error("occull_twice.ply", "ply\nformat ascii 1.0\nelement v 1\nproperty float x\nelement v 1\nend_header\n"),
            "line 5 of its PLY header declares element 'v' again: damaged");
  // Comments, obj_info, CRLF line ends and the sized type names are PLY.
  const std::string fine = write_temp("occull_fine.ply",
                                      "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info none\r\n"
                                      "element vertex 3\r\nproperty float32 x\r\nproperty float32 y\r\n"
                                      "property float32 z\r\nelement face 1\r\nproperty list uint8 int32 vertex_indices\r\n"
                                      "end_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n");
  EXPECT_EQ(make_scene("file:" + fine).scene.objects().size(), 1u);
}

// assimp runs in a child process under limits: past one, loading ends in an
// InputError naming the file, the import and the limit, and this process
// goes on. (The wall-clock limit is the one a test can pass for certain:
// the child may reuse heap it inherits without passing its memory limit.
// tests/child_process_test.cpp ends children every way.)
TEST(InputLimits, AModelImportPastItsLimitIsAnInputErrorNamingTheFileAndTheLimit) {
  const std::string obj = std::string(OCCULL_SOURCE_DIR) + "/tests/corpus/model/cube.obj";
  const ChildLimits no_time{5, 1e-9, 0};
  EXPECT_EQ(error_of([&] { (void)scenes::load_model_file(obj, 1500, no_time); }),
            obj + ": assimp's import did not finish within 1e-09 s");
  EXPECT_GT(scenes::load_model_file(obj).scene.objects().size(), 0u);
}
