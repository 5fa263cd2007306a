// Promises the repository makes about itself.

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace {

std::string slurp(const std::string& relative) {
  std::ifstream in(std::string(POUNDSIM_SOURCE_DIR) + "/" + relative);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Repository, CiRunsTheReadmeTestCommand) {
  const std::string ci = slurp(".ci/run"), readme = slurp("README.md");
  const std::string command = "./scripts/install-deps.sh && cmake --workflow --preset ci";
  EXPECT_NE(ci.find("\n" + command + "\n"), std::string::npos) << ci;
  EXPECT_NE(readme.find("\n" + command + "\n"), std::string::npos);
}

TEST(Repository, ReadmeMainJobReproducesThePaper) {
  const std::string readme = slurp("README.md");
  EXPECT_NE(readme.find("\n./scripts/install-deps.sh && cmake --preset release && cmake --build --preset "
                        "release && cmake --install build/release --prefix ~/.local && ./scripts/reproduce-paper.sh\n"),
            std::string::npos);
  const std::string script = slurp("scripts/reproduce-paper.sh");
  for (const char* figure : {"2a", "2b", "2c", "3a", "3b", "4a", "4b"}) {
    EXPECT_FALSE(slurp(std::string("examples/paper/fig") + figure + ".toml").empty()) << figure;
  }
  EXPECT_NE(script.find("figures=(2a 2b 2c 3a 3b 4a 4b)"), std::string::npos);
}

// The layers of docs/architecture.md: a file includes poundsim headers of its own layer and the
// layers below only, and the core (model … analysis) includes no reader or writer library.
TEST(Repository, LayersIncludeOnlyTheLayersBelow) {
  const std::map<std::string, int> rank = {
      {"model", 0}, {"dynamics", 1}, {"integrate", 2}, {"analysis", 3}, {"io", 4}, {"optimize", 5}};
  const std::regex poundsim_include(R"re(#include\s+"poundsim/(\w+)/)re");
  const std::regex library_include(R"re(#include\s+<(toml\+\+|nlohmann|SQLiteCpp|sqlite3|nlopt))re");
  int files = 0;
  for (const char* root : {"include/poundsim", "src"}) {
    for (const auto& [layer, own] : rank) {
      const std::filesystem::path folder = std::filesystem::path(POUNDSIM_SOURCE_DIR) / root / layer;
      ASSERT_TRUE(std::filesystem::is_directory(folder)) << folder;
      for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
        const std::string relative =
            std::filesystem::relative(entry.path(), POUNDSIM_SOURCE_DIR).string();
        const std::string text = slurp(relative);
        ++files;
        for (std::sregex_iterator it(text.begin(), text.end(), poundsim_include), end; it != end;
             ++it) {
          const std::string used = (*it)[1];
          ASSERT_TRUE(rank.contains(used)) << relative << " includes poundsim/" << used;
          EXPECT_LE(rank.at(used), own) << relative << " (" << layer << ") includes poundsim/"
                                        << used << "/: a layer above its own";
        }
        if (own < rank.at("io")) {
          EXPECT_FALSE(std::regex_search(text, library_include))
              << relative << ": the core links Eigen and fmt only";
        }
      }
    }
  }
  EXPECT_GT(files, 40);
}

}  // namespace
