#include "poundsim/io/ground_motion.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <mutex>
#include <optional>
#include <regex>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "poundsim/error.hpp"

namespace poundsim::io {

namespace {

namespace fs = std::filesystem;

/// The largest record file read. The longest strong-motion records (an hour at 1000 samples/s) are
/// a few tens of MB; anything larger is not a record, and reading it whole would only exhaust
/// memory (a device such as /dev/zero never ends).
constexpr std::size_t kMaxRecordBytes = std::size_t{64} << 20;

/// Text from a file as shown in a message: control bytes escaped, and cut after 40 bytes with the
/// length given, so that a message never carries a megabyte line or raw binary.
std::string shown(std::string_view text) {
  constexpr std::size_t kShown = 40;
  std::size_t n = std::min(text.size(), kShown);
  while (n < text.size() && n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;  // UTF-8
  std::string out;
  for (const char c : text.substr(0, n)) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7F) {
      out += fmt::format("\\x{:02x}", u);
    } else {
      out.push_back(c);
    }
  }
  if (n < text.size()) out += fmt::format("… ({} characters)", text.size());
  return out;
}

/// The file's content and where its lines start; lines are views without "\n" or a final "\r",
/// numbered from 1 in messages. Four bytes per line, whatever the file holds.
struct Lines {
  fs::path file;
  std::string content;
  std::vector<std::uint32_t> starts;

  std::size_t size() const { return starts.size(); }

  std::string_view operator[](std::size_t k) const {
    const std::size_t begin = starts[k];
    std::size_t end = k + 1 < starts.size() ? starts[k + 1] - 1 : content.size();
    if (k + 1 == starts.size() && end > begin && content[end - 1] == '\n') --end;
    if (end > begin && content[end - 1] == '\r') --end;
    return std::string_view(content).substr(begin, end - begin);
  }

  /// At most how many values lines [first, end) can hold: a value takes a character and a
  /// separator (a line's end counts as one), so that no count read from a header can make us
  /// allocate more than the file justifies.
  std::size_t capacity_from(std::size_t first) const { return bytes_from(first) / 2; }
  std::size_t bytes_from(std::size_t first) const {
    if (first >= starts.size()) return 0;
    const std::size_t bytes = content.size() - starts[first];
    return content.empty() || content.back() == '\n' ? bytes : bytes + 1;
  }

  [[noreturn]] void fail(std::size_t line, const std::string& message) const {
    if (line == 0) throw InputError(fmt::format("{}: {}", file.string(), message));
    throw InputError(fmt::format("{}:{}: {}", file.string(), line, message));
  }
};

[[noreturn]] void fail_file(const fs::path& file, const std::string& message) {
  throw InputError(fmt::format("{}: {}", file.string(), message));
}

std::string too_large() {
  return fmt::format("larger than {} MiB: not a ground-motion record", kMaxRecordBytes >> 20);
}

/// The content split into lines; `file` names it in messages.
Lines split_lines(std::string content, const fs::path& file) {
  if (content.size() > kMaxRecordBytes) fail_file(file, too_large());
  Lines lines{file, std::move(content), {}};
  for (std::size_t begin = 0; begin < lines.content.size();) {
    lines.starts.push_back(static_cast<std::uint32_t>(begin));  // < kMaxRecordBytes < 2³²
    const std::size_t newline = lines.content.find('\n', begin);
    begin = newline == std::string::npos ? lines.content.size() : newline + 1;
  }
  if (lines.size() == 0) fail_file(file, "the file is empty");
  return lines;
}

std::string read_bytes(const fs::path& file) {
  const auto fail = [&](const std::string& message) { fail_file(file, message); };
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) fail("cannot open the record file: " + ec.message());
  if (!fs::exists(status)) fail("cannot open the record file");
  if (fs::is_directory(status)) fail("a directory, not a record file");
  if (fs::is_regular_file(status)) {
    const std::uintmax_t size = fs::file_size(file, ec);
    if (!ec && size > kMaxRecordBytes) {
      fail(fmt::format("{} bytes, larger than {} MiB: not a ground-motion record", size, kMaxRecordBytes >> 20));
    }
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) fail("cannot open the record file");
  // Read in chunks up to the bound, for the files whose size is not known in advance.
  std::string content;
  std::vector<char> chunk(std::size_t{1} << 16);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    content.append(chunk.data(), static_cast<std::size_t>(in.gcount()));
    if (content.size() > kMaxRecordBytes) fail(too_large());
  }
  if (in.bad()) fail("read error");
  return content;
}

