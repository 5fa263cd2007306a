// Fuzz target: the model-file reader, poundsim::io::read_input_string (text → RunInput).
// Relative paths resolve against a scratch folder holding a few small records (records/...).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "poundsim/io/input.hpp"
#include "scratch_records.hpp"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  poundsim::fuzz::install_records(poundsim::fuzz::scratch_dir());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  poundsim::fuzz::expect_only_input_errors(
      [&] { (void)poundsim::io::read_input_string(text, "fuzz.toml", poundsim::fuzz::scratch_dir()); });
  return 0;
}
