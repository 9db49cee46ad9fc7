#include "occull/error.hpp"
#include "occull/view.hpp"

#include <gtest/gtest.h>

#include <fstream>

using namespace occull;

namespace {
std::string write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}
std::string error_reading(const std::string& path) {
  try {
    (void)read_path_file(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}
}  // namespace

TEST(PathFile, RoundTripsAGeneratedPath) {
  const CameraPath p("walk", "", {{0.0, {{1, 2, 3}, 0.5f, -0.1f}, false}, {2.5, {{4, 5, 6}, 1.0f, 0.2f}, true}});
  const std::string file = ::testing::TempDir() + "occull_path.txt";
  write_path_file(p, file);
  const CameraPath q = read_path_file(file);
  ASSERT_EQ(q.keys().size(), 2u);
  EXPECT_EQ(q.name(), "file:occull_path.txt");
  EXPECT_NEAR(q.keys()[1].time, 2.5, 1e-6);
  EXPECT_NEAR(q.keys()[1].pose.position.y, 5.0f, 1e-4f);
  EXPECT_NEAR(q.keys()[0].pose.yaw, 0.5f, 1e-4f);
  EXPECT_NEAR(q.keys()[1].pose.pitch, 0.2f, 1e-4f);
  EXPECT_TRUE(q.keys()[1].cut);
}

TEST(PathFile, CommentsAndBlankLinesAreSkipped) {
  const CameraPath p = read_path_file(write("occull_path2.txt", "# a path\n\n0 0 1.7 0 0 0\n  # more\n1 0 1.7 -5 90 10\n"));
  EXPECT_EQ(p.keys().size(), 2u);
  EXPECT_NEAR(p.keys()[1].pose.yaw, glm::radians(90.0f), 1e-5f);
}

TEST(PathFile, MistakesNameTheLine) {
  EXPECT_NE(error_reading(write("p3.txt", "0 0 0 0 0 0\n1 2 3\n")).find("p3.txt:2: expected"), std::string::npos);
  EXPECT_NE(error_reading(write("p4.txt", "1 0 0 0 0 0\n0.5 0 0 0 0 0\n")).find(":2: time 0.5 does not increase"),
            std::string::npos);
  EXPECT_NE(error_reading(write("p5.txt", "0 0 0 0 0 0 jump\n")).find("\"jump\""), std::string::npos);
  EXPECT_NE(error_reading(write("p6.txt", "0 0 0 0 0 95\n")).find("pitch"), std::string::npos);
  EXPECT_NE(error_reading(write("p7.txt", "# nothing\n")).find("no poses"), std::string::npos);
  EXPECT_NE(error_reading(::testing::TempDir() + "does-not-exist.txt").find("cannot be opened"), std::string::npos);
}