std::string upper(std::string_view text) {
  std::string s(text);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

/// Parses a real number token; Fortran D exponents accepted. False if the token is not a
/// complete number. A number beyond the range of a double (1e999, 1e-999) is a number, +inf,
/// so that the finiteness checks reject it with the token in the message.
bool parse_number(std::string_view text, double& value) {
  std::string token(text);
  for (char& c : token) {
    if (c == 'D' || c == 'd') c = 'E';
  }
  if (!token.empty() && token.front() == '+') token.erase(0, 1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (end != token.data() + token.size()) return false;
  if (ec == std::errc::result_out_of_range) {
    value = std::numeric_limits<double>::infinity();
    return true;
  }
  return ec == std::errc{};
}

/// The message for a token parse_number took as a non-finite value: NaN and infinity are spelt
/// with an 'n' (nan, inf, infinity), a number out of range never is.
std::string not_finite(std::string_view token) {
  if (token.find_first_of("nN") != std::string_view::npos) return fmt::format("{} is not a finite value", shown(token));
  return fmt::format("{} is beyond the range of a double", shown(token));
}

/// A count written as digits; nullopt when `token` is not one, `UINT64_MAX` when it is too large
/// for 64 bits (then larger than any bound it is checked against).
std::optional<std::uint64_t> parse_count(std::string_view token) {
  if (token.empty() || !std::all_of(token.begin(), token.end(), is_digit)) return std::nullopt;
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec == std::errc::result_out_of_range) return std::numeric_limits<std::uint64_t>::max();
  return value;
}

std::vector<std::string_view> split(std::string_view line, std::string_view separators) {
  std::vector<std::string_view> tokens;
  std::size_t begin = 0;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i == line.size() || separators.find(line[i]) != std::string_view::npos) {
      if (i > begin) tokens.push_back(line.substr(begin, i - begin));
      begin = i + 1;
    }
  }
  return tokens;
}

std::vector<std::string_view> words(std::string_view line) { return split(line, " \t\r\v\f"); }

/// Reads `count` numbers from lines [first, end): whitespace-separated tokens, the count
/// authoritative. Fails on text, NaN, too few, and numbers left over (`stop_at` marks a line
/// where another section starts, e.g. COSMOS "End-of-data"). `count` has been checked against
/// `capacity_from(first)` by the caller, so the reservation is bounded by the file.
std::vector<double> read_values(const Lines& lines, std::size_t first, std::size_t count,
                                const std::string& what, std::string_view stop_at = {}) {
  std::vector<double> values;
  values.reserve(count);
  std::size_t line = first;
  for (; line < lines.size(); ++line) {
    if (!stop_at.empty() && lines[line].find(stop_at) != std::string_view::npos) break;
    for (const std::string_view token : words(lines[line])) {
      double v = 0;
      if (!parse_number(token, v)) {
        lines.fail(line + 1, fmt::format("'{}' is not a number (reading the {} values)", shown(token), what));
      }
      if (!std::isfinite(v)) lines.fail(line + 1, not_finite(token));
      if (values.size() == count) {
        lines.fail(line + 1, fmt::format("more values than the {} the header announces", count));
      }
      values.push_back(v);
    }
  }
  if (values.size() < count) {
    lines.fail(std::min(line, lines.size()),
               fmt::format("truncated: {} values where the header announces {}", values.size(), count));
  }
  return values;
}

/// t_i = i·dt for i < points; dt > 0 and finite, and the last time is checked finite first.
std::vector<double> uniform_times(std::size_t points, double dt) {
  std::vector<double> time(points);
  for (std::size_t i = 0; i < points; ++i) time[i] = static_cast<double>(i) * dt;
  return time;
}

double pga(const std::vector<double>& a) {
  double p = 0;
  for (const double x : a) p = std::max(p, std::abs(x));
  return p;
}

std::string normalise_units(std::string_view text) {
  const std::string u = upper(text);
  if (u == "G") return "g";
  if (u == "M/S2" || u == "M/S/S" || u == "M/SEC2" || u == "M/S^2") return "m/s2";
  if (u == "CM/S2" || u == "CM/S/S" || u == "CM/SEC2" || u == "CM/SEC/SEC" || u == "GAL" || u == "CM/S^2") return "cm/s2";
  return {};
}

/// The digits after the first `NPTS` that blanks and an optional '=' separate from digits
/// (as the pattern NPTS\s*=?\s*(\d+)); empty if none. Scanned by hand: std::regex recurses per
/// character and overflows its stack on a long line.
std::string_view labelled_npts(std::string_view header) {
  for (std::size_t at = header.find("NPTS"); at != std::string_view::npos; at = header.find("NPTS", at + 1)) {
    std::size_t i = at + 4;
    while (i < header.size() && is_blank(header[i])) ++i;
    if (i < header.size() && header[i] == '=') ++i;
    while (i < header.size() && is_blank(header[i])) ++i;
    std::size_t end = i;
    while (end < header.size() && is_digit(header[end])) ++end;
    if (end > i) return header.substr(i, end - i);
  }
  return {};
}

