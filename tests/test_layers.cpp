// The library's folders form layers (docs/architecture.md): a folder includes only folders of a
// lower layer (and itself), so no two folders know each other. Read from the sources.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>

namespace {

namespace fs = std::filesystem;

// Lowest first; the table docs/architecture.md draws.
const std::map<std::string, int> kLayer = {
    {"core", 0},         {"io", 1},   {"geometry", 1}, {"features", 2},  {"sim", 2},
    {"registration", 3}, {"eval", 4}, {"mapping", 4},  {"mapping2d", 4}, {"odometry", 4},
    {"config", 5},       {"run", 6},  {"benchmark", 7}};

TEST(Layers, EachLibraryFolderIncludesOnlyLowerLayers) {
  const fs::path library = fs::path(SCANMATCH_SOURCE_DIR) / "scanmatch";
  ASSERT_TRUE(fs::is_directory(library)) << library;
  const std::regex include(R"re(^\s*#include\s+"scanmatch/([a-z0-9_]+)/)re");
  std::size_t files = 0, includes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(library)) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".hpp" && ext != ".cpp")) continue;
    const std::string folder = fs::relative(entry.path(), library).begin()->string();
    const auto own = kLayer.find(folder);
    ASSERT_NE(own, kLayer.end()) << "a library folder missing from the layer table: " << folder;
    ++files;
    std::ifstream in(entry.path());
    std::string line;
    std::smatch m;
    while (std::getline(in, line)) {
      if (!std::regex_search(line, m, include)) continue;
      ++includes;
      const std::string used = m[1];
      if (used == folder) continue;
      const auto other = kLayer.find(used);
      ASSERT_NE(other, kLayer.end()) << entry.path() << " includes an unknown folder: " << line;
      EXPECT_LT(other->second, own->second)
          << entry.path() << " (" << folder << ", layer " << own->second << ") includes " << used
          << " (layer " << other->second << "): " << line;
    }
  }
  EXPECT_GT(files, 100u);
  EXPECT_GT(includes, 300u);
}

}  // namespace
