// Promises the repository makes about itself.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

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

// The README says what poundsim is, gives the two set-up commands, one short example and the links;
// the rest is in docs/ (the guide first).
TEST(Repository, ReadmeIsShortAndLinksTheGuideReferenceAndExplanations) {
  const std::string readme = slurp("README.md");
  EXPECT_LE(std::count(readme.begin(), readme.end(), '\n'), 150);
  for (const char* page : {"docs/guide.md", "docs/input.md", "docs/output.md", "docs/model.md", "docs/numerics.md",
                           "docs/periodic-orbits.md", "docs/verification.md", "docs/architecture.md", "docs/python.md",
                           "docs/studies.md", "docs/records.md", "docs/paper-reproduction.md"}) {
    EXPECT_NE(readme.find(std::string("(") + page + ")"), std::string::npos) << page;
    // Each page says what it is for in a paragraph under its title, before its first section.
    const std::string text = slurp(page);
    const std::size_t title_end = text.find('\n'), first_section = text.find("\n## ");
    ASSERT_NE(title_end, std::string::npos) << page;
    const std::string intro = text.substr(title_end, first_section == std::string::npos ? std::string::npos
                                                                                        : first_section - title_end);
    EXPECT_GT(std::count_if(intro.begin(), intro.end(), [](char c) { return c == ' '; }), 20)
        << page << ": no paragraph says what the page is for";
  }
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

// Docs, examples, comments and docstrings say what is true now; history lives in git. A
// work-log marker anywhere in them fails: a session or stop number, a tracker reference (issue 12,
// (#12)), a commit hash (seven or more hexadecimal digits with letters and digits, not 0x…), a
// numbered log heading in Markdown ("## 3. …" outside code), or "used to" narrating an old
// behaviour. The committed checksums and fuzz corpora are data, not prose, and are left out.
TEST(Repository, NoWorkLogMarkersInDocsCodeOrDocstrings) {
  namespace fs = std::filesystem;
  const std::regex marker(
      R"re(\b([Ss]ession|[Ss]top) [0-9]+\b|\b[Ii]ssues? #?[0-9]+\b|\(#[0-9]+\)|\bused to (fail|finish|crash)\b)re");
  // A hexadecimal word, not part of a number (3.437285e-04) or of 0x…; an upstream source's
  // commit in a provenance line ("owner/name at 3c5339f7") is where a file came from, not history.
  const std::regex hash(R"re((^|[^0-9A-Za-z_.+-])([0-9a-f]{7,40})($|[^0-9A-Za-z_.+-]))re");
  const std::regex provenance(R"re([\w.-]+/[\w.-]+ at [0-9a-f]{7,40})re");
  const std::regex heading(R"re(^#{1,6} +[0-9]+[.)] )re");
  const std::vector<std::string> roots{"README.md", "docs", "examples", "src", "include", "apps", "python",
                                       "bench", "scripts", "fuzz", "tests", "cmake", "CMakeLists.txt"};
  const auto scanned = [](const fs::path& path) {
    const std::string name = path.filename().string(), ext = path.extension().string();
    if (path.string().find("/corpus") != std::string::npos || name == "outputs.json") return false;
    return ext == ".md" || ext == ".cpp" || ext == ".hpp" || ext == ".py" || ext == ".pyi" || ext == ".sh" ||
           ext == ".toml" || ext == ".cmake" || name == "CMakeLists.txt";
  };
  int files = 0;
  for (const std::string& root : roots) {
    const fs::path top = fs::path(POUNDSIM_SOURCE_DIR) / root;
    std::vector<fs::path> paths;
    if (fs::is_regular_file(top)) paths.push_back(top);
    for (const auto& e : fs::is_directory(top) ? fs::recursive_directory_iterator(top) : fs::recursive_directory_iterator())
      if (e.is_regular_file() && scanned(e.path())) paths.push_back(e.path());
    for (const fs::path& path : paths) {
      const std::string relative = fs::relative(path, POUNDSIM_SOURCE_DIR).string();
      if (relative == "tests/repository_test.cpp") continue;  // the patterns themselves
      std::istringstream text(slurp(relative));
      bool fenced = false;
      int number = 0;
      ++files;
      for (std::string line; std::getline(text, line);) {
        ++number;
        if (line.starts_with("```")) fenced = !fenced;
        std::smatch m;
        EXPECT_FALSE(std::regex_search(line, marker)) << relative << ":" << number << ": " << line;
        if (std::regex_search(line, m, hash) && !std::regex_search(line, provenance)) {
          const std::string h = m[2];
          const bool letters = h.find_first_of("abcdef") != std::string::npos;
          const bool digits = h.find_first_of("0123456789") != std::string::npos;
          EXPECT_FALSE(letters && digits) << relative << ":" << number << ": a commit hash? " << line;
        }
        if (path.extension() == ".md" && !fenced) {
          EXPECT_FALSE(std::regex_search(line, heading)) << relative << ":" << number << ": " << line;
        }
      }
    }
  }
  EXPECT_GT(files, 200);
}

}  // namespace