/// The number after the first word `DT` that blanks and an optional '=' separate from a number
/// [0-9]*\.?[0-9]+ with an optional exponent [ED][-+]?[0-9]+ (header upper-cased); empty if none.
std::string_view labelled_dt(std::string_view header) {
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; };
  for (std::size_t at = header.find("DT"); at != std::string_view::npos; at = header.find("DT", at + 1)) {
    if (at > 0 && word(header[at - 1])) continue;
    std::size_t i = at + 2;
    while (i < header.size() && is_blank(header[i])) ++i;
    if (i < header.size() && header[i] == '=') ++i;
    while (i < header.size() && is_blank(header[i])) ++i;
    std::size_t end = i;
    while (end < header.size() && is_digit(header[end])) ++end;
    if (end + 1 < header.size() && header[end] == '.' && is_digit(header[end + 1])) {
      ++end;
      while (end < header.size() && is_digit(header[end])) ++end;
    }
    if (end == i) continue;
    if (end < header.size() && (header[end] == 'E' || header[end] == 'D')) {
      std::size_t e = end + 1;
      if (e < header.size() && (header[e] == '+' || header[e] == '-')) ++e;
      const std::size_t digits = e;
      while (e < header.size() && is_digit(header[e])) ++e;
      if (e > digits) end = e;
    }
    return header.substr(i, end - i);
  }
  return {};
}

/// A header count on line `line` (0-based) that must not exceed `limit`; `why` says what the
/// limit is. The value is returned only when it fits: nothing is allocated from a count the file
/// cannot hold.
std::size_t bounded_count(const Lines& lines, std::size_t line, std::string_view token, const std::string& what,
                          std::size_t limit, const std::string& why) {
  const std::optional<std::uint64_t> n = parse_count(token);
  if (!n) lines.fail(line + 1, fmt::format("'{}' is not a count of {}", shown(token), what));
  if (*n > limit) lines.fail(line + 1, fmt::format("{} {} announced: {}", shown(token), what, why));
  return static_cast<std::size_t>(*n);
}

/// `units_line` is set to the line that gives the units (1-based).
GroundMotionRecord read_at2(const Lines& lines, std::size_t& units_line) {
  if (lines.size() < 5) lines.fail(lines.size(), "an AT2 file has four header lines before the data");
  GroundMotionRecord r;
  r.format = "at2";
  r.description = std::string(lines[1]);
  // Patterns without repetition only: std::regex recurses per repeated character. Built once
  // (matching a const regex from several threads is safe).
  static const std::regex in_g(R"(UNITS OF G\b|\(G\)|IN G\b)"), in_cm(R"(CM/S(EC)?(/S(EC)?|2|\^2|\*\*2))"),
      in_m(R"(\bM/S(EC)?(/S(EC)?|2|\^2|\*\*2))");
  const std::string quantity = upper(lines[2]);
  if (std::regex_search(quantity, in_g)) {
    r.file_units = "g";
  } else if (std::regex_search(quantity, in_cm)) {
    r.file_units = "cm/s2";
  } else if (std::regex_search(quantity, in_m)) {
    r.file_units = "m/s2";
  }
  units_line = 3;
  if (quantity.find("VELOCITY") != std::string::npos || quantity.find("DISPLACEMENT") != std::string::npos) {
    lines.fail(3, "this is a velocity or displacement record (.VT2/.DT2), not an acceleration");
  }
  // NPTS and DT: labelled values anywhere on the line; else the first two numbers before "SEC"
  // (filter information may follow), ordered by their labels, or integer first.
  const std::string header = upper(lines[3]);
  const std::string_view cut =
      std::string_view(header).substr(0, header.find("SEC") == std::string::npos ? header.size() : header.find("SEC") + 3);
  std::string_view npts_token = labelled_npts(header), dt_token = labelled_dt(header);
  if (npts_token.empty() || dt_token.empty()) {
    std::vector<std::pair<double, std::string_view>> numbers;
    for (const std::string_view token : split(cut, " \t,=")) {
      double v = 0;
      if (parse_number(token, v)) numbers.emplace_back(v, token);
    }
    if (numbers.size() >= 2) {
      const auto at_npts = cut.find("NPTS"), at_dt = cut.find("DT");
      const bool dt_first = at_dt != std::string::npos && at_npts != std::string::npos && at_dt < at_npts;
      const bool unlabelled = at_npts == std::string::npos && at_dt == std::string::npos;
      const bool integer_first = numbers[0].first == std::floor(numbers[0].first) && numbers[0].first >= 2;
      const bool npts_first = unlabelled ? integer_first : !dt_first;
      if (npts_token.empty()) npts_token = numbers[npts_first ? 0 : 1].second;
      if (dt_token.empty()) dt_token = numbers[npts_first ? 1 : 0].second;
    }
  }
  if (npts_token.empty()) lines.fail(4, fmt::format("no NPTS in the header line '{}'", shown(lines[3])));
  if (dt_token.empty()) lines.fail(4, fmt::format("no DT (> 0) in the header line '{}'", shown(lines[3])));
  double npts = 0, dt = 0;
  parse_number(npts_token, npts);
  parse_number(dt_token, dt);
  if (!(std::isfinite(dt) && dt > 0)) lines.fail(4, fmt::format("DT = {} s must be a finite number > 0", shown(dt_token)));
  const std::size_t capacity = lines.capacity_from(4);
  const std::size_t limit = std::min<std::size_t>(capacity, INT_MAX);
  if (!(npts <= static_cast<double>(limit))) {  // NaN too
    lines.fail(4, fmt::format("NPTS = {} announced: the {} bytes after the header hold at most {} values",
                              shown(npts_token), lines.bytes_from(4), capacity));
  }
  if (npts != std::floor(npts) || npts < 2) lines.fail(4, fmt::format("NPTS = {} must be an integer ≥ 2", shown(npts_token)));
  const auto points = static_cast<std::size_t>(npts);  // an integer in [2, INT_MAX]
  if (!std::isfinite(static_cast<double>(points - 1) * dt)) {
    lines.fail(4, fmt::format("the record's length (NPTS − 1) × DT = {} × {} s is not a finite number", points - 1,
                              shown(dt_token)));
  }
  r.points = static_cast<int>(points);
  r.dt = dt;
  r.excitation.acceleration = read_values(lines, 4, points, "NPTS");
  r.excitation.time = uniform_times(points, dt);
  return r;
}

