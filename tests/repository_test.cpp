// Promises the repository makes about itself.

#include <fstream>
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
                        "release && ./scripts/reproduce-paper.sh\n"),
            std::string::npos);
  const std::string script = slurp("scripts/reproduce-paper.sh");
  for (const char* figure : {"2a", "2b", "2c", "3a", "3b", "4a", "4b"}) {
    EXPECT_FALSE(slurp(std::string("examples/paper/fig") + figure + ".toml").empty()) << figure;
  }
  EXPECT_NE(script.find("figures=(2a 2b 2c 3a 3b 4a 4b)"), std::string::npos);
}

}  // namespace
