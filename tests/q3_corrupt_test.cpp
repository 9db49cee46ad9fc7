// Damaged Quake 3 input: every case a clear InputError naming the file and
// the fault, never a crash. Also built with AddressSanitizer (see CMake).
#include "occull/error.hpp"
#include "occull/q3bsp.hpp"
#include "tiny_bsp.hpp"

#include <gtest/gtest.h>
#include <minizip/zip.h>
#include <fmt/format.h>
#include <zlib.h>

#include <fstream>

using namespace occull;

namespace {

std::string error_of(const std::vector<std::byte>& bytes) {
  try {
    (void)q3::read_bsp(bytes, "bad.bsp");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::size_t lump_offset(const std::vector<std::byte>& b, int lump) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | std::to_integer<std::uint32_t>(b[8 + std::size_t(lump) * 8 + std::size_t(i)]);
  return v;
}

}  // namespace

TEST(Q3Corrupt, TruncatedHeader) {
  auto b = test::TinyBsp::example().bytes();
  b.resize(50);
  EXPECT_NE(error_of(b).find("bad.bsp: truncated"), std::string::npos) << error_of(b);
}

TEST(Q3Corrupt, TruncatedBody) {
  auto b = test::TinyBsp::example().bytes();
  b.resize(b.size() - 10);
  EXPECT_NE(error_of(b).find("outside the file"), std::string::npos) << error_of(b);
}

TEST(Q3Corrupt, WrongMagic) {
  auto b = test::TinyBsp::example().bytes();
  b[0] = std::byte{'X'};
  EXPECT_NE(error_of(b).find("magic"), std::string::npos);
}

TEST(Q3Corrupt, WrongVersion) {
  auto b = test::TinyBsp::example().bytes();
  test::TinyBsp::put(b, 4, 47);
  EXPECT_NE(error_of(b).find("version 47"), std::string::npos);
}

TEST(Q3Corrupt, LumpPointsOutsideTheFile) {
  auto b = test::TinyBsp::example().bytes();
  test::TinyBsp::put(b, 8 + 10 * 8, 1 << 30);
  EXPECT_NE(error_of(b).find("lump 10 (vertexes)"), std::string::npos) << error_of(b);
}

TEST(Q3Corrupt, LumpOfPartialRecords) {
  auto b = test::TinyBsp::example().bytes();
  test::TinyBsp::put(b, 12 + 13 * 8, 100);  // faces are 104 bytes each
  EXPECT_NE(error_of(b).find("whole number"), std::string::npos) << error_of(b);
}

TEST(Q3Corrupt, AbsurdFaceCounts) {
  auto b = test::TinyBsp::example().bytes();
  const std::size_t face0 = lump_offset(b, 13);
  test::TinyBsp::put(b, face0 + 16, 2000000000);  // vertex count
  EXPECT_NE(error_of(b).find("face 0 has vertices"), std::string::npos) << error_of(b);
  b = test::TinyBsp::example().bytes();
  test::TinyBsp::put(b, face0 + 24, -6);  // mesh vertex count
  EXPECT_NE(error_of(b).find("face 0 has mesh vertices"), std::string::npos) << error_of(b);
  b = test::TinyBsp::example().bytes();
  test::TinyBsp::put(b, face0 + 104 + 96, 4);  // patch width even
  EXPECT_NE(error_of(b).find("face 1: a 4 x 3 patch"), std::string::npos) << error_of(b);
}

TEST(Q3Corrupt, MeshVertexOutOfItsFace) {
  auto bsp = test::TinyBsp::example();
  bsp.meshverts[2] = 9;
  EXPECT_NE(error_of(bsp.bytes()).find("points to vertex 9"), std::string::npos);
}

TEST(Q3Corrupt, BrokenEntities) {
  auto bsp = test::TinyBsp::example();
  bsp.entities = "{ \"classname\" \"worldspawn";
  EXPECT_NE(error_of(bsp.bytes()).find("entities"), std::string::npos);
}

TEST(Q3Corrupt, NotAZipArchive) {
  const std::string path = ::testing::TempDir() + "occull_not_a.pk3";
  std::ofstream(path) << "this is not a zip";
  try {
    (void)q3::read_map_from_pk3(path, "x");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a zip"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
}

TEST(Q3Corrupt, MissingMapListsTheArchiveMaps) {
  const std::string path = ::testing::TempDir() + "occull_test.pk3";
  zipFile z = zipOpen(path.c_str(), APPEND_STATUS_CREATE);
  ASSERT_NE(z, nullptr);
  const auto bytes = test::TinyBsp::example().bytes();
  zip_fileinfo info{};
  ASSERT_EQ(zipOpenNewFileInZip(z, "maps/tiny.bsp", &info, nullptr, 0, nullptr, 0, nullptr, Z_DEFLATED, 6), ZIP_OK);
  zipWriteInFileInZip(z, bytes.data(), unsigned(bytes.size()));
  zipCloseFileInZip(z);
  zipClose(z, nullptr);
  EXPECT_EQ(q3::read_map_from_pk3(path, "tiny"), bytes);
  EXPECT_EQ(q3::list_maps(path), std::vector<std::string>{"tiny"});
  try {
    (void)q3::read_map_from_pk3(path, "huge");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no map 'huge'; maps in it: tiny"), std::string::npos) << e.what();
  }
}

TEST(Q3Corrupt, EveryTruncationIsAnErrorNotACrash) {
  const auto full = test::TinyBsp::example().bytes();
  for (std::size_t n = 0; n < full.size(); n += 7) {
    const std::vector<std::byte> cut(full.begin(), full.begin() + long(n));
    EXPECT_NE(error_of(cut), "(no error)") << n;
  }
}

namespace {

// A .pk3 with one stored (uncompressed) entry maps/NAME.bsp holding `bytes`,
// whose directory claims `claimed` bytes once inflated.
std::string pk3_claiming(const std::string& name, const std::vector<std::byte>& bytes, std::uint64_t claimed) {
  const std::string path = ::testing::TempDir() + "occull_claims_" + name + ".pk3";
  zipFile z = zipOpen64(path.c_str(), APPEND_STATUS_CREATE);
  zip_fileinfo info{};
  const std::string entry = "maps/" + name + ".bsp";
  zipOpenNewFileInZip2_64(z, entry.c_str(), &info, nullptr, 0, nullptr, 0, nullptr, 0 /* stored */, 0, 1 /* raw */,
                          claimed > 0xffffffffu);
  zipWriteInFileInZip(z, bytes.data(), unsigned(bytes.size()));
  zipCloseFileInZipRaw64(z, claimed, crc32(0, reinterpret_cast<const Bytef*>(bytes.data()), uInt(bytes.size())));
  zipClose(z, nullptr);
  return path;
}

std::string pk3_error(const std::string& path, const std::string& map) {
  try {
    (void)q3::read_map_from_pk3(path, map);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(Q3Corrupt, AnEntryClaimingMoreThanTheMapLimitIsRefusedNamingTheLimit) {
  const auto bytes = test::TinyBsp::example().bytes();
  const std::string path = pk3_claiming("huge", bytes, std::uint64_t(3) << 30);
  const std::string e = pk3_error(path, "huge");
  EXPECT_NE(e.find("claims 3221225472 bytes, past the limit of 268435456 bytes for a map (occull::limits::map_bytes)"),
            std::string::npos) << e;
  EXPECT_NE(e.find(path), std::string::npos) << e;
}

TEST(Q3Corrupt, AnEntryInflatingToLessThanItClaimsIsDamaged) {
  const auto bytes = test::TinyBsp::example().bytes();
  const std::string path = pk3_claiming("short", bytes, 100u << 20);
  const std::string e = pk3_error(path, "short");
  EXPECT_NE(e.find(fmt::format("maps/short.bsp is damaged (inflates to {} bytes, its directory says 104857600)",
                               bytes.size())),
            std::string::npos) << e;
}

TEST(Q3Corrupt, AnEntryInflatingToMoreThanItClaimsIsDamaged) {
  const auto bytes = test::TinyBsp::example().bytes();
  const std::string path = pk3_claiming("long", bytes, 16);
  const std::string e = pk3_error(path, "long");
  EXPECT_NE(e.find("maps/long.bsp is damaged (inflates to"), std::string::npos) << e;
  EXPECT_NE(e.find("its directory says 16)"), std::string::npos) << e;
}

TEST(Q3Corrupt, TheFuzzedArchiveClaimingGigabytesIsRefusedWithoutAllocatingThem) {
  // Found by fuzz_pk3 (an out-of-memory): 151 bytes claiming ~2 GB inflated.
  const std::string path = std::string(OCCULL_SOURCE_DIR) + "/tests/corpus/pk3/claims-2gb.pk3";
  const std::string e = pk3_error(path, "a");
  EXPECT_NE(e.find("past the limit of 268435456 bytes for a map"), std::string::npos) << e;
}