[[noreturn]] void cosmos_expect(const Lines& lines, std::size_t line, const std::string& what) {
  lines.fail(std::min(line + 1, lines.size()), fmt::format("expected {}", what));
}

bool begins(std::string_view word, std::string_view prefix) { return word.rfind(prefix, 0) == 0; }

/// The words of line `line`, none past the end of the file.
std::vector<std::string_view> words_at(const Lines& lines, std::size_t line) {
  return line < lines.size() ? words(lines[line]) : std::vector<std::string_view>{};
}

/// The text lines the first line announces ("… with N text lines"): where the headers begin.
std::size_t cosmos_text_lines(const Lines& lines) {
  const std::vector<std::string_view> w = words(lines[0]);
  std::size_t k = 0;
  while (k + 3 < w.size() && !(w[k] == "with" && w[k + 2] == "text" && begins(w[k + 3], "lines"))) ++k;
  if (k + 3 >= w.size()) cosmos_expect(lines, 0, "'with N text lines' in the first line");
  const std::size_t line = bounded_count(lines, 0, w[k + 1], "text lines", lines.size() - 1,
                                         fmt::format("the file has {} lines", lines.size()));
  if (line == 0) lines.fail(1, "0 text lines announced: the first line is one");
  return line;
}

/// A header section at `line`: "<n> Integer-header values follow on <m> lines" (or Real-).
/// Calls `value(line, token)` for each of its values and checks their count; returns the line
/// after the section.
template <class Value>
std::size_t cosmos_header(const Lines& lines, std::size_t line, const std::string& name, std::string_view label,
                          const Value& value) {
  const std::vector<std::string_view> w = words_at(lines, line);
  if (w.size() < 7 || w[1] != label || w[2] != "values" || w[3] != "follow" || w[4] != "on" || !begins(w[6], "lines")) {
    cosmos_expect(lines, line, fmt::format("the {}-header line '<n> {} values follow on <m> lines'", name, label));
  }
  const std::size_t follow = lines.size() - line - 1;
  const std::size_t count_lines = bounded_count(lines, line, w[5], name + "-header lines", follow,
                                                fmt::format("{} lines follow", follow));
  const std::optional<std::uint64_t> count = parse_count(w[0]);
  if (!count) lines.fail(line + 1, fmt::format("'{}' is not a count of {}-header values", shown(w[0]), name));
  std::size_t held = 0;
  for (std::size_t k = line + 1; k <= line + count_lines; ++k) {
    for (const std::string_view token : words(lines[k])) value(k, token, ++held);
  }
  if (*count != held) {
    lines.fail(line + 1, fmt::format("{} {}-header values announced: lines {}–{} hold {}", shown(w[0]), name,
                                     line + 2, line + 1 + count_lines, held));
  }
  return line + 1 + count_lines;
}

