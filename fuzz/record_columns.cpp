// Fuzz target: the column-file readers (poundsim::io::read_ground_motion / parse_ground_motion
// with format = columns or single).
//
// The record options come from an optional first line `# fuzz: <option> ...` (a comment to the
// reader, which skips it), limited to what a model file can ask for:
//   single         format = single (one value per line); default: columns
//   dt=<s>         single's sampling interval, > 0 (default 0.01)
//   column=<n>     the acceleration column, 2–9 (default 2)
//   units=<u>      g, m/s2, cm/s2 or none (default g)
//   scale=<x>      a finite factor (default 1)
//   target_pga_g=<x>  > 0, instead of scale

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include "fuzz_support.hpp"
#include "read_record.hpp"

namespace {

double number(const std::string& text, double fallback) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == '\0' && std::isfinite(v) ? v : fallback;
}

poundsim::io::RecordOptions options_from(std::string_view data) {
  poundsim::io::RecordOptions o;
  o.format = poundsim::io::RecordFormat::columns;
  o.units = "g";
  constexpr std::string_view tag = "# fuzz:";
  if (!data.starts_with(tag)) return o;
  std::istringstream words(std::string(data.substr(tag.size(), data.find('\n') - tag.size())));
  for (std::string word; words >> word;) {
    const std::size_t eq = word.find('=');
    const std::string key = word.substr(0, eq);
    const std::string value = eq == std::string::npos ? std::string() : word.substr(eq + 1);
    if (key == "single") {
      o.format = poundsim::io::RecordFormat::single;
      if (!(o.dt > 0)) o.dt = 0.01;
    } else if (key == "dt") {
      if (const double dt = number(value, 0.0); dt > 0) o.dt = dt;
    } else if (key == "column") {
      const double c = number(value, 2.0);
      if (c >= 2 && c <= 9) o.column = static_cast<int>(c);
    } else if (key == "units") {
      if (value == "g" || value == "m/s2" || value == "cm/s2") o.units = value;
      if (value == "none") o.units.clear();
    } else if (key == "scale") {
      o.scale = number(value, 1.0);
    } else if (key == "target_pga_g") {
      if (const double t = number(value, 0.0); t > 0) o.target_pga_g = t;
    }
  }
  if (o.format != poundsim::io::RecordFormat::single) o.dt = 0.0;  // a model file allows dt only there
  return o;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const poundsim::io::RecordOptions options = options_from(text);
  poundsim::fuzz::expect_only_input_errors(
      [&] { (void)poundsim::fuzz::read_record(text, "fuzz.txt", options); });
  return 0;
}
