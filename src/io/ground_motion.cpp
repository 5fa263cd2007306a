#include "poundsim/io/ground_motion.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "poundsim/error.hpp"

namespace poundsim::io {

namespace {

/// The file as lines (CR stripped), with 1-based numbers in messages.
struct Lines {
  std::filesystem::path file;
  std::vector<std::string> text;

  [[noreturn]] void fail(std::size_t line, const std::string& message) const {
    if (line == 0) throw InputError(fmt::format("{}: {}", file.string(), message));
    throw InputError(fmt::format("{}:{}: {}", file.string(), line, message));
  }
};

Lines read_lines(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the record file", file.string()));
  Lines lines{file, {}};
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.text.push_back(std::move(line));
  }
  if (in.bad()) throw InputError(fmt::format("{}: read error", file.string()));
  return lines;
}

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

/// Parses a real number token; Fortran D exponents accepted. False if the token is not a
/// complete number.
bool parse_number(std::string token, double& value) {
  for (char& c : token) {
    if (c == 'D' || c == 'd') c = 'E';
  }
  if (!token.empty() && token.front() == '+') token.erase(0, 1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc{} && end == token.data() + token.size();
}

std::vector<std::string> split(const std::string& line, const std::string& separators) {
  std::vector<std::string> tokens;
  std::string current;
  for (const char c : line) {
    if (separators.find(c) != std::string::npos) {
      if (!current.empty()) tokens.push_back(current);
      current.clear();
    } else {
      current.push_back(c);
    }
  }
  if (!current.empty()) tokens.push_back(current);
  return tokens;
}

/// Reads `count` numbers from lines [first, end): whitespace-separated tokens, NPTS
/// authoritative. Fails on text, NaN, too few, and numbers left over (`stop_at` marks a line
/// where another section starts, e.g. COSMOS "End-of-data").
std::vector<double> read_values(const Lines& lines, std::size_t first, std::size_t count,
                                const std::string& what, const std::string& stop_at = {}) {
  std::vector<double> values;
  values.reserve(count);
  std::size_t line = first;
  for (; line < lines.text.size(); ++line) {
    if (!stop_at.empty() && lines.text[line].find(stop_at) != std::string::npos) break;
    for (const std::string& token : split(lines.text[line], " \t")) {
      double v = 0;
      if (!parse_number(token, v)) {
        lines.fail(line + 1, fmt::format("'{}' is not a number (reading the {} values)", token, what));
      }
      if (!std::isfinite(v)) lines.fail(line + 1, fmt::format("{} is not a finite value", token));
      if (values.size() == count) {
        lines.fail(line + 1, fmt::format("more values than the {} the header announces", count));
      }
      values.push_back(v);
    }
  }
  if (values.size() < count) {
    lines.fail(std::min(line, lines.text.size()),
               fmt::format("truncated: {} values where the header announces {}", values.size(), count));
  }
  return values;
}

double pga(const std::vector<double>& a) {
  double p = 0;
  for (const double x : a) p = std::max(p, std::abs(x));
  return p;
}

std::string normalise_units(const std::string& text) {
  const std::string u = upper(text);
  if (u == "G") return "g";
  if (u == "M/S2" || u == "M/S/S" || u == "M/SEC2" || u == "M/S^2") return "m/s2";
  if (u == "CM/S2" || u == "CM/S/S" || u == "CM/SEC2" || u == "CM/SEC/SEC" || u == "GAL" || u == "CM/S^2") return "cm/s2";
  return {};
}

GroundMotionRecord read_at2(const Lines& lines) {
  if (lines.text.size() < 5) lines.fail(lines.text.size(), "an AT2 file has four header lines before the data");
  GroundMotionRecord r;
  r.format = "at2";
  r.description = lines.text[1];
  const std::string units_line = upper(lines.text[2]);
  if (std::regex_search(units_line, std::regex(R"(UNITS OF G\b|\(G\)|IN G\b)"))) {
    r.file_units = "g";
  } else if (std::regex_search(units_line, std::regex(R"(CM/S(EC)?(/S(EC)?|2|\^2|\*\*2))"))) {
    r.file_units = "cm/s2";
  } else if (std::regex_search(units_line, std::regex(R"(\bM/S(EC)?(/S(EC)?|2|\^2|\*\*2))"))) {
    r.file_units = "m/s2";
  }
  if (units_line.find("VELOCITY") != std::string::npos || units_line.find("DISPLACEMENT") != std::string::npos) {
    lines.fail(3, "this is a velocity or displacement record (.VT2/.DT2), not an acceleration");
  }
  // NPTS and DT: labelled values anywhere on the line; else the first two numbers before "SEC"
  // (filter information may follow), ordered by their labels, or integer first.
  const std::string header = upper(lines.text[3]);
  const std::string cut = header.substr(0, header.find("SEC") == std::string::npos ? header.size() : header.find("SEC") + 3);
  std::smatch m;
  double npts = -1, dt = -1;
  const std::regex npts_value(R"(NPTS\s*=?\s*(\d+))"), dt_value(R"(\bDT\s*=?\s*([0-9]*\.?[0-9]+(?:[EDed][-+]?\d+)?))");
  if (std::regex_search(header, m, npts_value)) npts = std::stod(m[1]);
  if (std::regex_search(header, m, dt_value)) parse_number(m[1], dt);
  if (npts < 0 || dt < 0) {
    std::vector<double> numbers;
    for (const std::string& token : split(cut, " \t,=")) {
      double v = 0;
      if (parse_number(token, v)) numbers.push_back(v);
    }
    if (numbers.size() >= 2) {
      const auto at_npts = cut.find("NPTS"), at_dt = cut.find("DT");
      const bool dt_first = at_dt != std::string::npos && at_npts != std::string::npos && at_dt < at_npts;
      const bool unlabelled = at_npts == std::string::npos && at_dt == std::string::npos;
      const bool integer_first = numbers[0] == std::floor(numbers[0]) && numbers[0] >= 2;
      const bool npts_first = unlabelled ? integer_first : !dt_first;
      if (npts < 0) npts = npts_first ? numbers[0] : numbers[1];
      if (dt < 0) dt = npts_first ? numbers[1] : numbers[0];
    }
  }
  if (npts < 0) lines.fail(4, fmt::format("no NPTS in the header line '{}'", lines.text[3]));
  if (!(dt > 0)) lines.fail(4, fmt::format("no DT (> 0) in the header line '{}'", lines.text[3]));
  if (npts != std::floor(npts) || npts < 2) lines.fail(4, fmt::format("NPTS = {} must be an integer ≥ 2", npts));
  r.points = static_cast<int>(npts);
  r.dt = dt;
  r.excitation.acceleration = read_values(lines, 4, static_cast<std::size_t>(npts), "NPTS");
  for (int i = 0; i < r.points; ++i) r.excitation.time.push_back(i * dt);
  return r;
}

GroundMotionRecord read_cosmos(const Lines& lines) {
  GroundMotionRecord r;
  r.format = "cosmos";
  std::smatch m;
  const auto find = [&](std::size_t line, const std::regex& pattern, const std::string& what) {
    if (line >= lines.text.size() || !std::regex_search(lines.text[line], m, pattern)) {
      lines.fail(std::min(line + 1, lines.text.size()), fmt::format("expected {}", what));
    }
  };
  const std::string first = lines.text.empty() ? std::string() : lines.text[0];
  if (first.rfind("Corrected acceleration", 0) != 0) {
    lines.fail(1, first.find("acceleration") != std::string::npos
                      ? "not corrected acceleration (COSMOS V2): V0/V1 records are not processed"
                      : "a COSMOS V2 file starts with 'Corrected acceleration'");
  }
  find(0, std::regex(R"(with\s+(\d+)\s+text lines)"), "'with N text lines' in the first line");
  std::size_t line = std::stoul(m[1]);
  if (lines.text.size() > 1) r.description = lines.text[1];
  find(line, std::regex(R"(^\s*(\d+)\s+Integer-header values follow on\s+(\d+)\s+lines)"), "the integer-header line");
  line += 1 + std::stoul(m[2]);
  find(line, std::regex(R"(^\s*(\d+)\s+Real-header values follow on\s+(\d+)\s+lines)"), "the real-header line");
  const std::size_t real_count = std::stoul(m[1]), real_lines = std::stoul(m[2]);
  std::vector<double> reals;
  for (std::size_t k = line + 1; k <= line + real_lines && k < lines.text.size(); ++k) {
    for (const std::string& token : split(lines.text[k], " \t")) {
      double v = 0;
      if (!parse_number(token, v)) lines.fail(k + 1, fmt::format("'{}' is not a number (real header)", token));
      reals.push_back(v);
    }
  }
  if (reals.size() < std::min<std::size_t>(real_count, 62)) lines.fail(line + 1, "real header too short: no sampling interval (#62)");
  line += 1 + real_lines;
  find(line, std::regex(R"(^\s*(\d+)\s+Comment line)"), "the comment-count line");
  line += 1 + std::stoul(m[1]);
  find(line, std::regex(R"(^\s*(\d+)\s+acceleration pts.*units=\s*([^(,\s]+))"), "the data header '<n> acceleration pts, …, units=…'");
  const std::size_t npts = std::stoul(m[1]);
  r.file_units = normalise_units(m[2]);
  if (r.file_units.empty()) lines.fail(line + 1, fmt::format("unknown units '{}'", m[2].str()));
  const double dt_ms = reals[61];
  if (!(dt_ms > 0) || dt_ms == -999.0) lines.fail(line + 1, "no sampling interval: real header #62 is unknown (-999)");
  r.dt = dt_ms / 1000.0;
  r.points = static_cast<int>(npts);
  if (npts < 2) lines.fail(line + 1, "fewer than two points");
  r.excitation.acceleration = read_values(lines, line + 1, npts, "acceleration", "End-of-data");
  for (std::size_t i = 0; i < npts; ++i) r.excitation.time.push_back(static_cast<double>(i) * r.dt);
  return r;
}

GroundMotionRecord read_columns(const Lines& lines, const RecordOptions& o, bool single) {
  GroundMotionRecord r;
  r.format = single ? "single" : "columns";
  bool data_started = false;
  for (std::size_t i = 0; i < lines.text.size(); ++i) {
    const std::string& text = lines.text[i];
    const auto start = text.find_first_not_of(" \t");
    if (start == std::string::npos || text[start] == '#' || text[start] == '%') continue;
    const std::vector<std::string> tokens = split(text, " \t,;");
    std::vector<double> values;
    bool numeric = true;
    for (const std::string& t : tokens) {
      double v = 0;
      if (!parse_number(t, v)) {
        numeric = false;
        break;
      }
      values.push_back(v);
    }
    if (!numeric) {
      if (!data_started) {
        if (r.description.empty()) r.description = text;
        continue;  // a header line
      }
      lines.fail(i + 1, fmt::format("text among the numbers: '{}'", text));
    }
    data_started = true;
    for (const double v : values) {
      if (!std::isfinite(v)) lines.fail(i + 1, "NaN or infinite value");
    }
    if (single) {
      if (values.size() != 1) lines.fail(i + 1, fmt::format("expected one value per line, found {}", values.size()));
      r.excitation.time.push_back(static_cast<double>(r.excitation.acceleration.size()) * o.dt);
      r.excitation.acceleration.push_back(values[0]);
      continue;
    }
    if (static_cast<int>(values.size()) < std::max(2, o.column)) {
      lines.fail(i + 1, fmt::format("expected at least {} columns (time and acceleration), found {}",
                                    std::max(2, o.column), values.size()));
    }
    const double t = values[0];
    if (r.excitation.time.empty() && t < 0) lines.fail(i + 1, fmt::format("the first time {} s is negative", t));
    if (!r.excitation.time.empty() && !(t > r.excitation.time.back())) {
      lines.fail(i + 1, fmt::format("time {} s does not increase (previous {} s)", t, r.excitation.time.back()));
    }
    r.excitation.time.push_back(t);
    r.excitation.acceleration.push_back(values[static_cast<std::size_t>(o.column - 1)]);
  }
  r.points = static_cast<int>(r.excitation.time.size());
  if (r.points < 2) lines.fail(0, fmt::format("a record needs at least two samples, found {}", r.points));
  r.dt = single ? o.dt : 0.0;
  if (!single) {
    // Uniform sampling (to a millisecond of the step) is reported as dt; otherwise 0.
    const double step = r.excitation.time[1] - r.excitation.time[0];
    bool uniform = true;
    for (std::size_t k = 1; k < r.excitation.time.size() && uniform; ++k) {
      uniform = std::abs(r.excitation.time[k] - r.excitation.time[k - 1] - step) <= 1e-3 * step;
    }
    r.dt = uniform ? step : 0.0;
  }
  return r;
}

RecordFormat detect(const std::filesystem::path& file, const Lines& lines) {
  const std::string ext = upper(file.extension().string());
  const std::string first = lines.text.empty() ? std::string() : lines.text[0];
  if (ext == ".AT2" || upper(first).find("PEER") != std::string::npos) return RecordFormat::at2;
  const bool cosmos_banner = std::regex_search(first, std::regex(R"(^(Corrected|Uncorrected|Raw) acceleration)"));
  if (ext == ".V2" || ext == ".V2C" || cosmos_banner) return RecordFormat::cosmos;
  return RecordFormat::columns;
}

}  // namespace

double units_to_si(const std::string& units, double gravity) {
  if (units == "g") return gravity;
  if (units == "m/s2") return 1.0;
  if (units == "cm/s2") return 0.01;
  throw InputError(fmt::format("units \"{}\" must be \"g\", \"m/s2\" or \"cm/s2\"", units));
}

GroundMotionRecord read_ground_motion(const std::filesystem::path& file, const RecordOptions& o) {
  const Lines lines = read_lines(file);
  RecordFormat format = o.format == RecordFormat::automatic ? detect(file, lines) : o.format;
  if (format == RecordFormat::single && !(o.dt > 0)) {
    throw InputError(fmt::format("{}: a one-column record needs its dt", file.string()));
  }
  GroundMotionRecord r = format == RecordFormat::at2      ? read_at2(lines)
                         : format == RecordFormat::cosmos ? read_cosmos(lines)
                                                          : read_columns(lines, o, format == RecordFormat::single);
  if (r.file_units.empty()) {
    if (o.units.empty()) {
      throw InputError(fmt::format("{}: the units of the accelerations are not in the file: declare them "
                                   "(units = \"g\", \"m/s2\" or \"cm/s2\")",
                                   file.string()));
    }
    r.file_units = o.units;
  } else if (!o.units.empty() && o.units != r.file_units) {
    throw InputError(fmt::format("{}: the file says its accelerations are in {}, the input says {}",
                                 file.string(), r.file_units, o.units));
  }
  const double to_si = units_to_si(r.file_units, o.gravity);
  r.pga_file_g = pga(r.excitation.acceleration) * to_si / o.gravity;
  if (o.target_pga_g) {
    if (!(r.pga_file_g > 0)) throw InputError(fmt::format("{}: the record is all zeros: no PGA to scale", file.string()));
    r.scale = *o.target_pga_g / r.pga_file_g;
  } else {
    r.scale = o.scale;
  }
  for (double& a : r.excitation.acceleration) a *= r.scale * to_si;
  r.pga_g = pga(r.excitation.acceleration) / o.gravity;
  r.duration = r.excitation.time.back();
  r.excitation.source = file.string();
  return r;
}

}  // namespace poundsim::io