/// Real header #62: the sampling interval in ms, found on line `line` as `token`.
struct CosmosInterval {
  double ms = 0;
  std::size_t line = 0;
  std::string_view token;
};

/// The comment lines ("<n> Comment line(s) follow", each starting with '|'); returns the line after.
std::size_t cosmos_comments(const Lines& lines, std::size_t line) {
  const std::vector<std::string_view> w = words_at(lines, line);
  if (w.size() < 2 || !begins(w[1], "Comment")) cosmos_expect(lines, line, "the comment-count line '<n> Comment line(s) follow'");
  const std::size_t follow = lines.size() - line - 1;
  const std::size_t comments =
      bounded_count(lines, line, w[0], "comment lines", follow, fmt::format("{} lines follow", follow));
  for (std::size_t k = 1; k <= comments; ++k) {
    if (!begins(lines[line + k], "|")) {
      lines.fail(line + k + 1, fmt::format("comment line {} of {} does not start with '|'", k, comments));
    }
  }
  return line + 1 + comments;
}

/// The data header's units ("units=cm/sec/sec"), normalised.
std::string cosmos_units(const Lines& lines, std::size_t line) {
  const std::string_view header = lines[line];
  const std::size_t at = header.find("units=");
  if (at == std::string_view::npos) lines.fail(line + 1, "the data header gives no units=");
  std::size_t begin = at + 6;
  while (begin < header.size() && is_blank(header[begin])) ++begin;
  std::size_t end = begin;
  while (end < header.size() && header[end] != '(' && header[end] != ',' && !is_blank(header[end])) ++end;
  const std::string_view units = header.substr(begin, end - begin);
  std::string normalised = normalise_units(units);
  if (normalised.empty()) lines.fail(line + 1, fmt::format("unknown units '{}'", shown(units)));
  return normalised;
}

/// The data section at `line`: its header, then the accelerations at the interval `dt`.
void cosmos_data(const Lines& lines, std::size_t line, const CosmosInterval& dt, GroundMotionRecord& r) {
  const std::vector<std::string_view> w = words_at(lines, line);
  if (w.size() < 3 || w[1] != "acceleration" || !begins(w[2], "pts")) {
    cosmos_expect(lines, line, "the data header '<n> acceleration pts, …, units=…'");
  }
  r.file_units = cosmos_units(lines, line);
  const std::size_t capacity = lines.capacity_from(line + 1);
  const std::size_t points =
      bounded_count(lines, line, w[0], "acceleration points", std::min<std::size_t>(capacity, INT_MAX),
                    fmt::format("the {} bytes after this line hold at most {}", lines.bytes_from(line + 1), capacity));
  if (points < 2) lines.fail(line + 1, "fewer than two points");
  if (!(std::isfinite(dt.ms) && dt.ms > 0)) {
    lines.fail(dt.line + 1, fmt::format("no sampling interval: real header #62 is {} ms, not a finite number > 0 "
                                        "(-999 means unknown)",
                                        shown(dt.token)));
  }
  r.dt = dt.ms / 1000.0;
  if (!std::isfinite(static_cast<double>(points - 1) * r.dt)) {
    lines.fail(dt.line + 1, fmt::format("the record's length ({} − 1) × {} ms is not a finite number", points,
                                        shown(dt.token)));
  }
  r.points = static_cast<int>(points);  // ≤ INT_MAX, checked above
  r.excitation.acceleration = read_values(lines, line + 1, points, "acceleration", "End-of-data");
  r.excitation.time = uniform_times(points, r.dt);
}

GroundMotionRecord read_cosmos(const Lines& lines, std::size_t& units_line) {
  GroundMotionRecord r;
  r.format = "cosmos";
  const std::string_view first = lines[0];
  if (first.rfind("Corrected acceleration", 0) != 0) {
    lines.fail(1, first.find("acceleration") != std::string::npos
                      ? "not corrected acceleration (COSMOS V2): V0/V1 records are not processed"
                      : "a COSMOS V2 file starts with 'Corrected acceleration'");
  }
  // Each section announces its own length; every count is checked against the lines that follow
  // before it is used, and each section's values are counted against its count.
  std::size_t line = cosmos_text_lines(lines);
  if (lines.size() > 1) r.description = std::string(lines[1]);
  line = cosmos_header(lines, line, "integer", "Integer-header", [&](std::size_t k, std::string_view token, std::size_t) {
    long long v = 0;
    const std::string_view digits = token.substr(token.front() == '+' ? 1 : 0);
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
    if (ec != std::errc{} || end != digits.data() + digits.size()) {
      lines.fail(k + 1, fmt::format("'{}' is not an integer (integer header)", shown(token)));
    }
  });
  CosmosInterval dt;
  std::size_t real_held = 0;
  const std::size_t real_line = line;
  line = cosmos_header(lines, line, "real", "Real-header", [&](std::size_t k, std::string_view token, std::size_t held) {
    double v = 0;
    if (!parse_number(token, v)) lines.fail(k + 1, fmt::format("'{}' is not a number (real header)", shown(token)));
    if (held == 62) dt = CosmosInterval{.ms = v, .line = k, .token = token};
    real_held = held;
  });
  if (real_held < 62) {
    lines.fail(real_line + 1, fmt::format("the real header has {} values: the sampling interval is value #62", real_held));
  }
  line = cosmos_comments(lines, line);
  units_line = line + 1;
  cosmos_data(lines, line, dt, r);
  return r;
}

