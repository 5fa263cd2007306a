#include "poundsim/io/record_file.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "poundsim/error.hpp"

namespace poundsim::io {

namespace {
/// Parses the next number of `line` from `pos`, skipping blanks and one comma before it.
bool next_number(const std::string& line, std::size_t& pos, double& value) {
  while (pos < line.size() && (line[pos] == ' ' || line[pos] == '\t' || line[pos] == '\r')) ++pos;
  if (pos < line.size() && line[pos] == ',') ++pos;
  while (pos < line.size() && (line[pos] == ' ' || line[pos] == '\t')) ++pos;
  if (pos < line.size() && line[pos] == '+') ++pos;  // from_chars rejects a leading '+'
  const char* begin = line.data() + pos;
  const auto [end, ec] = std::from_chars(begin, line.data() + line.size(), value);
  if (ec != std::errc{}) return false;
  pos += static_cast<std::size_t>(end - begin);
  return true;
}
}  // namespace

RecordExcitation read_two_column_record(const std::filesystem::path& file, double to_si) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open the record file", file.string()));
  RecordExcitation record;
  record.source = file.string();
  std::string line;
  int number = 0;
  const auto fail = [&](const std::string& what) {
    throw InputError(fmt::format("{}:{}: {}", file.string(), number, what));
  };
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::size_t pos = 0;
    double t = 0, a = 0;
    if (!next_number(line, pos, t) || !next_number(line, pos, a)) {
      fail(fmt::format("expected two numbers (time, acceleration), got '{}'", line));
    }
    if (line.find_first_not_of(" \t\r", pos) != std::string::npos) {
      fail(fmt::format("unexpected text after the two numbers: '{}'", line));
    }
    if (!std::isfinite(t) || !std::isfinite(a)) fail("time and acceleration must be finite");
    if (record.time.empty() && t < 0) fail(fmt::format("the first time {} s is negative", t));
    if (!record.time.empty() && !(t > record.time.back())) {
      fail(fmt::format("time {} s does not increase (previous {} s)", t, record.time.back()));
    }
    record.time.push_back(t);
    record.acceleration.push_back(a * to_si);
  }
  if (in.bad()) throw InputError(fmt::format("{}: read error", file.string()));
  if (record.time.size() < 2) {
    throw InputError(fmt::format("{}: a record needs at least two samples, found {}",
                                 file.string(), record.time.size()));
  }
  return record;
}

}  // namespace poundsim::io
