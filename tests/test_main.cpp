// main() of every occull test program. Each process gets a cache folder of
// its own (XDG_CACHE_HOME, where calibrated hardware profiles go), removed
// at exit: no test reads a profile another test, a parallel test process or
// the user wrote. ctest runs every test in its own process.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <stdlib.h>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  namespace fs = std::filesystem;
  std::string folder = (fs::temp_directory_path() / "occull-test-cache-XXXXXX").string();
  if (!mkdtemp(folder.data())) {
    std::perror("occull tests: cannot create a private cache folder");
    return 1;
  }
  setenv("XDG_CACHE_HOME", folder.c_str(), 1);
  const int result = RUN_ALL_TESTS();
  std::error_code ignored;
  fs::remove_all(folder, ignored);
  return result;
}