GroundMotionRecord read_columns(const Lines& lines, const RecordOptions& o, bool single) {
  GroundMotionRecord r;
  r.format = single ? "single" : "columns";
  bool data_started = false;
  std::size_t last = 0;  // the last data line, 1-based
  const auto column = static_cast<std::size_t>(o.column);  // ≥ 2, checked by the caller
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string_view text = lines[i];
    const auto start = text.find_first_not_of(" \t");
    if (start == std::string::npos || text[start] == '#' || text[start] == '%') continue;
    const std::vector<std::string_view> tokens = split(text, " \t,;");
    std::vector<double> values;
    bool numeric = true;
    for (const std::string_view t : tokens) {
      double v = 0;
      if (!parse_number(t, v)) {
        numeric = false;
        break;
      }
      values.push_back(v);
    }
    if (!numeric) {
      if (!data_started) {
        if (r.description.empty()) r.description = std::string(text);
        continue;  // a header line
      }
      lines.fail(i + 1, fmt::format("text among the numbers: '{}'", shown(text)));
    }
    data_started = true;
    last = i + 1;
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (!std::isfinite(values[k])) lines.fail(i + 1, not_finite(tokens[k]));
    }
    if (single) {
      if (values.size() != 1) lines.fail(i + 1, fmt::format("expected one value per line, found {}", values.size()));
      const std::size_t k = r.excitation.acceleration.size();
      const double t = static_cast<double>(k) * o.dt;
      if (!std::isfinite(t)) lines.fail(i + 1, fmt::format("time {} × {} s is not a finite number", k, o.dt));
      r.excitation.time.push_back(t);
      r.excitation.acceleration.push_back(values[0]);
      continue;
    }
    if (values.size() < column) {
      lines.fail(i + 1, fmt::format("expected at least {} columns (time and acceleration), found {}", column,
                                    values.size()));
    }
    const double t = values[0];
    if (r.excitation.time.empty() && t < 0) lines.fail(i + 1, fmt::format("the first time {} s is negative", t));
    if (!r.excitation.time.empty() && !(t > r.excitation.time.back())) {
      lines.fail(i + 1, fmt::format("time {} s does not increase (previous {} s)", t, r.excitation.time.back()));
    }
    r.excitation.time.push_back(t);
    r.excitation.acceleration.push_back(values[column - 1]);
  }
  const std::size_t points = r.excitation.time.size();  // ≤ kMaxRecordBytes / 2 < INT_MAX
  if (points < 2) lines.fail(last > 0 ? last : lines.size(), fmt::format("a record needs at least two samples, found {}", points));
  r.points = static_cast<int>(points);
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

RecordFormat detect(const fs::path& file, const Lines& lines) {
  const std::string ext = upper(file.extension().string());
  const std::string_view first = lines[0];
  // PEER's banner opens its files; a column file may name PEER as its source further on.
  const std::size_t text = first.find_first_not_of(" \t");
  if (ext == ".AT2" || (text != std::string_view::npos && upper(first.substr(text)).rfind("PEER", 0) == 0)) {
    return RecordFormat::at2;
  }
  const bool cosmos_banner = first.rfind("Corrected acceleration", 0) == 0 ||
                             first.rfind("Uncorrected acceleration", 0) == 0 || first.rfind("Raw acceleration", 0) == 0;
  if (ext == ".V2" || ext == ".V2C" || cosmos_banner) return RecordFormat::cosmos;
  return RecordFormat::columns;
}

