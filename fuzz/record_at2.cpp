// Fuzz target: the PEER AT2 reader (poundsim::io::read_ground_motion / parse_ground_motion with
// format = at2) with the options a model file leaves at their defaults: units from the file,
// scale 1.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "read_record.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  poundsim::io::RecordOptions options;
  options.format = poundsim::io::RecordFormat::at2;
  poundsim::fuzz::expect_only_input_errors([&] {
    (void)poundsim::fuzz::read_record(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.AT2", options);
  });
  return 0;
}
