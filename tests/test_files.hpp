#pragma once
// Files and folders shared by the tests that run the CLI or write outputs.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace poundsim::testing {

/// An empty folder `poundsim_<name>` in the temporary directory (emptied if it exists).
inline std::filesystem::path fresh_folder(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("poundsim_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The whole content of a file ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace poundsim::testing
