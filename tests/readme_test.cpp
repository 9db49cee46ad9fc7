// The library guide (docs/library.md) quotes the example engine, which is
// compiled and run by the tests: every region of examples/engine/main.cpp
// between "// [readme: NAME]" and "// [readme end]" must appear in it as it
// stands (less the region's common indentation), and every C++ block of
// README.md must be one of those regions, so none of them can drift.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::string read(const std::string& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Region {
  std::string name, body;
};

std::vector<Region> regions_of(const std::string& source) {
  std::vector<Region> out;
  std::istringstream in(source);
  std::string line;
  Region* open = nullptr;
  std::size_t indent = std::string::npos;
  std::vector<std::string> lines;
  while (std::getline(in, line)) {
    const auto mark = line.find("// [readme: ");
    if (mark != std::string::npos) {
      out.push_back({line.substr(mark + 12, line.find(']', mark) - mark - 12), {}});
      open = &out.back();
      lines.clear();
      indent = std::string::npos;
      continue;
    }
    if (open && line.find("// [readme end]") != std::string::npos) {
      for (const std::string& l : lines) open->body += (l.size() >= indent ? l.substr(indent) : l) + "\n";
      open = nullptr;
      continue;
    }
    if (!open) continue;
    const auto first = line.find_first_not_of(' ');
    if (first != std::string::npos) indent = std::min(indent, first);
    lines.push_back(line);
  }
  return out;
}

}  // namespace

TEST(Readme, QuotesTheExampleEngineAsItStands) {
  const std::string source = read(std::string(OCCULL_SOURCE_DIR) + "/examples/engine/main.cpp");
  const std::string guide = read(std::string(OCCULL_SOURCE_DIR) + "/docs/library.md");
  const std::vector<Region> regions = regions_of(source);
  ASSERT_GE(regions.size(), 4u) << "examples/engine/main.cpp lost its [readme: NAME] regions";
  for (const Region& r : regions) {
    ASSERT_FALSE(r.body.empty()) << r.name;
    EXPECT_NE(guide.find(r.body), std::string::npos)
        << "docs/library.md does not quote the example engine's region '" << r.name << "' as it stands:\n"
        << r.body;
  }
  const std::string readme = read(std::string(OCCULL_SOURCE_DIR) + "/README.md");
  std::size_t blocks = 0;
  for (std::size_t at = readme.find("```cpp\n"); at != std::string::npos; at = readme.find("```cpp\n", at)) {
    at += 7;
    const std::string block = readme.substr(at, readme.find("```", at) - at);
    ++blocks;
    EXPECT_TRUE(std::any_of(regions.begin(), regions.end(), [&](const Region& r) { return r.body == block; }))
        << "README.md quotes C++ that is no region of the example engine:\n"
        << block;
  }
  EXPECT_GT(blocks, 0u) << "README.md quotes the example engine";
}