/// The options, checked before the file is read so that every message names the record.
void check(const RecordOptions& o, const fs::path& file) {
  const auto fail = [&](const std::string& message) { fail_file(file, message); };
  if (!o.units.empty() && std::ranges::find(record_unit_names, o.units) == record_unit_names.end()) {
    fail(fmt::format("units \"{}\" must be \"g\", \"m/s2\" or \"cm/s2\"", o.units));
  }
  if (!(std::isfinite(o.gravity) && o.gravity > 0)) fail(fmt::format("gravity {} m/s² must be > 0", o.gravity));
  if (!std::isfinite(o.scale)) fail(fmt::format("scale {} must be a finite number", o.scale));
  if (o.target_pga_g && !(std::isfinite(*o.target_pga_g) && *o.target_pga_g > 0)) {
    fail(fmt::format("target_pga_g {} must be a finite number > 0", *o.target_pga_g));
  }
  if (o.format == RecordFormat::single && !(std::isfinite(o.dt) && o.dt > 0)) {
    fail(fmt::format("a one-column record needs its dt (a finite number > 0), not {}", o.dt));
  }
  if (o.column < 2) fail(fmt::format("column {}: the acceleration column is 2 or more (column 1 is time)", o.column));
}

void scale_record(GroundMotionRecord& r, const RecordOptions& o, const std::filesystem::path& file);

}  // namespace

double units_to_si(const std::string& units, double gravity) {
  if (units == "g") return gravity;
  if (units == "m/s2") return 1.0;
  if (units == "cm/s2") return 0.01;
  throw InputError(fmt::format("units \"{}\" must be \"g\", \"m/s2\" or \"cm/s2\"", units));
}

namespace {

GroundMotionRecord parse_unscaled(std::string content, const fs::path& file, const RecordOptions& o);

/// The records read, unscaled, by file (its path, size and modification time) and the options
/// that read it: a study's points and an ensemble's records read each file once. Bounded, the
/// oldest dropped first; shared by the threads that read points.
class RecordCache {
 public:
  /// How much it holds at most.
  struct Options {
    std::size_t records = 256;
    std::size_t samples = std::size_t{32} << 20;  ///< 32 Mi samples: 512 MiB of times and accelerations
  };

  /// The record of `file` read with `o` (before scaling), read now when it is not held.
  GroundMotionRecord get(const fs::path& file, const RecordOptions& o) {
    const std::optional<std::string> key = key_of(file, o);
    if (!key) return parse_unscaled(read_bytes(file), file, o);
    {
      const std::lock_guard lock(mutex_);
      for (const auto& [held, record] : held_) {
        if (held == *key) return record;
      }
    }
    GroundMotionRecord record = parse_unscaled(read_bytes(file), file, o);
    const std::lock_guard lock(mutex_);
    // Another thread may have read it meanwhile: hold it once.
    if (std::ranges::any_of(held_, [&](const auto& entry) { return entry.first == *key; })) return record;
    held_.emplace_back(*key, record);
    samples_ += record.excitation.time.size();
    while (held_.size() > limits_.records || (samples_ > limits_.samples && held_.size() > 1)) {
      samples_ -= held_.front().second.excitation.time.size();
      held_.erase(held_.begin());
    }
    return record;
  }

 private:
  /// What identifies a reading; none when the file's size or time cannot be known (not cached).
  static std::optional<std::string> key_of(const fs::path& file, const RecordOptions& o) {
    std::error_code ec;
    const fs::path path = fs::absolute(file, ec).lexically_normal();
    if (ec || !fs::is_regular_file(path, ec)) return std::nullopt;
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) return std::nullopt;
    const auto written = fs::last_write_time(path, ec);
    if (ec) return std::nullopt;
    return fmt::format("{}\n{}\n{}\n{}\n{}\n{:a}\n{}\n{:a}", path.string(), size, written.time_since_epoch().count(),
                       static_cast<int>(o.format), o.units, o.dt, o.column, o.gravity);
  }

  Options limits_;
  std::mutex mutex_;
  std::vector<std::pair<std::string, GroundMotionRecord>> held_;
  std::size_t samples_ = 0;
};

RecordCache& record_cache() {
  static RecordCache cache;
  return cache;
}

}  // namespace

GroundMotionRecord read_ground_motion(const std::filesystem::path& file, const RecordOptions& options) {
  check(options, file);
  GroundMotionRecord r = record_cache().get(file, options);
  scale_record(r, options, file);
  return r;
}

GroundMotionRecord parse_ground_motion(std::string content, const std::filesystem::path& file, const RecordOptions& o) {
  GroundMotionRecord r = parse_unscaled(std::move(content), file, o);
  scale_record(r, o, file);
  return r;
}

