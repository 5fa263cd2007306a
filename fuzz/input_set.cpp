// Fuzz target: the model-file reader with --set overrides. The input is split at NUL bytes (which
// neither a TOML file nor a command-line argument can hold): the first part is the model text,
// each further part one `key=value` override, in order (at most 16, as a command line would be).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_support.hpp"
#include "poundsim/io/input.hpp"
#include "scratch_records.hpp"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  poundsim::fuzz::install_records(poundsim::fuzz::scratch_dir());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string_view> parts;
  for (std::string_view rest(reinterpret_cast<const char*>(data), size);;) {
    const std::size_t end = rest.find('\0');
    parts.push_back(rest.substr(0, end));
    if (end == std::string_view::npos) break;
    rest.remove_prefix(end + 1);
  }
  const std::string_view model = parts.front();
  const std::vector<std::string> overrides(parts.begin() + 1,
                                           parts.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(parts.size(), 17)));
  poundsim::fuzz::expect_only_input_errors([&] {
    (void)poundsim::io::read_input_string(model, "fuzz.toml", poundsim::fuzz::scratch_dir(), overrides);
  });
  return 0;
}
