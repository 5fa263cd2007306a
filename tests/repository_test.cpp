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

TEST(Repository, ReadmeMainJobRunsAnExampleThatExists) {
  const std::string readme = slurp("README.md");
  const auto at = readme.find("./build/release/poundsim run examples/");
  ASSERT_NE(at, std::string::npos);
  const auto start = readme.find("examples/", at);
  const std::string example = readme.substr(start, readme.find(' ', start) - start);
  EXPECT_FALSE(slurp(example).empty()) << example;
}

}  // namespace