namespace {

/// The record in `content`, in its file's units (scale_record converts and scales it).
GroundMotionRecord parse_unscaled(std::string content, const fs::path& file, const RecordOptions& o) {
  check(o, file);
  const Lines lines = split_lines(std::move(content), file);
  RecordFormat format = o.format == RecordFormat::automatic ? detect(file, lines) : o.format;
  std::size_t units_line = 0;  // column files carry no units
  GroundMotionRecord r = format == RecordFormat::at2      ? read_at2(lines, units_line)
                         : format == RecordFormat::cosmos ? read_cosmos(lines, units_line)
                                                          : read_columns(lines, o, format == RecordFormat::single);
  if (r.file_units.empty()) {
    if (o.units.empty()) {
      lines.fail(units_line, "the units of the accelerations are not in the file: declare them "
                               "(units = \"g\", \"m/s2\" or \"cm/s2\")");
    }
    r.file_units = o.units;
  } else if (!o.units.empty() && o.units != r.file_units) {
    lines.fail(units_line,
               fmt::format("the file says its accelerations are in {}, the input says {}", r.file_units, o.units));
  }
  return r;
}

/// Converts `r` (in r.file_units) to m/s², scaled by o.scale or to o.target_pga_g.
void scale_record(GroundMotionRecord& r, const RecordOptions& o, const std::filesystem::path& file) {
  const auto fail = [&](const std::string& message) { fail_file(file, message); };
  const double to_si = units_to_si(r.file_units, o.gravity);
  r.pga_file_g = pga(r.excitation.acceleration) * to_si / o.gravity;
  if (!std::isfinite(r.pga_file_g)) {
    fail(fmt::format("the peak {} {} overflows in m/s²", pga(r.excitation.acceleration), r.file_units));
  }
  if (o.target_pga_g) {
    if (!(r.pga_file_g > 0)) fail("the record is all zeros: no PGA to scale");
    r.scale = *o.target_pga_g / r.pga_file_g;
    if (!std::isfinite(r.scale)) {
      throw RecordScaleError(fmt::format("{}: the peak {} g is too small to scale to target_pga_g {}", file.string(),
                                         r.pga_file_g, *o.target_pga_g));
    }
  } else {
    r.scale = o.scale;
  }
  const std::string scaled_by =
      o.target_pga_g ? fmt::format("target_pga_g {}", *o.target_pga_g) : fmt::format("scale {}", r.scale);
  const auto overflow = [&](const std::string& message) {
    throw RecordScaleError(fmt::format("{}: {}", file.string(), message));
  };
  if (!std::isfinite(r.scale * to_si)) overflow(fmt::format("the {} overflows in m/s² per {}", scaled_by, r.file_units));
  for (std::size_t k = 0; k < r.excitation.acceleration.size(); ++k) {
    double& a = r.excitation.acceleration[k];
    const double file_value = a;
    a *= r.scale * to_si;
    if (!std::isfinite(a)) {
      overflow(
          fmt::format("the {} makes sample {} ({} {} in the file) overflow", scaled_by, k + 1, file_value, r.file_units));
    }
  }
  r.pga_g = pga(r.excitation.acceleration) / o.gravity;
  r.duration = r.excitation.time.back();
  r.excitation.source = file.string();
}

}  // namespace

GroundMotionRecord record_from_samples(std::vector<double> acceleration, const RecordOptions& o,
                                       const std::filesystem::path& name) {
  check(o, name);
  const auto fail = [&](const std::string& message) { fail_file(name, message); };
  if (!(std::isfinite(o.dt) && o.dt > 0)) fail(fmt::format("the samples need their dt (a finite number > 0), not {}", o.dt));
  if (o.units.empty()) fail("the units of the accelerations are not given: units = \"g\", \"m/s2\" or \"cm/s2\"");
  if (acceleration.size() < 2) fail(fmt::format("a record needs at least two samples, found {}", acceleration.size()));
  for (std::size_t k = 0; k < acceleration.size(); ++k) {
    if (!std::isfinite(acceleration[k])) fail(fmt::format("sample {} is {}, not a finite number", k + 1, acceleration[k]));
  }
  if (!std::isfinite(static_cast<double>(acceleration.size() - 1) * o.dt)) {
    fail(fmt::format("{} samples of {} s overflow the time", acceleration.size(), o.dt));
  }
  GroundMotionRecord r;
  r.format = "samples";
  r.file_units = o.units;
  r.points = static_cast<int>(std::min<std::size_t>(acceleration.size(), std::numeric_limits<int>::max()));
  if (static_cast<std::size_t>(r.points) != acceleration.size()) fail(fmt::format("{} samples are too many", acceleration.size()));
  r.dt = o.dt;
  r.excitation.time = uniform_times(acceleration.size(), o.dt);
  r.excitation.acceleration = std::move(acceleration);
  scale_record(r, o, name);
  return r;
}

}  // namespace poundsim::io
