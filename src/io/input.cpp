#include "poundsim/io/input.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "poundsim/analysis/channels.hpp"
#include "poundsim/analysis/periodic_orbits.hpp"
#include "poundsim/error.hpp"
#include "poundsim/integrate/integrator.hpp"
#include "poundsim/io/ground_motion.hpp"
#include "poundsim/units.hpp"

namespace poundsim::io {

namespace {

std::string_view type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "table";
    case toml::node_type::array: return "array";
    case toml::node_type::string: return "string";
    case toml::node_type::integer: return "integer";
    case toml::node_type::floating_point: return "number";
    case toml::node_type::boolean: return "boolean";
    default: return "date/time";
  }
}

/// `text` with its control characters escaped, so that a message stays on one line.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      out += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
    } else {
      out += c;
    }
  }
  return out;
}

/// Where a key came from, for messages.
struct Origin {
  std::string file;
  /// Key path → the setting that set it. A setting that creates tables on its way also owns
  /// them. The settings outlive the reading (read_root's span).
  std::map<std::string, const Setting*> overrides;
  /// Where each node of the tree being read stands in the file: the tree is a copy of the file
  /// as parsed, and toml++ does not copy positions (see remember_positions).
  std::unordered_map<const toml::node*, toml::source_position> positions;
  /// The settings name one of the ensemble's records.
  Reading reading = Reading::run;

  /// The setting that set `path` (or created a table on its way to it), or null.
  [[nodiscard]] const Setting* override_of(const std::string& path) const {
    for (const auto& [key, setting] : overrides) {
      if (path == key || path.starts_with(key + ".") || path.starts_with(key + "[")) return setting;
    }
    return nullptr;
  }

  /// The start of a message about `path`: "file: --set key=value: path", "file:line:column: path",
  /// or "file: path" (a key that the file does not hold); "file" alone for the whole file.
  [[nodiscard]] std::string locate(const toml::node* node, const std::string& path) const {
    if (const Setting* s = override_of(path)) return fmt::format("{}: --set {}: {}", file, printable(s->text), path);
    if (path.empty()) return file;
    toml::source_position at{};
    if (node != nullptr) {
      at = node->source().begin;
      if (const auto it = positions.find(node); at.line == 0 && it != positions.end()) at = it->second;
    }
    if (at.line > 0) return fmt::format("{}:{}:{}: {}", file, at.line, at.column, path);
    return fmt::format("{}: {}", file, path);
  }

  /// Throws the InputError about `path`, blamed on the setting that set it, if any.
  [[noreturn]] void fail(const toml::node* node, const std::string& path,
                         const std::string& message) const {
    const Setting* s = path.empty() ? nullptr : override_of(path);
    throw InputError(fmt::format("{}: {}", locate(node, path), message), s != nullptr ? s->key : std::string());
  }
};

/// The value of an integer node if it lies in [lo, hi]; otherwise `fail(message)` (which must
/// throw) is called with the rule broken. The 64-bit value TOML holds is checked before it is
/// narrowed, so that 4294967297 is not read as 1. `what` starts the message ("item 2: ").
/// T is the type the value is stored in; [lo, hi] must lie within it.
template <class T = int, class Fail>
T bounded_integer(const toml::node& node, std::int64_t lo, std::int64_t hi, const std::string& what,
                  const Fail& fail) {
  assert(lo >= static_cast<std::int64_t>(std::numeric_limits<T>::min()) &&
         static_cast<std::uint64_t>(hi) <= static_cast<std::uint64_t>(std::numeric_limits<T>::max()));
  if (!node.is_integer()) fail(fmt::format("{}expected an integer, got a {}", what, type_name(node)));
  const std::int64_t v = node.as_integer()->get();
  if (v < lo) fail(fmt::format("{}must be ≥ {} (got {})", what, lo, v));
  if (v > hi) fail(fmt::format("{}must be ≤ {} (got {})", what, hi, v));
  return static_cast<T>(v);
}

/// The number of single-character insertions, deletions, substitutions and swaps of neighbours
/// that turn a into b (optimal string alignment), to tell a misspelt key from another key.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t change = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + change});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

/// Whether `typed` is close enough to `key` to be its misspelling: one edit in a short key, two
/// up to eight characters, three beyond (a third of a long key's letters).
bool misspelt(std::string_view typed, std::string_view key) {
  const std::size_t allowed = key.size() <= 4 ? 1 : key.size() <= 8 ? 2 : 3;
  return typed != key && edit_distance(typed, key) <= allowed;
}

/// Reads keys of one table, remembers which were read, and rejects the others in finish().
class TableReader {
 public:
  TableReader(const toml::table& table, std::string path, const Origin& origin)
      : table_(&table), path_(std::move(path)), origin_(&origin) {}

  [[nodiscard]] std::string key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }
  [[nodiscard]] bool has(std::string_view key) const {
    check_declared(key);
    return table_->contains(key);
  }

  /// Accepts only the keys the structs S declare (fields.hpp): finish() refuses the others as
  /// unknown, and reading a key they do not declare is a logic error of the reader.
  template <Configuration... S>
  TableReader& declare() {
    for (const std::string_view key : declared_keys<S...>()) declared_.emplace(key);
    return *this;
  }

  /// The first of `keys` this table gives, else `fallback`: the key to blame for a rule between
  /// several (an override is blamed for what it changed).
  [[nodiscard]] std::string_view first_given(std::span<const std::string_view> keys, std::string_view fallback) const {
    const auto given = std::find_if(keys.begin(), keys.end(), [&](std::string_view key) { return has(key); });
    return given != keys.end() ? *given : fallback;
  }
  [[noreturn]] void fail(std::string_view key, const std::string& message) const {
    const toml::node* node = table_->get(key);
    origin_->fail(node != nullptr ? node : table_, key_path(key), message);
  }
  [[noreturn]] void fail_table(const std::string& message) const {
    origin_->fail(table_, path_, message);
  }

  const toml::node* find(std::string_view key) {
    check_declared(key);
    used_.insert(std::string(key));
    return table_->get(key);
  }
  const toml::node& require(std::string_view key) {
    const toml::node* node = find(key);
    if (node == nullptr) fail_missing(key);
    return *node;
  }
  /// A required key is absent: blamed on a key of the table that misspells it, if one does
  /// (a misspelt key is unknown, and would otherwise be reported only after the missing one).
  [[noreturn]] void fail_missing(std::string_view key, const std::string& detail = {}) const {
    blame_misspelling(key);
    origin_->fail(table_, key_path(key), detail.empty() ? "missing key" : "missing key (" + detail + ")");
  }
  /// A required key is absent: fails with `message` at the table, unless a key of the table
  /// misspells it (blame_misspelling).
  [[noreturn]] void fail_table_missing(std::string_view key, const std::string& message) const {
    blame_misspelling(key);
    fail_table(message);
  }
  /// Fails at a key of the table that is not declared and misspells the required `key`, if any.
  void blame_misspelling(std::string_view key) const {
    for (const auto& [given, node] : *table_) {
      if (!is_declared(given.str()) && misspelt(given.str(), key)) {
        origin_->fail(&node, key_path(given.str()),
                      fmt::format("unknown {}; did you mean '{}'? ({} is required)", node.is_table() ? "table" : "key",
                                  key, key_path(key)));
      }
    }
  }

  double number(std::string_view key) { return to_number(key, require(key)); }
  std::optional<double> optional_number(std::string_view key) {
    const toml::node* node = find(key);
    if (node == nullptr) return std::nullopt;
    return to_number(key, *node);
  }
  double number_or(std::string_view key, double fallback) {
    return optional_number(key).value_or(fallback);
  }
  /// An integer in [lo, hi], stored as a T.
  template <class T = int>
  T integer(std::string_view key, std::int64_t lo, std::int64_t hi) {
    return bounded_integer<T>(require(key), lo, hi, "", [&](const std::string& m) { fail(key, m); });
  }
  template <class T = int>
  std::optional<T> optional_integer(std::string_view key, std::int64_t lo, std::int64_t hi) {
    if (!has(key)) return std::nullopt;
    return integer<T>(key, lo, hi);
  }
  /// True when a --set override gave `key`.
  [[nodiscard]] bool overridden(std::string_view key) const { return origin_->override_of(key_path(key)) != nullptr; }
  /// The start of a message about `key` (for messages made later, e.g. by a study's points).
  [[nodiscard]] std::string where(std::string_view key) const {
    return origin_->locate(table_->get(key), key_path(key));
  }
  std::string string(std::string_view key) {
    const toml::node& node = require(key);
    if (!node.is_string()) fail(key, fmt::format("expected a string, got a {}", type_name(node)));
    return *node.value<std::string>();
  }
  bool boolean_or(std::string_view key, bool fallback) {
    if (!has(key)) return fallback;
    const toml::node& node = require(key);
    if (!node.is_boolean()) fail(key, fmt::format("expected true or false, got a {}", type_name(node)));
    return *node.value<bool>();
  }
  std::string string_or(std::string_view key, const std::string& fallback) {
    if (!has(key)) return fallback;
    return string(key);
  }
  /// A non-empty string, one of `allowed` if any are given; `hint` ends the message about an empty one.
  std::string text(std::string_view key, std::span<const std::string_view> allowed, std::string_view hint = {}) {
    if (!allowed.empty()) return choice(key, allowed);
    std::string value = string(key);
    if (value.empty()) fail(key, hint.empty() ? "must not be empty" : fmt::format("must not be empty: {}", hint));
    return value;
  }
  /// A number or an array of numbers, each in `range`, of min_items to max_items items, strictly
  /// increasing if asked.
  std::vector<double> number_list(std::string_view key, const Interval& range, std::size_t min_items,
                                  std::size_t max_items, bool increasing) {
    std::vector<double> values = numbers(key);
    if (values.size() < min_items) fail(key, fmt::format("{} values: at least {}", values.size(), min_items));
    if (values.size() > max_items) fail(key, fmt::format("{} values: at most {}", values.size(), max_items));
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (!range.contains(values[i])) {
        fail(key, fmt::format("item {} must be {} (got {})", i + 1, range.describe(), values[i]));
      }
      if (increasing && i > 0 && !(values[i] > values[i - 1])) fail(key, "must increase");
    }
    return values;
  }
  /// A string that must be one of `allowed`.
  std::string choice(std::string_view key, std::initializer_list<std::string_view> allowed,
                     std::optional<std::string> fallback = std::nullopt) {
    return choice(key, std::span(allowed.begin(), allowed.size()), std::move(fallback));
  }
  std::string choice(std::string_view key, std::span<const std::string_view> allowed,
                     std::optional<std::string> fallback = std::nullopt) {
    const std::string value =
        fallback && !has(key) ? *fallback : string(key);
    for (const std::string_view a : allowed) {
      if (value == a) return value;
    }
    fail(key, fmt::format("\"{}\" is not one of: \"{}\"", value, fmt::join(allowed, "\", \"")));
  }
  /// A number (one value for every floor) or an array of numbers (one per floor).
  std::vector<double> numbers(std::string_view key) {
    const toml::node& node = require(key);
    if (const toml::array* array = node.as_array()) {
      std::vector<double> out;
      for (std::size_t i = 0; i < array->size(); ++i) {
        const toml::node& item = (*array)[i];
        if (!item.is_number()) {
          fail(key, fmt::format("item {} must be a number, got a {}", i + 1, type_name(item)));
        }
        out.push_back(check_finite(key, *item.value<double>()));
      }
      if (out.empty()) fail(key, "the array is empty");
      return out;
    }
    return {to_number(key, node)};
  }
  /// An array of arrays of numbers.
  std::vector<std::vector<double>> number_rows(std::string_view key) {
    const toml::node& node = require(key);
    const toml::array* rows = node.as_array();
    if (rows == nullptr) fail(key, "expected an array of arrays (one per frame)");
    std::vector<std::vector<double>> out;
    for (std::size_t r = 0; r < rows->size(); ++r) {
      const toml::array* row = (*rows)[r].as_array();
      if (row == nullptr) fail(key, fmt::format("item {} must be an array (one value per floor)", r + 1));
      out.emplace_back();
      for (std::size_t i = 0; i < row->size(); ++i) {
        const toml::node& item = *row->get(i);
        if (!item.is_number()) {
          fail(key, fmt::format("frame {} item {} must be a number, got a {}", r + 1, i + 1,
                                type_name(item)));
        }
        out.back().push_back(check_finite(key, *item.value<double>()));
      }
    }
    return out;
  }
  TableReader table(std::string_view key) {
    const toml::node& node = require(key);
    const toml::table* t = node.as_table();
    if (t == nullptr) fail(key, fmt::format("expected a table, got a {}", type_name(node)));
    return TableReader(*t, key_path(key), *origin_);
  }
  std::optional<TableReader> optional_table(std::string_view key) {
    if (!has(key)) return std::nullopt;
    return table(key);
  }
  std::vector<TableReader> tables(std::string_view key) {
    const toml::node& node = require(key);
    const toml::array* array = node.as_array();
    if (array == nullptr || !array->is_array_of_tables()) {
      fail(key, fmt::format("expected an array of tables ([[{}]])", key_path(key)));
    }
    std::vector<TableReader> out;
    for (std::size_t i = 0; i < array->size(); ++i) {
      out.emplace_back(static_cast<const toml::table&>((*array)[i]), fmt::format("{}[{}]", key_path(key), i + 1),
                       *origin_);
    }
    if (out.empty()) fail(key, "the array is empty");
    return out;
  }

  // Range checks that name the key.
  double positive(std::string_view key, double v) {
    if (!(v > 0)) fail(key, fmt::format("must be > 0 (got {})", v));
    return v;
  }

  /// Every key present and not read is an error. `context` explains why, when the key could be valid elsewhere.
  void finish(const std::string& context = {}) const {
    if (declared_.empty()) throw std::logic_error(fmt::format("the reader of [{}] declares no keys", path_));
    for (const auto& [key, node] : *table_) {
      if (!used_.contains(std::string(key.str()))) {
        const std::string what = node.is_table() ? "unknown table" : "unknown key";
        std::string message = context.empty() ? what : what + " " + context;
        if (const std::optional<std::string_view> meant = nearest_declared(key.str())) {
          message += fmt::format("; did you mean '{}'?", *meant);
        }
        origin_->fail(&node, key_path(key.str()), message);
      }
    }
  }

 private:
  void check_declared(std::string_view key) const {
    if (!declared_.empty() && !declared_.contains(key)) {
      throw std::logic_error(fmt::format("the reader of [{}] reads '{}', which its table does not declare",
                                         path_, key));
    }
  }
  double check_finite(std::string_view key, double v) const {
    if (!std::isfinite(v)) fail(key, "must be finite");
    return v;
  }
  double to_number(std::string_view key, const toml::node& node) const {
    if (!node.is_number()) fail(key, fmt::format("expected a number, got a {}", type_name(node)));
    return check_finite(key, *node.value<double>());
  }

  [[nodiscard]] bool is_declared(std::string_view key) const {
    return declared_.empty() ? used_.contains(std::string(key)) : declared_.contains(key);
  }
  /// The declared key nearest to `typed` when `typed` misspells it (the first of equals).
  [[nodiscard]] std::optional<std::string_view> nearest_declared(std::string_view typed) const {
    std::optional<std::string_view> best;
    std::size_t best_distance = 0;
    for (const std::string& key : declared_) {
      if (!misspelt(typed, key)) continue;
      const std::size_t distance = edit_distance(typed, key);
      if (!best || distance < best_distance) best = key, best_distance = distance;
    }
    return best;
  }

  const toml::table* table_;
  std::string path_;
  const Origin* origin_;
  std::set<std::string> used_;
  std::set<std::string, std::less<>> declared_;  ///< Empty until declare().
};

// --- declared fields (fields.hpp) ---------------------------------------------------------------

/// Whether the table may leave a required field out: an override table inherits its fields.
enum class Presence : std::uint8_t { as_declared, inherited };

/// Reads every declared field of S that `t` holds into `s`, checking its type and range; a
/// field absent from the table keeps its value in `s` (the struct's default, or what it
/// inherits). Messages name the key and the rule: "must be ≥ 0 (got -1)".
template <Configuration S>
void read_fields(TableReader& t, S& s, Presence presence = Presence::as_declared) {
  for_each_field<S>([&](const auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (!has_own_rules<Field>) {  // read by the table's own rules
      if (!t.has(field.key)) {
        if constexpr (requires { field.required; }) {
          if (field.required && presence == Presence::as_declared) t.require(field.key);
        }
        return;
      }
    }
    if constexpr (is_number_field<Field>) {
      const double v = t.number(field.key);
      if (!field.range.contains(v)) {
        t.fail(field.key, fmt::format("must be {} (got {})", field.range.describe(), v));
      }
      s.*field.member = v;
    } else if constexpr (is_integer_field<Field>) {
      using T = std::remove_reference_t<decltype(s.*field.member)>;
      s.*field.member = bounded_integer<T>(t.require(field.key), field.lo, field.hi, "", [&](const std::string& m) {
        t.fail(field.key, field.hint.empty() ? m : m + "; " + std::string(field.hint));
      });
    } else if constexpr (is_bool_field<Field>) {
      s.*field.member = t.boolean_or(field.key, s.*field.member);
    } else if constexpr (is_text_field<Field>) {
      s.*field.member = t.text(field.key, field.names, field.hint);
    } else if constexpr (is_optional_number_field<Field>) {
      const double v = t.number(field.key);
      if (!field.range.contains(v)) t.fail(field.key, fmt::format("must be {} (got {})", field.range.describe(), v));
      s.*field.member = v;
    } else if constexpr (is_number_list_field<Field>) {
      s.*field.member = t.number_list(field.key, field.range, field.min_items, field.max_items, field.increasing);
    } else if constexpr (is_choice_field<Field>) {
      const std::string name = t.string(field.key);
      const auto value = field.parse(name);
      if (!value) {
        std::vector<std::string_view> names;
        for (const auto& entry : field.names) names.push_back(entry.first);
        t.fail(field.key, fmt::format("\"{}\" is not one of: \"{}\"", name, fmt::join(names, "\", \"")));
      }
      s.*field.member = *value;
    }
  });
}

// --- --set overrides -------------------------------------------------------------------------

struct KeySegment {
  std::string key;
  int index = 0;  // 1-based array index, 0 for none
};

/// `at` starts every message: "model.toml: --set key=value".
std::vector<KeySegment> split_key(const std::string& key, const std::string& at) {
  std::vector<KeySegment> out;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t dot = key.find('.', begin);
    std::string part = key.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    KeySegment seg;
    const auto bracket = part.find('[');
    if (bracket != std::string::npos) {
      if (part.back() != ']') throw InputError(at + ": malformed key", key);
      const std::string number = part.substr(bracket + 1, part.size() - bracket - 2);
      // Digits only, and few enough that the number fits: "2][3", "+2" or "1e3" are not indices.
      if (number.empty() || number.size() > 9 ||
          number.find_first_not_of("0123456789") != std::string::npos) {
        throw InputError(fmt::format("{}: '{}' is not an index", at, number), key);
      }
      seg.index = std::stoi(number);
      if (seg.index < 1) {
        throw InputError(at + ": indices start at 1 (frames are numbered from 1)", key);
      }
      part = part.substr(0, bracket);
    }
    if (part.empty()) throw InputError(at + ": empty key segment", key);
    seg.key = part;
    out.push_back(seg);
    if (dot == std::string::npos) break;
    begin = dot + 1;
  }
  return out;
}

/// A parsed TOML value as a setting's value; `fail` (which throws) names what it cannot be.
template <class Fail>
SettingValue from_node(const toml::node& node, const Fail& fail) {
  if (node.is_integer()) return {*node.value<std::int64_t>()};
  if (node.is_floating_point()) return {*node.value<double>()};
  if (node.is_boolean()) return {*node.value<bool>()};
  if (node.is_string()) return {std::string(node.as_string()->get())};
  if (const toml::array* array = node.as_array()) {
    auto items = std::make_shared<std::vector<SettingValue>>();
    for (const toml::node& item : *array) items->push_back(from_node(item, fail));
    return {SettingArray(std::move(items))};
  }
  if (node.is_table()) fail("a table cannot be set as a whole: set its keys one by one");
  fail(fmt::format("a {} is not a value of any key", type_name(node)));
  return {};
}

toml::array to_array(const SettingArray& items);

/// Hands `put` the TOML form of a setting's value (a scalar, or a toml::array).
template <class Put>
void with_node(const SettingValue& v, const Put& put) {
  std::visit(
      [&](const auto& x) {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, SettingArray>) {
          put(to_array(x));
        } else {
          put(x);
        }
      },
      v.value);
}

toml::array to_array(const SettingArray& items) {
  toml::array array;
  for (const SettingValue& item : *items) with_node(item, [&](auto&& node) { array.push_back(node); });
  return array;
}

/// The message start of a setting: "model.toml: --set key=value".
std::string setting_at(const std::string& file, const std::string& text) {
  return fmt::format("{}: --set {}", file, printable(text));
}

/// Applies one setting to the parsed file; returns the canonical key path (e.g. "frames[2].mass").
/// The tables it creates on its way are registered in `origin`, so that a message about them
/// names the setting; an error is blamed on the setting.
std::string apply_setting(toml::table& root, const Setting& setting, Origin& origin) {
  const std::string at = setting_at(origin.file, setting.text);
  const auto fail = [&](const std::string& message) { throw InputError(fmt::format("{}: {}", at, message), setting.key); };
  const std::vector<KeySegment> segments = split_key(setting.key, at);
  toml::table* table = &root;
  std::string path;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const KeySegment& seg = segments[s];
    const bool last = s + 1 == segments.size();
    path += (path.empty() ? "" : ".") + seg.key;
    if (seg.index > 0) {
      toml::array* array = table->get_as<toml::array>(seg.key);
      if (array == nullptr || !array->is_array_of_tables()) fail(fmt::format("'{}' is not an array of tables in the file", path));
      if (static_cast<std::size_t>(seg.index) > array->size()) fail(fmt::format("the file has only {} [[{}]]", array->size(), path));
      path += fmt::format("[{}]", seg.index);
      if (last) fail("cannot replace a whole table");
      table = &static_cast<toml::table&>((*array)[static_cast<std::size_t>(seg.index - 1)]);
      continue;
    }
    if (last) {
      with_node(setting.value, [&](auto&& node) { table->insert_or_assign(seg.key, node); });
      break;
    }
    toml::node* child = table->get(seg.key);
    if (child == nullptr) {
      table = table->insert_or_assign(seg.key, toml::table{}).first->second.as_table();
      origin.overrides[path] = &setting;
    } else if (child->is_table()) {
      table = child->as_table();
    } else {
      fail(fmt::format("'{}' is not a table", path));
    }
  }
  return path;
}

// --- sections ----------------------------------------------------------------------------------

/// True when an element whose gap and shortening add up to `stroke` fits a joint of `width`: it
/// bottoms out before the floors meet. Decimal inputs (0.1 + 0.2 in a joint of 0.3) are let
/// through the rounding of the sum.
bool fits_in_joint(double width, double stroke) {
  return width >= stroke * (1 - 4 * std::numeric_limits<double>::epsilon());
}

Model read_dimensionless(TableReader& model_table, RunInput& run) {
  const toml::node& storeys_node = model_table.require("storeys");
  const toml::array* storeys_array = storeys_node.as_array();
  if (storeys_array == nullptr) model_table.fail("storeys", "expected an array of two integers");
  if (storeys_array->size() != 2) {
    model_table.fail("storeys",
                     "the dimensionless form describes two frames; use [[frames]] for other counts");
  }
  std::array<int, 2> storeys{};
  for (std::size_t i = 0; i < 2; ++i) {
    storeys[i] = bounded_integer((*storeys_array)[i], 1, limits::storeys, fmt::format("frame {}: ", i + 1),
                                 [&](const std::string& m) { model_table.fail("storeys", m); });
  }
  TableReader d = model_table.table("dimensionless");
  d.declare<DimensionlessParameters, keys::DimensionlessJoint>();
  DimensionlessParameters p;
  read_fields(d, p);
  if (const std::optional<FieldRule> rule = p.rule_violation()) d.fail(d.first_given(rule->keys, rule->keys.front()), rule->message);
  if (p.epsilon == 0 && (p.eta > 0 || p.mu > 0)) {
    d.fail("epsilon",
           "is 0 but eta or mu is not: an element without stroke is a rigid stop whose spring and "
           "dashpot never act; give epsilon > 0 or eta = mu = 0");
  }
  // w̄ = w λ²/g like delta and epsilon; the floors would collide at w, so the element must
  // bottom out first: delta + epsilon ≤ joint_width.
  const std::optional<double> joint = d.optional_number("joint_width");
  if (joint && !fits_in_joint(*joint, p.delta + p.epsilon)) {
    d.fail("joint_width", fmt::format("{} is narrower than delta + epsilon = {}: the floors would collide "
                                      "before the gap element bottoms out", *joint, p.delta + p.epsilon));
  }
  d.finish();
  double height = 0.0;
  if (auto h = model_table.optional_number("storey_height")) height = model_table.positive("storey_height", *h);
  model_table.finish();
  run.dimensionless = p;
  Model model = make_model(p, storeys);
  if (height > 0) {
    for (Frame& f : model.frames) f.storey_height.assign(f.mass.size(), height);
  }
  for (const GapElement& g : model.gaps) {
    run.joint_widths.push_back(joint ? *joint * standard_gravity / p.lambda2 : g.gap());
  }
  return model;
}

/// The law of gap elements and the width of the joint they sit in.
struct GapSpec {
  GapLaw law;
  std::optional<double> joint;  ///< w [m]; absent: the element's gap.
};

/// [gap_elements] (defaults == nullptr) or one of its overrides. An override inherits the joint
/// width and the law of [gap_elements] and, unless it names another law, the law's values.
GapSpec read_gap_law(TableReader& t, const GapSpec* defaults) {
  GapSpec spec = defaults != nullptr ? *defaults : GapSpec{};
  bool inherits = defaults != nullptr;
  if (t.has("law")) {
    const std::string name = t.choice("law", gap_law_names);
    if (!inherits || name != key_of(spec.law)) {
      spec.law = *gap_law_named(name);
      inherits = false;
    }
  }
  std::visit(
      [&](auto& law) {
        using Parameters = std::decay_t<decltype(law.parameters)>;
        t.declare<Parameters>();
        read_fields(t, law.parameters, inherits ? Presence::inherited : Presence::as_declared);
        if (const std::optional<FieldRule> rule = law.parameters.rule_violation()) {
          t.fail(t.first_given(rule->keys, rule->keys.front()), rule->message);
        }
      },
      spec.law);
  if (auto w = t.optional_number("joint_width")) spec.joint = *w;
  // The floors would collide at the joint width: the element must bottom out first. An override
  // that widens the element beyond an inherited joint is blamed on the key it changed.
  std::visit(
      [&](const auto& law) {
        if (!spec.joint || fits_in_joint(*spec.joint, law.locked_length())) return;
        const auto& keys = law.locked_length_keys;
        t.fail(t.has("joint_width") ? std::string_view("joint_width") : t.first_given(keys, keys.back()),
               fmt::format("the joint width {} m is narrower than {} = {} m: the floors would collide before "
                           "the gap element bottoms out",
                           *spec.joint, fmt::join(keys, " + "), law.locked_length()));
      },
      spec.law);
  return spec;
}

/// `floors = [left, right]` of a [[gap_elements.pair]] between frames `left` and `right` (from 1).
template <class Storeys>
FloorPair read_floor_pair(TableReader& t, int left, int right, const Storeys& storeys) {
  const toml::array* floor_pair = t.require("floors").as_array();
  if (floor_pair == nullptr || floor_pair->size() != 2) {
    t.fail("floors", "expected [floor of the left frame, floor of the right frame], e.g. [3, 2]");
  }
  const int lf = bounded_integer((*floor_pair)[0], 1, storeys(left), "item 1: ", [&](const std::string& m) {
    t.fail("floors", fmt::format("{} (frame {} has {} floors)", m, left, storeys(left)));
  });
  const int rf = bounded_integer((*floor_pair)[1], 1, storeys(right), "item 2: ", [&](const std::string& m) {
    t.fail("floors", fmt::format("{} (frame {} has {} floors)", m, right, storeys(right)));
  });
  return {.left_frame = left - 1, .left_floor = lf - 1, .right_floor = rf - 1};
}

/// The heights of a frame's floors above the ground [m], from its storey heights.
std::vector<double> floor_heights(const Frame& frame) {
  std::vector<double> heights;
  double height = 0.0;
  for (const double h : frame.storey_height) heights.push_back(height += h);
  return heights;
}

/// `slab = [frame, floor]` of a [[gap_elements.pair]] between frames `left` and left + 1: the
/// slab strikes the other frame's column at its height, between the floors below and above it
/// (the ground below a first floor), where the column's displacement interpolates theirs
/// (docs/model.md#slab-to-column). A slab level with a floor of the other frame strikes that
/// floor: the pair is then two floors.
FloorPair read_slab_pair(TableReader& t, int left, const std::vector<Frame>& frames,
                         std::vector<TableReader>& frame_tables) {
  const toml::array* slab = t.require("slab").as_array();
  if (slab == nullptr || slab->size() != 2) {
    t.fail("slab", "expected [frame, floor]: the frame whose slab strikes and its floor, e.g. [1, 4]");
  }
  const int frame = bounded_integer((*slab)[0], left, left + 1, "item 1: ", [&](const std::string& m) {
    t.fail("slab", fmt::format("{} (one of the pair's frames)", m));
  });
  const auto storeys = static_cast<std::int64_t>(frames[static_cast<std::size_t>(frame - 1)].storeys());
  const int floor = bounded_integer((*slab)[1], 1, storeys, "item 2: ", [&](const std::string& m) {
    t.fail("slab", fmt::format("{} (frame {} has {} floors)", m, frame, storeys));
  });
  const int struck = frame == left ? left + 1 : left;
  for (const int f : {frame, struck}) {
    if (frames[static_cast<std::size_t>(f - 1)].storey_height.empty()) {
      frame_tables[static_cast<std::size_t>(f - 1)].fail_table(fmt::format(
          "missing key: storey_height (gap_elements.pair.slab places the slab of frame {} on the column of frame "
          "{} by their heights)", frame, struck));
    }
  }
  const double height = floor_heights(frames[static_cast<std::size_t>(frame - 1)])[static_cast<std::size_t>(floor - 1)];
  const std::vector<double> column = floor_heights(frames[static_cast<std::size_t>(struck - 1)]);
  // Heights written to different precision (3.2 and 3.2000000001) are the same floor.
  const auto level = [&](double h) { return std::abs(h - height) <= 1e-9 * std::max(h, height); };
  const auto above = std::find_if(column.begin(), column.end(), [&](double h) { return h > height || level(h); });
  if (above == column.end()) {
    t.fail("slab", fmt::format("floor {} of frame {} stands {} m above the ground, above the roof of frame {} "
                               "({} m): there is no column to strike", floor, frame, height, struck, column.back()));
  }
  const int upper = static_cast<int>(above - column.begin());
  FloorPair pair{.left_frame = left - 1,
                 .left_floor = frame == left ? floor - 1 : upper,
                 .right_floor = frame == left ? upper : floor - 1};
  if (level(*above)) return pair;  // slab against slab
  const double below = upper == 0 ? 0.0 : column[static_cast<std::size_t>(upper - 1)];
  pair.column = ColumnStrike{.struck = struck == left ? Side::left : Side::right,
                             .weight = (height - below) / (*above - below)};
  return pair;
}

/// A slab striking a column takes a law without a stop (validate(Model) says so too, without the
/// key): refused naming the table's `law` (or its default's).
void check_law_at_column(TableReader& t, const FloorPair& pair, const GapLaw& law) {
  if (!pair.column) return;
  const LawTraits& traits = std::visit([](const auto& l) -> const LawTraits& { return l.traits; }, law);
  if (!traits.has_stop) return;
  GapElement element{.left_frame = pair.left_frame, .floor = pair.left_floor, .law = law,
                     .right_floor = pair.right_floor, .column = pair.column};
  t.fail("law", fmt::format("{} for the {}: a slab that strikes a column takes a contact law without a stop (kelvin_voigt, "
                            "hertz, hertzdamp, jankowski); {} has one, whose impacts and locking act between two floors",
                            t.has("law") ? fmt::format("\"{}\"", key_of(law)) : fmt::format("\"{}\" (the default)", key_of(law)),
                            describe(element), traits.name));
}

/// Whether two pairs of a joint give one floor two elements on the same side (a struck column has
/// no floor there: several slabs may strike one storey's column).
bool share_a_floor(const FloorPair& a, const FloorPair& b) {
  if (a.left_frame != b.left_frame) return false;
  const auto slab = [](const FloorPair& p, Side side) { return !p.column || p.column->struck != side; };
  return (slab(a, Side::left) && slab(b, Side::left) && a.left_floor == b.left_floor) ||
         (slab(a, Side::right) && slab(b, Side::right) && a.right_floor == b.right_floor);
}

/// Storey heights: by default gap elements join floors of the same number, which must then
/// stand at the same height above the ground; other floors are paired by height or listed.
void check_floor_heights(const std::vector<Frame>& frames, std::vector<TableReader>& tables) {
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    const Frame& left = frames[f];
    const Frame& right = frames[f + 1];
    if (left.storey_height.empty() && right.storey_height.empty()) continue;
    if (left.storey_height.empty() || right.storey_height.empty()) {
      const std::size_t without = left.storey_height.empty() ? f : f + 1;
      tables[without].fail_table(fmt::format(
          "missing key: storey_height (frame {} has one): frames {} and {} are joined floor to floor, "
          "which needs their floors at the same heights; give storey_height for both or neither",
          without == f ? f + 2 : f + 1, f + 1, f + 2));
    }
    const std::size_t shared = std::min(left.storey_height.size(), right.storey_height.size());
    double height_left = 0.0, height_right = 0.0;
    for (std::size_t i = 0; i < shared; ++i) {
      height_left += left.storey_height[i];
      height_right += right.storey_height[i];
      // Heights written to different precision (3.2 and 3.2000000001) are the same floor.
      if (std::abs(height_left - height_right) > 1e-9 * std::max(height_left, height_right)) {
        tables[f + 1].fail("storey_height", fmt::format(
            "floor {} stands {} m above the ground, floor {} of frame {} {} m: the gap elements join "
            "floors of the same number (gap_elements.pairing = \"floor\", the default), which must "
            "stand at the same height. Set gap_elements.pairing = \"height\" to join the floors that "
            "stand at the same height, or pairing = \"listed\" with a [[gap_elements.pair]] table "
            "(frames = [{}, {}], floors = [left floor, right floor]) for each pair of floors that "
            "strike each other, or slab = [frame, floor] for a slab that strikes the neighbour's column",
            i + 1, height_right, i + 1, f + 1, height_left, f + 1, f + 2));
      }
    }
  }
}

/// Each storey's (or floor's) value of `key` must lie in `range`: "storey 2: must be > 0 (got -1)".
void check_each_storey(TableReader& f, std::string_view key, const std::vector<double>& values, const Interval& range,
                       std::string_view item) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!range.contains(values[i])) {
      f.fail(key, fmt::format("{} {}: must be {} (got {})", item, i + 1, range.describe(), values[i]));
    }
  }
}

/// `storey_law` of a [[frames]] table (the first storey law by default) and then the declared
/// parameters of that law, each a number for every storey or an array of one per storey, with
/// each storey's value in the field's range and the law's rules between them.
template <class Broadcast>
StoreyLawParameters read_storey_law(TableReader& f, int storeys, const Broadcast& broadcast) {
  StoreyLawParameters law = *storey_law_named(f.has("storey_law") ? f.choice("storey_law", storey_law_names)
                                                                   : std::string(storey_law_names.front()));
  std::visit(
      [&](auto& per_storey) {
        using Parameters = typename std::decay_t<decltype(per_storey)>::Law::Parameters;
        f.declare<Parameters>();
        // None given: the law's defaults, as an empty list (one form for both) — refused when the
        // defaults break the law's rules (a yielding storey has no default yield force).
        bool given = false;
        for_each_field<Parameters>([&](const auto& field) { given = given || f.has(field.key) || field.required; });
        if (const std::optional<FieldRule> rule = Parameters{}.rule_violation(); rule && !given) {
          f.fail("storey_law", fmt::format("\"{}\" needs {}, and the frame gives neither: {}",
                                           std::decay_t<decltype(per_storey)>::Law::key,
                                           fmt::join(rule->keys, " or "), rule->message));
        }
        if (given) {
          per_storey.values.assign(static_cast<std::size_t>(storeys), Parameters{});
          for_each_field<Parameters>([&](const auto& field) {
            static_assert(is_number_field<std::decay_t<decltype(field)>>, "storey parameters are numbers");
            if (!f.has(field.key)) {
              if (field.required) f.require(field.key);
              return;
            }
            std::vector<double> values = f.numbers(field.key);
            broadcast(field.key, values);
            check_each_storey(f, field.key, values, field.range, "storey");
            for (std::size_t i = 0; i < values.size(); ++i) per_storey.values[i].*field.member = values[i];
          });
          for (std::size_t i = 0; i < per_storey.values.size(); ++i) {
            if (const std::optional<FieldRule> rule = per_storey.values[i].rule_violation()) {
              f.fail(f.first_given(rule->keys, rule->keys.front()), fmt::format("storey {}: {}", i + 1, rule->message));
            }
          }
        }
      },
      law);
  return law;
}

/// Rayleigh damping C = a₀M + a₁K from rayleigh_ratios = [ζ_i, ζ_j] at rayleigh_modes = [i, j]:
/// the storey dashpots a₁K_i and dashpots a₀M_i from each floor to the ground.
void read_rayleigh(TableReader& f, Frame& frame) {
  const std::vector<double> ratios = f.numbers("rayleigh_ratios");
  const std::vector<double> modes = f.numbers("rayleigh_modes");
  if (ratios.size() != 2) f.fail("rayleigh_ratios", fmt::format("expected two ratios [ζ_i, ζ_j], got {}", ratios.size()));
  if (modes.size() != 2) f.fail("rayleigh_modes", fmt::format("expected two modes [i, j], got {}", modes.size()));
  for (const double zeta : ratios) {
    if (!(zeta >= 0 && zeta < 1)) f.fail("rayleigh_ratios", fmt::format("each must be in [0, 1) (got {})", zeta));
  }
  const int n = frame.storeys();
  for (const double mode : modes) {
    if (!(mode >= 1 && mode <= n && std::floor(mode) == mode)) {
      f.fail("rayleigh_modes", fmt::format("each must be a mode number 1 … {} (got {})", n, mode));
    }
  }
  if (modes[0] == modes[1]) f.fail("rayleigh_modes", "the two modes must differ");
  frame.damping.assign(frame.mass.size(), 0.0);  // the undamped frame's modes
  const RayleighCoefficients a = rayleigh_coefficients(frame, static_cast<int>(modes[0]), ratios[0],
                                                       static_cast<int>(modes[1]), ratios[1]);
  if (!(a.mass >= 0 && a.stiffness >= 0)) {
    f.fail("rayleigh_ratios",
           fmt::format("give a₀ = {:.6g} 1/s and a₁ = {:.6g} s: a negative coefficient would feed energy into "
                       "some modes; raise the ratio of the higher mode",
                       a.mass, a.stiffness));
  }
  frame.ground_damping.resize(frame.mass.size());
  for (std::size_t i = 0; i < frame.mass.size(); ++i) {
    frame.damping[i] = a.stiffness * frame.stiffness[i];
    frame.ground_damping[i] = a.mass * frame.mass[i];
  }
}

/// The damping keys of a [[frames]] table: storey dashpots (damping, with dashpots to the ground
/// and modal damping if wanted), or one rule that sets them (damping_ratio, Rayleigh), alone.
struct DampingKeys {
  bool damping, ratio, rayleigh, modal;
};

DampingKeys check_damping_keys(TableReader& f) {
  const DampingKeys given{.damping = f.has("damping"), .ratio = f.has("damping_ratio"),
                          .rayleigh = f.has("rayleigh_ratios") || f.has("rayleigh_modes"),
                          .modal = f.has("modal_damping_ratios")};
  if (given.damping && given.ratio) f.fail_table("give either damping or damping_ratio, not both");
  if (!given.damping && !given.ratio && !given.rayleigh && !given.modal) {
    f.fail_table("missing key: damping (N·s/m per storey), damping_ratio, rayleigh_ratios with rayleigh_modes, "
                 "or modal_damping_ratios");
  }
  for (const auto& [rule, on] : {std::pair{"damping_ratio", given.ratio}, std::pair{"rayleigh_ratios", given.rayleigh}}) {
    if (!on) continue;
    for (const char* other : {"damping", "damping_ratio", "rayleigh_ratios", "modal_damping_ratios", "ground_damping"}) {
      const bool other_given = std::string_view(other) == "rayleigh_ratios" ? given.rayleigh : f.has(other);
      if (std::string_view(other) != rule && other_given) {
        f.fail(rule, fmt::format("sets the frame's dashpots by its rule: give it alone, not with {}", other));
      }
    }
  }
  return given;
}

/// The storey dashpots a frame's damping rule sets (none when they are given per storey).
void apply_damping_rule(TableReader& f, const DampingKeys& given, Frame& frame) {
  if (given.rayleigh) {
    read_rayleigh(f, frame);
  } else if (given.modal && !given.damping) {
    frame.damping.assign(frame.mass.size(), 0.0);  // modal damping alone
  } else if (!given.damping) {
    const double ratio = f.number("damping_ratio");
    if (!(ratio >= 0 && ratio < 1)) f.fail("damping_ratio", fmt::format("must be in [0, 1) (got {})", ratio));
    frame.damping.assign(frame.mass.size(), 0.0);
    frame.damping = stiffness_proportional_damping(frame, ratio);
    if (!std::all_of(frame.damping.begin(), frame.damping.end(), [](double c) { return std::isfinite(c); })) {
      // Storey stiffnesses spanning ~16 orders of magnitude leave the lowest eigenvalue below the
      // round-off of the largest: ω₁ comes out 0.
      const auto [low, high] = std::minmax_element(frame.stiffness.begin(), frame.stiffness.end());
      f.fail("damping_ratio",
             fmt::format("the frame's fundamental frequency cannot be resolved in double precision "
                         "(storey stiffnesses from {} to {} N/m), so stiffness-proportional dampers "
                         "are not finite; give damping per storey instead",
                         *low, *high));
    }
  }
}

/// The number of storeys of a frame: `storeys`, or the length of its per-floor arrays.
int frame_storeys(TableReader& f, const Frame& frame, const std::optional<int>& storeys) {
  int n = storeys.value_or(0);
  for_each_field<Frame>([&](const auto& field) {
    const std::vector<double>& v = frame.*field.member;
    if (v.size() > static_cast<std::size_t>(limits::storeys)) {
      f.fail(field.key, fmt::format("has {} values: a frame has at most {} storeys", v.size(), limits::storeys));
    }
    if (v.size() > 1 && n == 0) n = static_cast<int>(v.size());
  });
  if (n == 0 && !storeys) f.fail_table_missing("storeys", "missing key: storeys (or give per-floor arrays)");
  return n;
}

/// One [[frames]] table; `floors` counts the floors of the frames read so far.
Frame read_frame(TableReader& f, int& floors) {
  f.declare<keys::Frame, Frame>();
  Frame frame;
  frame.name = f.string_or("name", "");
  const std::optional<int> storeys = f.optional_integer("storeys", 1, limits::storeys);
  // The declared per-storey values (Frame::fields()), each a number or an array, bottom up.
  for_each_field<Frame>([&](const auto& field) {
    if (field.required || f.has(field.key)) frame.*field.member = f.numbers(field.key);
  });
  const DampingKeys damping = check_damping_keys(f);
  const int n = frame_storeys(f, frame, storeys);
  floors += n;
  if (floors > limits::floors) {
    f.fail_table(fmt::format("the frames up to this one have {} floors: at most {} in all", floors,
                             limits::floors));
  }
  const auto broadcast = [&](std::string_view key, std::vector<double>& v) {
    if (v.size() == 1) v.assign(static_cast<std::size_t>(n), v[0]);
    if (v.size() != static_cast<std::size_t>(n)) {
      f.fail(key, fmt::format("has {} values for {} floors", v.size(), n));
    }
  };
  for_each_field<Frame>([&](const auto& field) {
    std::vector<double>& v = frame.*field.member;
    if (v.empty()) return;  // not given
    broadcast(field.key, v);
    check_each_storey(f, field.key, v, field.range, field.item);
  });
  apply_damping_rule(f, damping, frame);
  frame.storey_law = read_storey_law(f, n, broadcast);
  f.finish();
  return frame;
}

/// pairing = "height": the floors of neighbouring frames that stand at the same height.
std::vector<FloorPair> pairs_at_equal_heights(TableReader& gaps, const std::vector<Frame>& frames,
                                              std::vector<TableReader>& frame_tables) {
  std::vector<FloorPair> pairs = floors_at_equal_heights(frames);
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    for (const std::size_t g : {f, f + 1}) {
      if (frames[g].storey_height.empty()) {
        frame_tables[g].fail_table(fmt::format(
            "missing key: storey_height (gap_elements.pairing = \"height\" joins the floors of frames {} "
            "and {} that stand at the same height)", f + 1, f + 2));
      }
    }
    if (std::none_of(pairs.begin(), pairs.end(), [&](const FloorPair& p) { return p.left_frame == static_cast<int>(f); })) {
      gaps.fail("pairing", fmt::format("no floor of frame {} stands at the height of a floor of frame {}: list "
                                       "the floors that strike each other (pairing = \"listed\")", f + 1, f + 2));
    }
  }
  return pairs;
}

/// pairing = "listed": one [[gap_elements.pair]] table per pair of floors (or slab and column).
std::vector<FloorPair> listed_pairs(TableReader& gaps, const std::vector<Frame>& frames,
                                    std::vector<TableReader>& frame_tables) {
  if (!gaps.has("pair")) gaps.fail("pairing", "\"listed\" needs a [[gap_elements.pair]] table per pair of floors");
  std::vector<FloorPair> pairs;
  for (TableReader& t : gaps.tables("pair")) {
    t.declare<keys::GapPair>();
    const toml::array* frame_pair = t.require("frames").as_array();
    if (frame_pair == nullptr || frame_pair->size() != 2) {
      t.fail("frames", "expected two neighbouring frame numbers, e.g. [1, 2]");
    }
    if (t.has("floors") == t.has("slab")) {
      t.fail_table("give floors = [left floor, right floor] for two floors that strike each other, or "
                   "slab = [frame, floor] for a slab that strikes the neighbour's column");
    }
    const auto frames_count = static_cast<std::int64_t>(frames.size());
    const int left = bounded_integer((*frame_pair)[0], 1, frames_count, "item 1: ",
                                     [&](const std::string& m) { t.fail("frames", m); });
    const int right = bounded_integer((*frame_pair)[1], 1, frames_count, "item 2: ",
                                      [&](const std::string& m) { t.fail("frames", m); });
    if (right != left + 1) t.fail("frames", fmt::format("[{}, {}] are not neighbouring frames", left, right));
    const auto storeys = [&](int frame) { return static_cast<std::int64_t>(frames[static_cast<std::size_t>(frame - 1)].storeys()); };
    FloorPair pair = t.has("floors") ? read_floor_pair(t, left, right, storeys)
                                     : read_slab_pair(t, left, frames, frame_tables);
    for (const FloorPair& seen : pairs) {
      if (share_a_floor(seen, pair)) {
        t.fail(t.has("floors") ? "floors" : "slab",
               fmt::format("a floor of it already has a gap element towards frame {}: a floor meets its neighbour "
                           "at one place", right));
      }
    }
    pairs.push_back(pair);
    t.finish();
  }
  return pairs;
}

/// The floors that gap elements join, by [gap_elements].pairing (empty: floor by floor).
std::vector<FloorPair> read_pairs(TableReader& gaps, const std::vector<Frame>& frames,
                                  std::vector<TableReader>& frame_tables) {
  const std::string pairing = gaps.choice("pairing", names::pairing, std::string("floor"));
  std::vector<FloorPair> pairs;
  if (pairing == "floor") {
    check_floor_heights(frames, frame_tables);
  } else if (pairing == "height") {
    pairs = pairs_at_equal_heights(gaps, frames, frame_tables);
  } else {
    pairs = listed_pairs(gaps, frames, frame_tables);
  }
  if (pairing != "listed" && gaps.has("pair")) gaps.fail("pair", "[[gap_elements.pair]] needs pairing = \"listed\"");
  return pairs;
}

/// Whether an override (right_floor < 0: any right floor) names the element at a pair's floors.
bool names_element(int left_frame, int floor, int right_floor, const FloorPair& p) {
  return p.left_frame == left_frame && p.left_floor == floor && (right_floor < 0 || p.right_floor == right_floor);
}

/// The element an override names: its left frame, left floor and (or -1) right floor.
GapOverride read_override_target(TableReader& o, const std::vector<Frame>& frames,
                                 const std::vector<FloorPair>& pairs) {
  const toml::array* pair = o.require("frames").as_array();
  if (pair == nullptr || pair->size() != 2) o.fail("frames", "expected two neighbouring frame numbers, e.g. [1, 2]");
  const auto frames_count = static_cast<std::int64_t>(frames.size());
  const auto frame_number = [&](std::size_t i) {
    return bounded_integer((*pair)[i], 1, frames_count, fmt::format("item {}: ", i + 1), [&](const std::string& m) {
      o.fail("frames", m + fmt::format(" (the model has {} frames)", frames_count));
    });
  };
  const int left = frame_number(0), right = frame_number(1);
  if (right != left + 1) {
    o.fail("frames", fmt::format("[{}, {}] are not neighbouring frames of the {} in the model", left, right,
                                 frames.size()));
  }
  const auto storeys = [&](int frame) { return frames[static_cast<std::size_t>(frame - 1)].storeys(); };
  const int shared = std::min(storeys(left), storeys(right));
  const int floor = bounded_integer(o.require("floor"), 1, pairs.empty() ? shared : storeys(left), "",
                                    [&](const std::string& m) {
    o.fail("floor", fmt::format("{}: frames {} and {} share floors 1..{}", m, left, right, shared));
  });
  // An element is named by its left floor, and by its right floor too when several share
  // the left one (a slab of the right frame striking the left column below a floor).
  int right_floor = -1;
  if (o.has("right_floor")) {
    if (pairs.empty()) o.fail("right_floor", "only with listed or height pairs (gap_elements.pairing)");
    const auto right_storeys = static_cast<std::int64_t>(storeys(right));
    right_floor = bounded_integer(o.require("right_floor"), 1, right_storeys, "", [&](const std::string& m) {
      o.fail("right_floor", fmt::format("{} (frame {} has {} floors)", m, right, right_storeys));
    }) - 1;
  }
  const auto named = std::count_if(pairs.begin(), pairs.end(), [&](const FloorPair& p) {
    return names_element(left - 1, floor - 1, right_floor, p);
  });
  if (!pairs.empty() && named == 0) {
    o.fail(right_floor < 0 ? "floor" : "right_floor",
           fmt::format("no gap element joins floor {} of frame {} to {} (an override names an element by its left "
                       "floor, and right_floor)", floor, left,
                       right_floor < 0 ? fmt::format("frame {}", right)
                                       : fmt::format("floor {} of frame {}", right_floor + 1, right)));
  }
  if (named > 1) {
    o.fail("floor", fmt::format("{} gap elements meet frame {} at floor {} or at its column below it (slabs of "
                                "frame {} that strike it): give right_floor, the element's floor in frame {}",
                                named, left, floor, right, right));
  }
  return GapOverride{.left_frame = left - 1, .floor = floor - 1, .law = GapLaw{}, .right_floor = right_floor};
}

/// The [[gap_elements.override]] tables, each with its joint width (absent: the default's).
struct Overrides {
  std::vector<GapOverride> elements;
  std::vector<std::optional<double>> joints;
};

Overrides read_overrides(TableReader& gaps, const std::vector<Frame>& frames, const std::vector<FloorPair>& pairs,
                         const GapSpec& defaults) {
  Overrides overrides;
  if (!gaps.has("override")) return overrides;
  for (TableReader& o : gaps.tables("override")) {
    o.declare<keys::GapOverride>();
    GapOverride go = read_override_target(o, frames, pairs);
    const GapSpec spec = read_gap_law(o, &defaults);
    for (const FloorPair& p : pairs) {
      if (names_element(go.left_frame, go.floor, go.right_floor, p)) check_law_at_column(o, p, spec.law);
    }
    go.law = spec.law;
    for (const GapOverride& seen : overrides.elements) {
      if (seen.left_frame == go.left_frame && seen.floor == go.floor &&
          (seen.right_floor < 0 || go.right_floor < 0 || seen.right_floor == go.right_floor)) {
        o.fail_table("a second override of the same element");
      }
    }
    overrides.elements.push_back(go);
    overrides.joints.push_back(spec.joint);
    o.finish();
  }
  return overrides;
}

/// Each element's joint width w [m]: its override's, else [gap_elements]', else its gap.
std::vector<double> joint_widths(const Model& model, const GapSpec& defaults, const Overrides& overrides) {
  std::vector<double> widths;
  for (const GapElement& g : model.gaps) {
    std::optional<double> joint = defaults.joint;
    for (std::size_t k = 0; k < overrides.elements.size(); ++k) {
      const GapOverride& o = overrides.elements[k];
      if (o.left_frame == g.left_frame && o.floor == g.floor && (o.right_floor < 0 || o.right_floor == g.floor_right())) {
        joint = overrides.joints[k];
      }
    }
    widths.push_back(joint.value_or(g.gap()));
  }
  return widths;
}

Model read_physical(TableReader& top, RunInput& run) {
  std::vector<Frame> frames;
  std::vector<TableReader> frame_tables = top.tables("frames");
  if (frame_tables.size() > static_cast<std::size_t>(limits::frames)) {
    top.fail("frames", fmt::format("{} frames: at most {}", frame_tables.size(), limits::frames));
  }
  int floors = 0;
  for (TableReader& f : frame_tables) frames.push_back(read_frame(f, floors));
  if (frames.size() == 1) {
    if (top.has("gap_elements")) {
      top.fail("gap_elements", "the model has a single frame: there are no gap elements");
    }
    return make_model(std::move(frames), GapLaw{});
  }
  TableReader gaps = top.table("gap_elements");
  gaps.declare<keys::GapElements>();
  const std::vector<FloorPair> pairs = read_pairs(gaps, frames, frame_tables);
  const GapSpec defaults = read_gap_law(gaps, nullptr);
  const Overrides overrides = read_overrides(gaps, frames, pairs, defaults);
  for (const FloorPair& p : pairs) {
    const bool overridden = std::any_of(overrides.elements.begin(), overrides.elements.end(), [&](const GapOverride& o) {
      return names_element(o.left_frame, o.floor, o.right_floor, p);
    });
    if (!overridden) check_law_at_column(gaps, p, defaults.law);
  }
  gaps.finish();
  Model model = make_model(std::move(frames), defaults.law, overrides.elements, pairs);
  run.joint_widths = joint_widths(model, defaults, overrides);
  return model;
}

/// [output]: the channels of history.csv, each pattern naming at least one channel of the model.
void read_output(TableReader& t, RunInput& run) {
  t.declare<keys::Output>();
  const toml::array* patterns = t.require("channels").as_array();
  if (patterns == nullptr || patterns->empty()) {
    t.fail("channels", "expected a non-empty array of channel names or patterns, e.g. [\"u_*\", \"drift_ratio_2_*\"]");
  }
  for (std::size_t k = 0; k < patterns->size(); ++k) {
    const std::optional<std::string> pattern = (*patterns)[k].value<std::string>();
    if (!pattern || pattern->empty()) t.fail("channels", fmt::format("item {}: expected a channel name or pattern", k + 1));
    run.channels.push_back(*pattern);
  }
  try {
    static_cast<void>(HistoryChannels(run.model, run.channels));
  } catch (const std::invalid_argument& e) {
    t.fail("channels", e.what());
  }
  t.finish();
}

void read_initial(TableReader& t, const Model& model, InitialConditions& ic) {
  t.declare<keys::Initial>();
  const auto rows = [&](const char* key, std::vector<std::vector<double>>& out) {
    if (!t.has(key)) return;
    out = t.number_rows(key);
    if (static_cast<int>(out.size()) != model.frame_count()) {
      t.fail(key, fmt::format("has {} rows, the model has {} frames", out.size(), model.frame_count()));
    }
    for (int f = 0; f < model.frame_count(); ++f) {
      if (static_cast<int>(out[f].size()) != model.frames[f].storeys()) {
        t.fail(key, fmt::format("frame {} has {} floors, {} values given", f + 1,
                                model.frames[f].storeys(), out[f].size()));
      }
    }
  };
  rows("displacement", ic.displacement);
  rows("velocity", ic.velocity);
  t.finish();
}

/// The figures of a record read (from samples or a file) that the run reports.
void set_record_info(const GroundMotionRecord& r, RunInput& run) {
  ExcitationInfo& info = run.excitation_info;
  run.excitation = r.excitation;
  info.record_scale = r.scale;
  info.record_units = r.file_units;
  info.record_format = r.format;
  info.record_points = r.points;
  info.record_dt = r.dt;
  info.record_pga_file_g = r.pga_file_g;
  info.record_pga_g = r.pga_g;
  info.record_duration = r.duration;
}

/// kind = "harmonic": ü_g = a g sin ω̄t with ω̄ given as one of ratio, omega or frequency_hz.
void read_harmonic(TableReader& t, RunInput& run) {
  ExcitationInfo& info = run.excitation_info;
  info.amplitude_g = t.number("amplitude_g");
  const int given = int(t.has("ratio")) + int(t.has("omega")) + int(t.has("frequency_hz"));
  if (given != 1) {
    t.fail_table("give exactly one of ratio (ω̄/ω₁), omega (rad/s) or frequency_hz");
  }
  if (auto r = t.optional_number("ratio")) info.omega = t.positive("ratio", *r) * info.omega1;
  if (auto w = t.optional_number("omega")) info.omega = t.positive("omega", *w);
  if (auto f = t.optional_number("frequency_hz")) {
    info.omega = 2.0 * std::numbers::pi * t.positive("frequency_hz", *f);
  }
  run.excitation = HarmonicExcitation{info.amplitude_g * standard_gravity, info.omega};
}

/// A record's format, units and factor (scale or target_pga_g), shared by samples and files.
RecordOptions read_record_scaling(TableReader& t, const Origin& origin, const RunInput& run) {
  RecordOptions o;
  o.gravity = standard_gravity;
  const std::string format = t.choice("format", names::record_format, std::string("auto"));
  for (const auto& [name, value] : record_format_names) {
    if (name == format) o.format = value;
  }
  o.units = t.has("units") ? t.choice("units", names::record_units) : std::string();
  if (t.has("scale") && t.has("target_pga_g")) t.fail("target_pga_g", "give either scale or target_pga_g, not both");
  if (auto scale = t.optional_number("scale")) {
    if (*scale == 0) t.fail("scale", "must not be 0 (a negative scale reverses the record)");
    o.scale = *scale;
  }
  if (auto target = t.optional_number("target_pga_g")) o.target_pga_g = t.positive("target_pga_g", *target);
  if (run.ensemble && run.ensemble->scaling) {
    // Each record's factor comes from [ensemble.scaling], set as the record's own scale (with
    // its file) when it runs: one given here would be overridden, or fight it.
    const bool record_point = origin.reading == Reading::ensemble_record;
    if (t.has("target_pga_g")) t.fail("target_pga_g", "not with [ensemble.scaling], which scales every record");
    if (t.has("scale") && !record_point) t.fail("scale", "not with [ensemble.scaling], which scales every record");
  }
  return o;
}

/// Samples given in the input (the Python module's arrays): no file, its format or column.
void read_record_samples(TableReader& t, RecordOptions o, RunInput& run) {
  for (const char* key : {"file", "format", "column"}) {
    if (t.has(key)) t.fail(key, "not with acceleration (the samples are the record)");
  }
  if (run.ensemble) t.fail("acceleration", "an ensemble takes its records from [ensemble]");
  if (!t.has("units")) t.blame_misspelling("units");
  if (!t.has("dt")) t.blame_misspelling("dt");
  if (!t.has("units")) t.fail_table("missing key: units (of the acceleration samples: \"g\", \"m/s2\" or \"cm/s2\")");
  if (!t.has("dt")) t.fail_table("missing key: dt (the interval of the acceleration samples)");
  o.dt = t.positive("dt", t.number("dt"));
  const toml::node& samples = t.require("acceleration");
  if (!samples.is_array() || samples.as_array()->size() < 2) {
    t.fail("acceleration", "expected an array of at least two accelerations");
  }
  ExcitationInfo& info = run.excitation_info;
  info.record_options = o;
  info.record_samples = t.numbers("acceleration");
  try {
    set_record_info(record_from_samples(info.record_samples, o, "samples"), run);
  } catch (const RecordScaleError& e) {  // the samples are fine; the factor overflows them
    t.fail(t.has("target_pga_g") ? "target_pga_g" : "scale", e.what());
  } catch (const InputError& e) {
    t.fail("acceleration", e.what());
  }
}

/// A record file that fails to read: blamed on the factor when it reads unscaled, else on the file.
[[noreturn]] void fail_record_file(TableReader& t, const std::filesystem::path& path, const RecordOptions& o,
                                   const InputError& e) {
  if (t.has("scale") || t.has("target_pga_g")) {
    RecordOptions unscaled = o;
    unscaled.scale = 1.0;
    unscaled.target_pga_g.reset();
    bool reads_unscaled = false;
    try {
      (void)read_ground_motion(path, unscaled);
      reads_unscaled = true;
    } catch (const InputError&) {
    }
    if (reads_unscaled) t.fail(t.has("target_pga_g") ? "target_pga_g" : "scale", e.what());
  }
  t.fail("file", e.what());
}

/// The record file, read with its options (none when an ensemble supplies the records).
void read_record_file(TableReader& t, RecordOptions o, const std::filesystem::path& base_dir, const Origin& origin,
                      RunInput& run) {
  const std::string format = t.choice("format", names::record_format, std::string("auto"));
  if (t.has("dt")) {
    if (format != "single") t.fail("dt", "only for format = \"single\" (the other formats carry their times)");
    o.dt = t.positive("dt", t.number("dt"));
  } else if (format == "single") {
    t.fail_table_missing("dt", "missing key: dt (format = \"single\" has no times)");
  }
  if (t.has("column")) {
    if (format != "columns" && format != "auto") t.fail("column", "only for column files");
    o.column = bounded_integer(t.require("column"), 2, limits::column, "", [&](const std::string& m) {
      t.fail("column", m + " (the acceleration column; column 1 is time)");
    });
  }
  ExcitationInfo& info = run.excitation_info;
  // An ensemble names its records in [ensemble]: a file here only comes from one of its points.
  if (run.ensemble && !(t.has("file") && origin.reading == Reading::ensemble_record)) {
    if (t.has("file")) t.fail("file", "an ensemble takes its records from [ensemble]");
    info.record_units = o.units;
    info.record_options = o;
    return;
  }
  std::filesystem::path path(t.string("file"));
  if (path.is_relative()) path = base_dir / path;
  info.record_file = path;
  info.record_options = o;
  try {
    const GroundMotionRecord r = read_ground_motion(path, o);
    set_record_info(r, run);
    info.record_description = r.description;
  } catch (const InputError& e) {
    fail_record_file(t, path, o, e);
  }
  // The reader checks the file's numbers; the factor applied to them is this table's.
  if (!std::isfinite(info.record_pga_g) || !std::isfinite(info.record_scale)) {
    const char* key = t.has("target_pga_g") ? "target_pga_g" : t.has("scale") ? "scale" : "file";
    t.fail(key, fmt::format("{}: the record's peak {} g scaled by {} is beyond the range of a double",
                            path.string(), info.record_pga_file_g, info.record_scale));
  }
}

void read_excitation(TableReader& t, const Model& model, const std::filesystem::path& base_dir,
                     const Origin& origin, RunInput& run) {
  t.declare<keys::Excitation>();
  ExcitationInfo& info = run.excitation_info;
  info.kind = t.choice("kind", names::excitation_kind);
  info.omega1 = reference_frequency(model);
  if (info.kind == "harmonic") {
    read_harmonic(t, run);
  } else if (info.kind == "record") {
    const RecordOptions o = read_record_scaling(t, origin, run);
    if (t.has("acceleration")) {
      read_record_samples(t, o, run);
    } else {
      read_record_file(t, o, base_dir, origin, run);
    }
  } else {
    run.excitation = NoExcitation{};
  }
  t.finish(fmt::format("for kind = \"{}\"", info.kind));
}

/// The integration keys shared by every kind of analysis.
void read_integration(TableReader& t, AnalysisSettings& a) {
  TimeHistoryOptions& o = a.options;
  read_fields(t, o);
  if (const auto violation = o.lock_time_violation()) t.fail("lock_time", *violation);
}

/// Newmark brackets an event inside its step, in the time τ ∈ [0, h] since the step's start;
/// doubles there are spaced up to 2⁻⁵² h, and a bracket narrower than a few spacings cannot shrink
/// (the reason 1e-20 s "did not converge"). So event_tolerance ≥ event_tolerance_ulps · 2⁻⁵² · h
/// for the longest step h of the run. `what` says which step that is.
void check_event_tolerance(TableReader& analysis, const TimeHistoryOptions& o, double longest_step,
                           const std::string& what) {
  const double finest = limits::event_tolerance_ulps * std::numeric_limits<double>::epsilon() * longest_step;
  if (!(o.event_tolerance >= finest)) {
    analysis.fail("event_tolerance",
                  fmt::format("{} s is finer than doubles can resolve within a step of {} s ({}): at least "
                              "{:.3g} s ({} × 2⁻⁵² × the step)",
                              o.event_tolerance, longest_step, what, finest, limits::event_tolerance_ulps));
  }
}

/// A time history's work: steps and history rows within analysis.max_steps, event times resolvable.
/// `source` says where the duration comes from when it is not the key itself.
void check_time_history_work(TableReader& analysis, const AnalysisSettings& a, const std::string& source) {
  const double steps = std::ceil(a.duration / a.options.dt);
  // Blamed on the duration when an override set it, else on dt (the duration may be a record's).
  const char* key = analysis.has("duration") && analysis.overridden("duration") ? "duration" : "dt";
  if (!(steps <= a.max_steps)) {
    analysis.fail(key, fmt::format("dt = {} s over the duration {} s{} makes {:.4g} steps, more than analysis.max_steps "
                                    "= {:.4g}: give a longer dt, a shorter duration, or a larger max_steps",
                                    a.options.dt, a.duration, source, steps, a.max_steps));
  }
  const double rows = std::floor(a.duration / a.output_dt);
  if (!(rows <= a.max_steps)) {
    analysis.fail("output_dt", fmt::format("{} s over the duration {} s{} makes {:.4g} rows of history.csv, more "
                                           "than analysis.max_steps = {:.4g}",
                                           a.output_dt, a.duration, source, rows, a.max_steps));
  }
  check_event_tolerance(analysis, a.options, a.options.dt, "analysis.dt");
}

void read_time_history(TableReader& t, AnalysisSettings& a) {
  // Without a duration a record runs to its last sample (checked once the record is read).
  a.duration = t.has("duration") ? t.positive("duration", t.number("duration")) : 0.0;
  TimeHistoryOptions& o = a.options;
  o.dt = t.positive("dt", t.number("dt"));  // checked against the duration once that is known
  a.output_dt = t.number_or("output_dt", o.dt);
  const double ratio = a.output_dt / o.dt;
  if (!(a.output_dt > 0) || std::abs(ratio - std::round(ratio)) > 1e-9 * ratio || ratio < 0.5) {
    t.fail("output_dt", fmt::format("{} s must be a positive multiple of dt = {} s", a.output_dt, o.dt));
  }
  read_integration(t, a);
  if (!(o.event_tolerance < o.dt)) {
    t.fail("event_tolerance", fmt::format("{} s must be smaller than dt = {} s", o.event_tolerance, o.dt));
  }
}

/// `band = [ratio_min, ratio_max]`: the ω̄/ω₁ range that an FRF objective looks at.
void read_band(TableReader& t, PointRun each, double& lo, double& hi) {
  if (!t.has("band")) return;
  if (each != PointRun::frf) t.fail("band", "only for each = \"frf\"");
  const std::vector<double> band = t.numbers("band");
  if (band.size() != 2 || !(band[0] > 0) || !(band[1] > band[0])) {
    t.fail("band", "expected [ratio_min, ratio_max] with 0 < ratio_min < ratio_max");
  }
  lo = band[0];
  hi = band[1];
}

FrfSettings read_frf(TableReader& t, TableReader& analysis, const Model& model, const AnalysisSettings& a) {
  FrfSettings f;
  read_fields(t, f);
  if (a.kind == AnalysisKind::continuation) {
    // [frf] gives a parameter continuation its forcing and options: one frequency, shot orbits.
    if (t.has("method") && f.method != FrfMethod::continuation) {
      t.fail("method", "analysis.kind = \"continuation\" shoots and continues orbits: \"continuation\", or leave it out");
    }
    if (t.has("sweep")) t.fail("sweep", "only for analysis.kind = \"frf\" with method = \"simulation\"");
    f.method = FrfMethod::continuation;
  } else if (a.kind == AnalysisKind::frf && !t.has("method")) {
    // Continuation is the default where it applies: the exact integrator, no sweep up or down
    // asked for, and a model whose state at t = 0 is its floors' (docs/input.md).
    const bool applies = a.options.integrator == Integrator::exact && f.sweep == SweepMode::from_rest &&
                         periodic_orbits_refusal(model, a.options).empty();
    f.method = applies ? FrfMethod::continuation : FrfMethod::simulation;
  }
  const bool listed = t.has("ratios");
  const bool range = t.has("ratio_min") || t.has("ratio_max") || t.has("points");
  if (listed == range) {
    t.fail_table("give either ratios = [...] or ratio_min, ratio_max and points");
  }
  if (listed) {
    f.ratios = t.numbers("ratios");
    for (const double r : f.ratios) {
      if (!(r > 0)) t.fail("ratios", fmt::format("every ratio must be > 0 (got {})", r));
    }
  } else {
    const double lo = t.positive("ratio_min", t.number("ratio_min"));
    const double hi = t.positive("ratio_max", t.number("ratio_max"));
    const int n = t.integer("points", 1, limits::frf_points);
    if (!(hi >= lo) || (n > 1 && hi == lo)) t.fail("ratio_max", "must be larger than ratio_min");
    for (int i = 0; i < n; ++i) f.ratios.push_back(n == 1 ? lo : lo + (hi - lo) * i / (n - 1));
  }
  std::sort(f.ratios.begin(), f.ratios.end());
  SteadyStateOptions& s = f.steady;
  read_fields(t, s);
  if (s.max_periods < 2 * s.max_periodicity + 2) {
    t.fail("max_periods", "must be at least 2 × max_periodicity + 2");
  }
  // The shortest step: the highest frequency's period over steps_per_period.
  const double shortest = 2 * std::numbers::pi / (f.ratios.back() * reference_frequency(model)) /
                          s.steps_per_period;
  if (!(a.options.event_tolerance < shortest)) {
    t.fail("steps_per_period", fmt::format("gives steps of {} s at the highest frequency, not longer "
                                           "than analysis.event_tolerance", shortest));
  }
  // The most work the points may take: every point runs to max_periods without settling.
  const double branches = f.sweep == SweepMode::both ? 2.0 : 1.0;
  const double periods = static_cast<double>(s.max_periods) + s.window_periods;
  const double steps = branches * static_cast<double>(f.ratios.size()) * periods * s.steps_per_period;
  if (!(steps <= a.max_steps)) {
    t.fail_table(fmt::format("{} frequencies × {} branch(es) × ({} max_periods + {} window_periods) × {} "
                             "steps_per_period may take {:.4g} steps, more than analysis.max_steps = {:.4g}: "
                             "give fewer points, periods or steps, or a larger analysis.max_steps",
                             f.ratios.size(), branches, s.max_periods, s.window_periods, s.steps_per_period,
                             steps, a.max_steps));
  }
  // The lowest frequency has the longest steps.
  const double longest = 2 * std::numbers::pi / (f.ratios.front() * reference_frequency(model)) / s.steps_per_period;
  if (!std::isfinite(longest)) {
    t.fail(listed ? "ratios" : "ratio_min",
           fmt::format("{} is so low that the forcing period is not finite", f.ratios.front()));
  }
  check_event_tolerance(analysis, a.options, longest,
                        fmt::format("a forcing period at ω̄/ω₁ = {} over frf.steps_per_period", f.ratios.front()));
  if (t.has("continuation")) {
    if (f.method != FrfMethod::continuation) t.fail("continuation", "only for method = \"continuation\"");
    TableReader c = t.table("continuation");
    c.declare<ContinuationOptions, ShootingOptions>();
    read_fields(c, f.continuation);
    read_fields(c, f.shooting);
    if (f.continuation.min_step > f.continuation.initial_step) c.fail("min_step", "must not exceed initial_step");
    if (f.continuation.initial_step > f.continuation.max_step) c.fail("initial_step", "must not exceed max_step");
    c.finish();
  }
  if (a.kind == AnalysisKind::continuation && f.ratios.size() != 1) {
    t.fail(listed ? "ratios" : "points", fmt::format("analysis.kind = \"continuation\" runs at one forcing frequency: "
                                                     "ratios = [ω̄/ω₁] (got {} ratios)", f.ratios.size()));
  }
  if (f.method == FrfMethod::continuation && f.sweep != SweepMode::from_rest) {
    t.fail("sweep", "a sweep up or down is the brute force's (method = \"simulation\"): continuation follows every "
                    "branch both ways");
  }
  if (f.method == FrfMethod::continuation && a.options.integrator != Integrator::exact) {
    analysis.fail("integrator", "must be \"exact\" for continuation: the map's Jacobian comes from the exact "
                                "integrator's propagators and saltation matrices");
  }
  if (t.has("lanes") && (f.method != FrfMethod::simulation || f.sweep != SweepMode::from_rest ||
                         a.options.integrator != Integrator::newmark)) {
    t.fail("lanes", "only for method = \"simulation\" with sweep = \"rest\" and analysis.integrator = \"newmark\": "
                    "the points stepped together in lockstep");
  }
  if (f.method == FrfMethod::continuation && a.options.separation == SeparationCriterion::force) {
    analysis.fail("separation", "must be \"displacement\" for frf.method = \"continuation\": under the force "
                                "criterion a separated element's free end relaxes with a memory the floors' state "
                                "does not hold");
  }
  t.finish();
  return f;
}

/// `min` and `max` given, `min` < `max`, and `start` (if given) in [min, max]: a range of a study
/// axis, of an optimiser's variable or of a continued parameter.
void check_range(TableReader& t, double min, double max, std::optional<double> start = std::nullopt) {
  if (!t.has("min")) t.require("min");
  if (!t.has("max")) t.require("max");
  if (!(max > min)) t.fail("max", "must be larger than min");
  if (start && !(*start >= min && *start <= max)) t.fail("start", "must lie in [min, max]");
}

/// A value of a study axis: a number (finite), a string or a yes/no.
SettingValue axis_value(TableReader& t, std::string_view key, const toml::node& node) {
  if (node.is_floating_point() && !std::isfinite(*node.value<double>())) t.fail(key, "values must be finite");
  if (node.is_array() || node.is_table() || node.is_date() || node.is_time() || node.is_date_time()) {
    t.fail(key, fmt::format("values must be numbers, strings or booleans, not a {}", type_name(node)));
  }
  return from_node(node, [&](const std::string& m) { t.fail(key, m); });
}

StudySettings read_study(TableReader& t) {
  StudySettings s;
  read_fields(t, s);
  if (s.sampling == Sampling::random) {
    s.samples = t.integer("samples", 1, limits::study_points);
    s.seed = t.optional_integer<unsigned>("seed", 0, limits::seed).value_or(s.seed);
  }
  read_band(t, s.each, s.band_min, s.band_max);
  std::size_t list_length = 0;
  double grid_points = 1;
  for (TableReader& p : t.tables("parameter")) {
    p.declare<StudyParameter>();
    StudyParameter param;
    read_fields(p, param);
    param.where = p.where("key");
    for (const StudyParameter& seen : s.parameters) {
      if (seen.key == param.key) p.fail("key", fmt::format("'{}' is varied twice", param.key));
    }
    const bool has_values = p.has("values");
    const bool has_range = p.has("min") || p.has("max") || p.has("points");
    if (s.sampling == Sampling::random) {
      if (has_values || p.has("points")) p.fail_table("random sampling takes min and max (and scale), not values or points");
    } else if (has_values == has_range) {
      p.fail_table("give either values = [...] or min, max and points");
    }
    if (s.sampling == Sampling::list && !has_values) p.fail_table("list sampling takes values = [...]");
    if (has_values) {
      const toml::node& node = p.require("values");
      const toml::array* values = node.as_array();
      if (values == nullptr || values->empty()) p.fail("values", "expected a non-empty array");
      for (std::size_t i = 0; i < values->size(); ++i) param.values.push_back(axis_value(p, "values", (*values)[i]));
      if (s.sampling == Sampling::list) {
        if (list_length != 0 && param.values.size() != list_length) {
          p.fail("values", fmt::format("list sampling needs the same number of values for every parameter "
                                       "({} here, {} before)", param.values.size(), list_length));
        }
        list_length = param.values.size();
      }
    } else {
      check_range(p, param.min, param.max);
      if (param.log && !(param.min > 0)) p.fail("min", "must be > 0 on a log scale");
      if (s.sampling == Sampling::grid && !p.has("points")) p.require("points");
    }
    // A grid has the product of its axes' points: bounded before study_points() lists them.
    if (s.sampling == Sampling::grid) {
      grid_points *= static_cast<double>(has_values ? param.values.size() : static_cast<std::size_t>(param.points));
      if (grid_points > limits::study_points) {
        p.fail(has_values ? "values" : "points",
               fmt::format("the grid has {:.4g} points with this parameter: at most {}", grid_points, limits::study_points));
      }
    } else if (s.sampling == Sampling::list && param.values.size() > static_cast<std::size_t>(limits::study_points)) {
      p.fail("values", fmt::format("{} values: at most {}", param.values.size(), limits::study_points));
    }
    p.finish();
    s.parameters.push_back(std::move(param));
  }
  t.finish();
  return s;
}

/// [parameter]: a key of the model (the continuation rebuilds the model at each value) and its range.
ContinuedParameter read_continued_parameter(TableReader& t) {
  ContinuedParameter c;
  read_fields(t, c);
  c.where = t.where("key");
  const std::string_view root = std::string_view(c.key).substr(0, c.key.find_first_of(".["));
  if (root != "model" && root != "frames" && root != "gap_elements") {
    t.fail("key", fmt::format("'{}' is not a key of the model ([model], [[frames]] or [gap_elements]): the "
                              "continuation follows orbits as the model changes", c.key));
  }
  check_range(t, c.min, c.max, c.start);
  c.start = c.start.value_or(c.min);
  t.finish();
  return c;
}

OptimizeConstraint read_constraint(TableReader& c) {
  c.declare<OptimizeConstraint>();
  OptimizeConstraint constraint;
  read_fields(c, constraint);
  constraint.where = c.where("metric");
  if (!constraint.min && !constraint.max) c.fail("metric", "needs a limit: min, max or both");
  if (constraint.min && constraint.max && !(*constraint.max > *constraint.min)) c.fail("max", "must be larger than min");
  c.finish();
  return constraint;
}

/// [optimize.pareto]; its objective defaults to the optimisation's.
ParetoSettings read_pareto(TableReader& p, const OptimizeSettings& o) {
  p.declare<ParetoSettings>();
  ParetoSettings pareto;
  pareto.objective = o.objective;
  read_fields(p, pareto);
  pareto.where = p.where("metric");
  if (p.has("objective")) {
    pareto.objective_where = p.where("objective");
    if (pareto.objective == objective_alias) pareto.objective = "max_peak_V_W";
  }
  if (pareto.metric == pareto.objective) {
    p.fail("metric", fmt::format("is the front's objective, {}: name a second figure", pareto.objective));
  }
  if (p.has("limits") == p.has("points")) p.fail("metric", "needs either limits or points");
  p.finish();
  return pareto;
}

OptimizeVariable read_variable(TableReader& v, const std::vector<OptimizeVariable>& seen) {
  v.declare<OptimizeVariable>();
  OptimizeVariable var;
  read_fields(v, var);
  var.where = v.where("key");
  for (const OptimizeVariable& other : seen) {
    if (other.key == var.key) v.fail("key", fmt::format("'{}' is a variable twice", var.key));
  }
  check_range(v, var.min, var.max, var.start);
  if (var.log && !(var.min > 0)) v.fail("min", "must be > 0 with scale = \"log\" (NLopt searches log(value))");
  v.finish();
  return var;
}

OptimizeSettings read_optimize(TableReader& t) {
  OptimizeSettings o;
  read_fields(t, o);
  read_band(t, o.each, o.band_min, o.band_max);
  if (o.global_algorithm != "none" && o.global_algorithm.rfind("G", 0) != 0) {
    t.fail("global", fmt::format("\"{}\" is not a global NLopt algorithm (GN_… or GD_…) or \"none\"", o.global_algorithm));
  }
  if (o.local_algorithm != "none" && o.local_algorithm.rfind("L", 0) != 0) {
    t.fail("local", fmt::format("\"{}\" is not a local NLopt algorithm (LN_… or LD_…) or \"none\"", o.local_algorithm));
  }
  if (o.global_algorithm == "none" && o.local_algorithm == "none") {
    t.fail(t.has("local") ? "local" : "global", "both stages are \"none\": nothing would be optimised");
  }
  if (t.has("objective")) {
    o.objective_where = t.where("objective");
    if (o.objective == objective_alias) o.objective = "max_peak_V_W";
  }
  for (TableReader& c : t.has("constraint") ? t.tables("constraint") : std::vector<TableReader>{}) {
    o.constraints.push_back(read_constraint(c));
  }
  if (std::optional<TableReader> p = t.optional_table("pareto")) o.pareto = read_pareto(*p, o);
  for (TableReader& v : t.tables("variable")) o.variables.push_back(read_variable(v, o.variables));
  t.finish();
  return o;
}

/// `*` and `?` wildcards against a whole file name.
bool matches(const std::string& pattern, const std::string& name) {
  std::size_t p = 0, n = 0, star = std::string::npos, mark = 0;
  while (n < name.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == name[n])) {
      ++p;
      ++n;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      mark = n;
    } else if (star != std::string::npos) {
      p = star + 1;
      n = ++mark;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

/// [ensemble.scaling]: every key that does not apply to its kind (or design) is refused.
EnsembleScaling read_scaling(TableReader& t, int frames) {
  EnsembleScaling s;
  read_fields(t, s);
  read_fields(t, s.spectrum);
  if (s.frame > frames) t.fail("frame", fmt::format("the model has {} frame(s)", frames));
  const auto only = [&](std::initializer_list<const char*> keys, const std::string& rule) {
    for (const char* key : keys) {
      if (t.has(key)) t.fail(key, rule);
    }
  };
  if (auto v = t.optional_number("target_g")) s.target_g = t.positive("target_g", *v);
  // An oscillator's sub-steps grow as 1/T over the record: below a millisecond they would run to
  // billions (and a period of 1e-20 s past what a step count can hold).
  const auto oscillator_period = [&](const char* key) -> std::optional<double> {
    const std::optional<double> v = t.optional_number(key);
    if (v && !(*v >= kShortestSpectrumPeriod && *v <= kLongestSpectrumPeriod)) {
      t.fail(key, fmt::format("must be in [{}, {}] s (got {})", kShortestSpectrumPeriod, kLongestSpectrumPeriod, *v));
    }
    return v;
  };
  s.period = oscillator_period("period");
  s.period_min = oscillator_period("period_min");
  s.period_max = oscillator_period("period_max");
  if (t.has("design")) {
    const std::string design = t.choice("design", names::design_spectrum);
    if (design == tabulated_design_name) {
      only({"ground_type", "ag_g"}, "only for design = \"ec8_type1\" or \"ec8_type2\"");
      TabulatedSpectrum table;
      const std::vector<std::vector<double>> rows = t.number_rows("table");
      s.table_g = rows;
      for (std::size_t i = 0; i < rows.size(); ++i) {
        if (rows[i].size() != 2) t.fail("table", fmt::format("row {}: expected [period in s, S_a in g]", i + 1));
        table.period.push_back(rows[i][0]);
        table.acceleration.push_back(rows[i][1] * standard_gravity);
      }
      try {
        validate(DesignSpectrum{table});
      } catch (const std::invalid_argument& e) {
        t.fail("table", e.what());
      }
      s.design = table;
    } else {
      only({"table"}, "only for design = \"table\"");
      Eurocode8Spectrum ec8;
      for (const auto& [name, type] : eurocode8_type_names) {
        if (name == design) ec8.type = type;
      }
      const std::string ground = t.choice("ground_type", names::ground_type);
      for (const auto& [name, value] : ground_type_names) {
        if (name == ground) ec8.ground = value;
      }
      s.ag_g = t.positive("ag_g", t.number("ag_g"));
      ec8.ag = s.ag_g * standard_gravity;
      ec8.damping = s.spectrum.damping;
      s.design = ec8;
    }
  } else {
    only({"ground_type", "ag_g", "table"}, "only with design");
  }
  switch (s.kind) {
    case ScalingKind::pga:
      if (!s.target_g) t.fail_table_missing("target_g", "missing key: target_g (the peak ground acceleration each record is scaled to)");
      only({"design", "period", "frame", "period_min", "period_max", "match", "fraction", "points"}, "not for kind = \"pga\"");
      break;
    case ScalingKind::sa:
      if (s.target_g.has_value() == s.design.has_value()) {
        t.fail_table("kind = \"sa\" takes its target from target_g or from a design spectrum: give exactly one");
      }
      if (s.period && t.has("frame")) t.fail("frame", "not with period (which it would set)");
      only({"period_min", "period_max", "match", "fraction", "points"}, "not for kind = \"sa\" (one period)");
      break;
    case ScalingKind::spectrum:
      if (!s.design) t.fail_table_missing("design", "missing key: design (the spectrum the suite's mean is matched to)");
      only({"target_g", "period"}, "not for kind = \"spectrum\" (the design spectrum is the target over a range)");
      if (s.period_min.has_value() != s.period_max.has_value()) {
        t.fail(s.period_min ? "period_min" : "period_max", "give both ends of the range, or neither ([0.2 T₁, 2 T₁])");
      }
      if (s.period_min && !(*s.period_min < *s.period_max)) t.fail("period_min", "must be below period_max");
      if (s.period_min && (t.has("frame"))) t.fail("frame", "not with period_min and period_max (which it would set)");
      if (t.has("fraction") && s.match != SuiteMatch::not_below) t.fail("fraction", "only for match = \"not_below\"");
      break;
  }
  t.finish("for this kind of scaling");
  return s;
}

EnsembleSettings read_ensemble(TableReader& t, const std::filesystem::path& base_dir, int frames) {
  EnsembleSettings e;
  const auto resolve = [&](const std::string& file) {
    std::filesystem::path p(file);
    // Absolute, so that a point's excitation.file is not resolved a second time.
    return std::filesystem::absolute(p.is_relative() ? base_dir / p : p).lexically_normal();
  };
  const bool listed = t.has("records"), folder = t.has("folder");
  if (listed == folder) t.fail_table("give either records = [...] or folder (and pattern)");
  if (listed) {
    const toml::node& node = t.require("records");
    const toml::array* records = node.as_array();
    if (records == nullptr || records->empty()) t.fail("records", "expected a non-empty array of file names");
    for (std::size_t i = 0; i < records->size(); ++i) {
      const toml::node& item = (*records)[i];
      if (!item.is_string()) t.fail("records", fmt::format("item {} must be a file name (string)", i + 1));
      e.records.push_back(resolve(*item.value<std::string>()));
    }
    if (t.has("pattern")) t.fail("pattern", "only with folder");
  } else {
    const std::filesystem::path dir = resolve(t.string("folder"));
    const std::string pattern = t.string_or("pattern", "*");
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) t.fail("folder", fmt::format("{} is not a folder", dir.string()));
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
      if (entry.is_regular_file() && matches(pattern, entry.path().filename().string())) e.records.push_back(entry.path());
    }
    std::sort(e.records.begin(), e.records.end());
    if (e.records.empty()) t.fail("pattern", fmt::format("no file in {} matches \"{}\"", dir.string(), pattern));
  }
  for (const std::filesystem::path& r : e.records) {
    if (!std::filesystem::is_regular_file(r)) t.fail(listed ? "records" : "folder", fmt::format("{}: no such file", r.string()));
  }
  read_fields(t, e);
  if (t.has("scaling")) {
    TableReader scaling = t.table("scaling");
    scaling.declare<EnsembleScaling, SpectrumOptions>();
    e.scaling = read_scaling(scaling, frames);
  }
  t.finish();
  return e;
}

/// The structure: [model] (dimensionless form) or [[frames]] with [gap_elements] (physical form).
void read_structure(TableReader& top, const Origin& origin, RunInput& run) {
  const bool dimensionless = top.has("model"), physical = top.has("frames");
  if (dimensionless && physical) {
    top.fail("frames", "give either [model] (dimensionless form) or [[frames]] (physical form), not both");
  }
  if (!dimensionless && !physical) {
    top.fail_table("missing the structure: [model] with [model.dimensionless], or [[frames]] and [gap_elements]");
  }
  // The readers check every key; a model they let through that the model's own validation still
  // refuses (a rule they miss) must stay an input error naming the file, never escape as a crash.
  try {
    if (dimensionless) {
      TableReader model = top.table("model");
      model.declare<keys::DimensionlessModel>();
      run.model = read_dimensionless(model, run);
    } else {
      run.model = read_physical(top, run);
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", origin.file, e.what()));
  }
}

/// [study], [optimize], [parameter] and [ensemble], each only for the kinds that read it; returns
/// what each of the run's points is once the study's or the optimiser's points are unfolded.
PointRun read_point_tables(TableReader& top, const std::filesystem::path& base_dir, RunInput& run) {
  const AnalysisKind kind = run.analysis.kind;
  PointRun each = kind == AnalysisKind::frf || kind == AnalysisKind::continuation ? PointRun::frf
                  : kind == AnalysisKind::ensemble ? PointRun::ensemble
                                                   : PointRun::time_history;
  if (kind == AnalysisKind::study) {
    TableReader study = top.table("study");
    study.declare<StudySettings>();
    run.study = read_study(study);
    each = run.study->each;
  } else if (kind == AnalysisKind::optimize) {
    TableReader optimize = top.table("optimize");
    optimize.declare<OptimizeSettings>();
    run.optimize = read_optimize(optimize);
    each = run.optimize->each;
  } else {
    for (const char* table : {"study", "optimize"}) {
      if (top.has(table)) top.fail(table, fmt::format("only for analysis.kind = \"{}\"", table));
    }
  }
  if (kind != AnalysisKind::continuation && top.has("parameter")) {
    top.fail("parameter", "only for analysis.kind = \"continuation\"");
  }
  if (each == PointRun::ensemble) {
    TableReader ensemble = top.table("ensemble");
    ensemble.declare<EnsembleSettings>();
    run.ensemble = read_ensemble(ensemble, base_dir, run.model.frame_count());
    each = PointRun::time_history;
  } else if (top.has("ensemble")) {
    top.fail("ensemble", "only for analysis.kind = \"ensemble\" or each = \"ensemble\"");
  }
  return each;
}

/// The time-history part of [analysis] and [excitation]; the duration defaults to the record's.
void read_time_history_run(TableReader& top, TableReader& analysis, const std::filesystem::path& base_dir,
                           const Origin& origin, RunInput& run) {
  read_time_history(analysis, run.analysis);
  TableReader excitation = top.table("excitation");
  read_excitation(excitation, run.model, base_dir, origin, run);
  if (run.ensemble && run.excitation_info.kind != "record") {
    excitation.fail("kind", "an ensemble runs records: kind = \"record\"");
  }
  if (run.analysis.duration == 0) {
    if (run.excitation_info.kind == "record" && run.excitation_info.record_duration > 0) {
      run.analysis.duration = run.excitation_info.record_duration;
    } else if (!run.ensemble) {
      analysis.fail_missing("duration", "only a record's length can stand in for it");
    }
  }
  if (run.analysis.duration > 0 && run.analysis.options.dt > run.analysis.duration) {
    analysis.fail("dt", fmt::format("{} s is longer than the duration {} s", run.analysis.options.dt,
                                    run.analysis.duration));
  }
  if (run.analysis.duration > 0) {
    const bool from_record = !analysis.has("duration");
    check_time_history_work(analysis, run.analysis,
                            from_record ? fmt::format(" (the length of {})", run.excitation_info.record_file.string())
                                        : std::string());
  }
  if (top.has("frf")) top.fail("frf", "only for analysis.kind = \"frf\"");
}

/// [frf] and, for a continuation, [parameter]: the harmonic excitation the response sets itself.
void read_frequency_response_run(TableReader& top, TableReader& analysis, RunInput& run) {
  read_integration(analysis, run.analysis);
  if (top.has("excitation")) {
    top.fail("excitation", "a frequency response sets its own harmonic excitation from [frf]");
  }
  if (top.has("initial")) top.fail("initial", "a frequency response starts from rest or from the previous point");
  TableReader frf = top.table("frf");
  frf.declare<FrfSettings, SteadyStateOptions>();
  run.frf = read_frf(frf, analysis, run.model, run.analysis);
  if (run.analysis.kind == AnalysisKind::continuation) {
    TableReader parameter = top.table("parameter");
    parameter.declare<ContinuedParameter>();
    run.parameter = read_continued_parameter(parameter);
  }
  run.excitation_info.kind = "harmonic";
  run.excitation_info.amplitude_g = run.frf->amplitude_g;
  run.excitation_info.omega1 = reference_frequency(run.model);
  // The band of the study and optimiser metrics defaults to the whole response.
  const auto whole_response_unless_given = [&](double& lo, double& hi) {
    if (lo == 0.0 && hi == 0.0) {
      lo = run.frf->ratios.front();
      hi = run.frf->ratios.back();
    }
  };
  if (run.study) whole_response_unless_given(run.study->band_min, run.study->band_max);
  if (run.optimize) whole_response_unless_given(run.optimize->band_min, run.optimize->band_max);
}

/// The initial displacements against each gap element's law: neighbours may not start overlapping.
void check_initial_overlap(const RunInput& run, const Origin& origin) {
  const auto& u0 = run.initial.displacement;
  for (const GapElement& g : run.model.gaps) {
    // A struck column's point interpolates the floors around it (the ground below a first floor).
    const auto at = [&](int frame, int floor, Side side) {
      const double above = u0[static_cast<std::size_t>(frame)][static_cast<std::size_t>(floor)];
      if (!g.column || g.column->struck != side) return above;
      const double below = floor == 0 ? 0.0 : u0[static_cast<std::size_t>(frame)][static_cast<std::size_t>(floor - 1)];
      return g.column->weight * above + (1 - g.column->weight) * below;
    };
    const double d = at(g.left_frame, g.floor, Side::left) - at(g.left_frame + 1, g.floor_right(), Side::right);
    try {  // the law says whether it can start at d (the simulator asks it the same)
      std::visit([&](const auto& law) { static_cast<void>(law.initial_mode(d)); }, g.law);
    } catch (const std::invalid_argument& e) {
      const std::string where = g.column ? "at the " + describe(g) : fmt::format("at floor {}", g.floor + 1);
      throw InputError(fmt::format("{}: initial.displacement: frames {} and {} overlap {} {}", origin.file,
                                   g.left_frame + 1, g.left_frame + 2, where, e.what()));
    }
  }
}

/// Cross-checks that need the whole model: its validation, the integrator's support of every law
/// (refused here, before the run makes its output folder, rather than by the simulator), the start.
void check_whole_run(const RunInput& run, const Origin& origin) {
  try {
    validate(run.model);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", origin.file, e.what()));
  }
  if (run.model.frame_count() == 0) return;
  const DofLayout layout(run.model);
  const IntegratorSupport support = supports(run.analysis.options.integrator, make_links(run.model, layout), layout);
  if (!support) throw InputError(fmt::format("{}: analysis.integrator: {}", origin.file, support.reason));
  if (!run.initial.displacement.empty()) check_initial_overlap(run, origin);
}

RunInput read_root(toml::table& root, Origin& origin, const std::filesystem::path& base_dir,
                   std::span<const Setting> settings) {
  for (const Setting& setting : settings) {
    const std::string path = apply_setting(root, setting, origin);
    origin.overrides[path] = &setting;
  }
  RunInput run;
  TableReader top(root, "", origin);
  top.declare<keys::File>();
  run.title = top.string_or("title", "");
  read_structure(top, origin, run);
  if (auto initial = top.optional_table("initial")) read_initial(*initial, run.model, run.initial);
  if (auto output = top.optional_table("output")) read_output(*output, run);
  TableReader analysis = top.table("analysis");
  analysis.declare<TimeHistoryOptions, AnalysisSettings>();
  read_fields(analysis, run.analysis);
  const AnalysisKind kind = run.analysis.kind;
  const std::string context = fmt::format("for kind = \"{}\"", to_string(kind));
  if (!run.channels.empty() && kind != AnalysisKind::time_history) {
    top.fail("output", fmt::format("only for kind = \"time_history\", whose history.csv it chooses (not {})", context));
  }
  if (read_point_tables(top, base_dir, run) == PointRun::time_history) {
    read_time_history_run(top, analysis, base_dir, origin, run);
  } else {
    read_frequency_response_run(top, analysis, run);
  }
  analysis.finish(context);
  top.finish();
  check_whole_run(run, origin);
  return run;
}

}  // namespace

std::string toml_float(double x) {
  std::string text = fmt::format("{}", x);
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

std::string to_text(const SettingValue& value) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, SettingArray>) {
          std::string text = "[";
          for (std::size_t i = 0; i < x->size(); ++i) text += (i == 0 ? "" : ", ") + to_text((*x)[i]);
          return text + "]";
        } else if constexpr (std::is_same_v<T, double>) {
          return toml_float(x);
        } else if constexpr (std::is_same_v<T, bool>) {
          return x ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::string>) {
          std::ostringstream out;
          out << toml::value<std::string>(x);
          return out.str();
        } else {
          return std::to_string(x);
        }
      },
      value.value);
}

bool operator==(const SettingValue& a, const SettingValue& b) {
  const auto* x = std::get_if<SettingArray>(&a.value);
  const auto* y = std::get_if<SettingArray>(&b.value);
  if (x != nullptr && y != nullptr) return **x == **y;
  return a.value == b.value;
}

Setting make_setting(std::string key, SettingValue value) {
  std::string text = key + "=" + to_text(value);
  return {std::move(key), std::move(value), std::move(text)};
}

Setting parse_setting(const std::string& text, const std::string& file) {
  const std::string at = setting_at(file, text);
  // The value is the rest of the argument: a line break would let it carry more keys (ignored).
  if (text.find_first_of("\n\r") != std::string::npos) {
    throw InputError(at + ": the override contains a line break");
  }
  for (const char c : text) {
    if (static_cast<unsigned char>(c) < 0x20 && c != '\t') {
      throw InputError(at + ": the override contains a control character");
    }
  }
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError(at + ": expected key=value");
  Setting setting;
  setting.key = text.substr(0, eq);
  setting.text = text;
  const std::string value = text.substr(eq + 1);
  std::string path;
  for (const KeySegment& seg : split_key(setting.key, at)) {
    path += (path.empty() ? "" : ".") + seg.key + (seg.index > 0 ? fmt::format("[{}]", seg.index) : "");
  }
  // A bare word (force, records/x.at2) is a string; anything that starts like a number, an
  // array, a table or a quoted string, or holds blanks or TOML punctuation, must be valid TOML,
  // so that 1e309 or [1, 2 is an error rather than a string.
  toml::table holder;
  try {
    holder = toml::parse("v = " + value);
  } catch (const toml::parse_error& e) {
    const bool bare = !value.empty() && value.find_first_of("0123456789+-[{\"'") != 0 &&
                      value.find_first_of(" \t#=,[]{}\"'") == std::string::npos;
    if (!bare) {
      throw InputError(fmt::format("{}: {}: the value is not valid TOML ({})", at, path, e.description()));
    }
    setting.value = {value};
    return setting;
  }
  if (holder.size() != 1 || !holder.contains("v")) {
    throw InputError(fmt::format("{}: {}: one value expected", at, path));
  }
  setting.value = from_node(*holder.get("v"), [&](const std::string& m) {
    throw InputError(fmt::format("{}: {}: {}", at, path, m));
  });
  return setting;
}

namespace {

toml::array number_array(std::span<const double> values) {
  toml::array a;
  for (const double v : values) a.push_back(v);
  return a;
}

/// Writes every declared field of S (fields.hpp) that is not read by rules of its own.
template <Configuration S>
void write_fields(toml::table& t, const S& s) {
  for_each_field<S>([&](const auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (is_number_field<Field> || is_bool_field<Field>) {
      t.insert_or_assign(field.key, s.*field.member);
    } else if constexpr (is_integer_field<Field>) {
      t.insert_or_assign(field.key, static_cast<std::int64_t>(s.*field.member));
    } else if constexpr (is_choice_field<Field>) {
      t.insert_or_assign(field.key, std::string(field.name_of(s.*field.member)));
    } else if constexpr (is_text_field<Field>) {
      if (!(s.*field.member).empty()) t.insert_or_assign(field.key, s.*field.member);
    } else if constexpr (is_optional_number_field<Field>) {
      if (s.*field.member) t.insert_or_assign(field.key, *(s.*field.member));
    } else if constexpr (is_number_list_field<Field>) {
      if (!(s.*field.member).empty()) t.insert_or_assign(field.key, number_array(s.*field.member));
    }
  });
}

toml::array number_rows(const std::vector<std::vector<double>>& rows) {
  toml::array a;
  for (const auto& row : rows) a.push_back(number_array(row));
  return a;
}

/// [ensemble.scaling] with the keys of its kind only (the reader refuses the others).
toml::table scaling_table(const EnsembleScaling& s) {
  toml::table t;
  t.insert("kind", std::string(name_in(scaling_kind_names, s.kind)));
  write_fields(t, s.spectrum);
  if (s.target_g) t.insert("target_g", *s.target_g);
  if (s.design) {
    t.insert("design", std::string(design_name(*s.design)));
    if (std::holds_alternative<TabulatedSpectrum>(*s.design)) {
      t.insert("table", number_rows(s.table_g));
    } else {
      t.insert("ground_type", std::string(name_in(ground_type_names, std::get<Eurocode8Spectrum>(*s.design).ground)));
      t.insert("ag_g", s.ag_g);
    }
  }
  if (s.kind == ScalingKind::sa) {
    if (s.period) {
      t.insert("period", *s.period);
    } else {
      t.insert("frame", static_cast<std::int64_t>(s.frame));
    }
  }
  if (s.kind == ScalingKind::spectrum) {
    if (s.period_min) {
      t.insert("period_min", *s.period_min);
      t.insert("period_max", *s.period_max);
    } else {
      t.insert("frame", static_cast<std::int64_t>(s.frame));
    }
    t.insert("match", std::string(name_in(suite_match_names, s.match)));
    if (s.match == SuiteMatch::not_below) t.insert("fraction", s.fraction);
    t.insert("points", static_cast<std::int64_t>(s.points));
  }
  return t;
}

toml::table model_tables(const RunInput& in, toml::table& root) {
  toml::array frames;
  for (const Frame& f : in.model.frames) {
    toml::table t;
    if (!f.name.empty()) t.insert("name", f.name);
    t.insert("storeys", f.storeys());
    for_each_field<Frame>([&](const auto& field) {
      const std::vector<double>& values = f.*field.member;
      if (!values.empty()) t.insert(field.key, number_array(values));  // empty: not given
    });
    if (!is_default(f.storey_law)) t.insert("storey_law", std::string(key_of(f.storey_law)));
    for_each_storey_parameter(f.storey_law, [&](const auto& field, const std::vector<double>& values) {
      if (!values.empty()) t.insert(field.key, number_array(values));  // none: the law's defaults
    });
    frames.push_back(std::move(t));
  }
  root.insert("frames", std::move(frames));
  toml::table gaps;
  if (in.model.gaps.empty()) return gaps;
  const auto joint = [&](std::size_t k) {
    return in.joint_widths.empty() ? in.model.gaps[k].gap() : in.joint_widths[k];
  };
  // The law's name, when it is not the one the table would have without it, and its values.
  const auto put_law = [](toml::table& t, const GapLaw& law, std::string_view inherited) {
    if (key_of(law) != inherited) t.insert("law", std::string(key_of(law)));
    std::visit([&](const auto& l) { write_fields(t, l.parameters); }, law);
  };

  // The first element's properties for all, then an override for every element that differs
  // from them or stands in a wider joint: each keeps the exact values it ran with.
  // A joint as wide as the element's gap is the default (an explicit one must also hold the
  // shortening): it is written only when it is wider.
  const auto put_joint = [&](toml::table& t, std::size_t k) {
    if (joint(k) != in.model.gaps[k].gap()) t.insert("joint_width", joint(k));
  };
  put_law(gaps, in.model.gaps.front().law, gap_law_names.front());  // no joint: overrides inherit it
  if (!in.model.facing.empty()) {
    // Pairs by height or listed: written as the list they made.
    gaps.insert("pairing", "listed");
    toml::array pairs;
    for (const FloorPair& p : in.model.facing) {
      toml::table pair{{"frames", toml::array{p.left_frame + 1, p.left_frame + 2}}};
      if (p.column) {  // the slab's side: its height places it on the column again
        const bool left_slab = p.column->struck == Side::right;
        pair.insert("slab", toml::array{p.left_frame + (left_slab ? 1 : 2), (left_slab ? p.left_floor : p.right_floor) + 1});
      } else {
        pair.insert("floors", toml::array{p.left_floor + 1, p.right_floor + 1});
      }
      pairs.push_back(std::move(pair));
    }
    gaps.insert("pair", std::move(pairs));
  }
  toml::array overrides;
  for (std::size_t k = 0; k < in.model.gaps.size(); ++k) {
    const GapElement& g = in.model.gaps[k];
    if (g.law == in.model.gaps.front().law && joint(k) == g.gap()) continue;
    toml::table o;
    o.insert("frames", toml::array{g.left_frame + 1, g.left_frame + 2});
    o.insert("floor", g.floor + 1);
    const auto sharing = std::count_if(in.model.gaps.begin(), in.model.gaps.end(), [&](const GapElement& e) {
      return e.left_frame == g.left_frame && e.floor == g.floor;
    });
    if (sharing > 1) o.insert("right_floor", g.floor_right() + 1);
    put_law(o, g.law, key_of(in.model.gaps.front().law));
    put_joint(o, k);
    overrides.push_back(std::move(o));
  }
  if (!overrides.empty()) gaps.insert("override", std::move(overrides));
  return gaps;
}

toml::table excitation_table(const RunInput& in) {
  const ExcitationInfo& info = in.excitation_info;
  toml::table e;
  e.insert("kind", info.kind);
  if (info.kind == "harmonic") {
    e.insert("amplitude_g", info.amplitude_g);
    e.insert("omega", info.omega);
  } else if (info.kind == "record") {
    const RecordOptions& o = info.record_options;
    e.insert("format", std::string(name_in(record_format_names, o.format)));
    if (!o.units.empty()) e.insert("units", o.units);
    if (o.target_pga_g) {
      e.insert("target_pga_g", *o.target_pga_g);
    } else if (!(in.ensemble && in.ensemble->scaling)) {  // [ensemble.scaling] gives each its own
      e.insert("scale", o.scale);
    }
    if (!info.record_samples.empty()) {
      e.erase("format");
      e.insert("dt", o.dt);
      e.insert("acceleration", number_array(info.record_samples));
      return e;
    }
    if (o.format == RecordFormat::single) e.insert("dt", o.dt);
    if (o.column != RecordOptions{}.column) e.insert("column", o.column);
    if (!in.ensemble) e.insert("file", std::filesystem::absolute(info.record_file).lexically_normal().string());
  }
  return e;
}

toml::array band(double lo, double hi) { return toml::array{lo, hi}; }

toml::table study_table(const StudySettings& s) {
  toml::table t;
  write_fields(t, s);
  if (s.sampling == Sampling::random) {
    t.insert("samples", s.samples);
    t.insert("seed", static_cast<std::int64_t>(s.seed));
  }
  if (s.each == PointRun::frf) t.insert("band", band(s.band_min, s.band_max));
  toml::array parameters;
  for (const StudyParameter& p : s.parameters) {
    toml::table axis{{"key", p.key}};
    if (p.values.empty()) {
      axis.insert("min", p.min);
      axis.insert("max", p.max);
      axis.insert("scale", p.log ? "log" : "linear");
      if (s.sampling == Sampling::grid) axis.insert("points", p.points);
    } else {
      toml::array values;
      for (const SettingValue& v : p.values) with_node(v, [&](auto&& node) { values.push_back(node); });
      axis.insert("values", std::move(values));
    }
    parameters.push_back(std::move(axis));
  }
  t.insert("parameter", std::move(parameters));
  return t;
}

toml::table optimize_table(const OptimizeSettings& o) {
  toml::table t{{"global", o.global_algorithm}, {"local", o.local_algorithm}, {"objective", o.objective}};
  write_fields(t, o);
  if (!o.constraints.empty()) {
    toml::array constraints;
    for (const OptimizeConstraint& c : o.constraints) {
      toml::table constraint{{"metric", c.metric}};
      if (c.min) constraint.insert("min", *c.min);
      if (c.max) constraint.insert("max", *c.max);
      constraints.push_back(std::move(constraint));
    }
    t.insert("constraint", std::move(constraints));
  }
  if (o.pareto) {
    toml::table pareto{{"objective", o.pareto->objective}, {"metric", o.pareto->metric}};
    if (o.pareto->limits.empty()) {
      pareto.insert("points", o.pareto->points);
    } else {
      pareto.insert("limits", number_array(o.pareto->limits));
    }
    t.insert("pareto", std::move(pareto));
  }
  if (o.each == PointRun::frf) t.insert("band", band(o.band_min, o.band_max));
  toml::array variables;
  for (const OptimizeVariable& v : o.variables) {
    toml::table variable{{"key", v.key}, {"min", v.min}, {"max", v.max}};
    if (v.start) variable.insert("start", *v.start);
    if (v.log) variable.insert("scale", "log");
    variables.push_back(std::move(variable));
  }
  t.insert("variable", std::move(variables));
  return t;
}

}  // namespace

std::string to_toml(const RunInput& in) {
  toml::table root;
  if (!in.title.empty()) root.insert("title", in.title);
  toml::table gaps = model_tables(in, root);
  if (!gaps.empty()) root.insert("gap_elements", std::move(gaps));
  const AnalysisKind kind = in.analysis.kind;
  toml::table analysis;
  write_fields(analysis, in.analysis);
  write_fields(analysis, in.analysis.options);
  if (in.frf) {
    toml::table f;
    write_fields(f, *in.frf);
    write_fields(f, in.frf->steady);
    f.insert("ratios", number_array(in.frf->ratios));
    if (in.frf->method == FrfMethod::continuation) {
      toml::table c;
      write_fields(c, in.frf->continuation);
      write_fields(c, in.frf->shooting);
      f.insert("continuation", std::move(c));
    }
    root.insert("frf", std::move(f));
  } else {
    if (in.analysis.duration > 0) analysis.insert("duration", in.analysis.duration);
    analysis.insert("dt", in.analysis.options.dt);
    analysis.insert("output_dt", in.analysis.output_dt);
    root.insert("excitation", excitation_table(in));
    if (!in.initial.displacement.empty() || !in.initial.velocity.empty()) {
      toml::table initial;
      if (!in.initial.displacement.empty()) initial.insert("displacement", number_rows(in.initial.displacement));
      if (!in.initial.velocity.empty()) initial.insert("velocity", number_rows(in.initial.velocity));
      root.insert("initial", std::move(initial));
    }
  }
  root.insert("analysis", std::move(analysis));
  if (!in.channels.empty()) {
    toml::array channels;
    for (const std::string& c : in.channels) channels.push_back(c);
    root.insert("output", toml::table{{"channels", std::move(channels)}});
  }
  if (kind == AnalysisKind::study && in.study) root.insert("study", study_table(*in.study));
  if (kind == AnalysisKind::optimize && in.optimize) root.insert("optimize", optimize_table(*in.optimize));
  if (kind == AnalysisKind::continuation && in.parameter) {
    root.insert("parameter", toml::table{{"key", in.parameter->key}, {"min", in.parameter->min},
                                         {"max", in.parameter->max}, {"start", *in.parameter->start}});
  }
  if (in.ensemble) {
    toml::table t;
    write_fields(t, *in.ensemble);
    toml::array records;
    for (const auto& r : in.ensemble->records) {
      records.push_back(std::filesystem::absolute(r).lexically_normal().string());
    }
    t.insert("records", std::move(records));
    if (in.ensemble->scaling) t.insert("scaling", scaling_table(*in.ensemble->scaling));
    root.insert("ensemble", std::move(t));
  }
  std::ostringstream out;
  out << "# The input as poundsim " POUNDSIM_VERSION " ran it (docs/output.md): run it again with\n"
         "# poundsim run input.toml --out DIR\n\n"
      << root << '\n';
  return out.str();
}

/// The file as parsed, before any setting.
struct ParsedInput {
  toml::table root;
};

namespace {

/// The file as parsed, with its settings applied and its paths absolute (to_toml_as_written).
toml::table as_written(const RunInput& in) {
  toml::table root = in.parsed->root;
  Origin origin{in.source.string(), {}, {}, Reading::run};
  for (const Setting& setting : in.settings) apply_setting(root, setting, origin);
  // Paths are relative to the file's folder; the echo lives elsewhere, so they become absolute.
  const std::function<void(toml::node*)> absolute = [&](toml::node* node) {
    if (node == nullptr) return;
    if (toml::array* items = node->as_array()) {  // ensemble.records, or a study axis over it
      for (toml::node& item : *items) absolute(&item);
      return;
    }
    if (!node->is_string()) return;
    const std::filesystem::path p(*node->value<std::string>());
    *node->as_string() = std::filesystem::absolute(in.base_dir / p).lexically_normal().string();
  };
  if (toml::table* excitation = root.get_as<toml::table>("excitation")) {
    // Beside [ensemble], a file set from the command line is one of its points' (the reader lets
    // it through only as a setting); the echo would refuse it.
    if (root.contains("ensemble")) excitation->erase("file");
    absolute(excitation->get("file"));
  }
  if (toml::table* ensemble = root.get_as<toml::table>("ensemble")) {
    absolute(ensemble->get("folder"));
    absolute(ensemble->get("records"));
  }
  // A study axis over a path: its values are paths too.
  constexpr std::array<std::string_view, 3> path_keys{"excitation.file", "ensemble.folder", "ensemble.records"};
  if (toml::table* study = root.get_as<toml::table>("study")) {
    if (toml::array* parameters = study->get_as<toml::array>("parameter")) {
      for (toml::node& node : *parameters) {
        toml::table* parameter = node.as_table();
        if (parameter == nullptr || parameter->get("key") == nullptr) continue;
        const std::optional<std::string> key = parameter->get("key")->value<std::string>();
        if (key && std::find(path_keys.begin(), path_keys.end(), *key) != path_keys.end()) {
          absolute(parameter->get("values"));
        }
      }
    }
  }
  return root;
}

/// A TOML value as JSON: tables are objects, arrays arrays; dates and times as their TOML text.
nlohmann::json to_json(const toml::node& node) {
  if (const toml::table* table = node.as_table()) {
    nlohmann::json object = nlohmann::json::object();
    for (const auto& [key, value] : *table) object[std::string(key.str())] = to_json(value);
    return object;
  }
  if (const toml::array* array = node.as_array()) {
    nlohmann::json items = nlohmann::json::array();
    for (const toml::node& item : *array) items.push_back(to_json(item));
    return items;
  }
  if (const auto* v = node.as_string()) return v->get();
  if (const auto* v = node.as_integer()) return v->get();
  if (const auto* v = node.as_floating_point()) return v->get();
  if (const auto* v = node.as_boolean()) return v->get();
  std::ostringstream text;
  node.visit([&](const auto& value) { text << value; });
  return text.str();
}

/// A JSON value as TOML (a model built in Python); `path` names it in messages.
std::unique_ptr<toml::node> to_toml_node(const nlohmann::json& value, const std::string& name, const std::string& path) {
  using T = nlohmann::json::value_t;
  const auto refuse = [&](std::string_view what) {
    throw InputError(fmt::format("{}: {}: {} is not a value of a model file", name, path.empty() ? "(top)" : path, what));
  };
  switch (value.type()) {
    case T::object: {
      auto table = std::make_unique<toml::table>();
      for (const auto& [key, item] : value.items()) {
        table->insert(key, std::move(*to_toml_node(item, name, path.empty() ? key : path + "." + key)));
      }
      return table;
    }
    case T::array: {
      auto array = std::make_unique<toml::array>();
      std::size_t k = 0;
      for (const nlohmann::json& item : value) {
        array->push_back(std::move(*to_toml_node(item, name, fmt::format("{}[{}]", path, ++k))));
      }
      return array;
    }
    case T::string: return std::make_unique<toml::value<std::string>>(value.get<std::string>());
    case T::boolean: return std::make_unique<toml::value<bool>>(value.get<bool>());
    case T::number_integer: return std::make_unique<toml::value<std::int64_t>>(value.get<std::int64_t>());
    case T::number_unsigned: {
      const auto n = value.get<std::uint64_t>();
      if (n > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
        refuse(fmt::format("the integer {} (more than 2^63 − 1)", n));
      }
      return std::make_unique<toml::value<std::int64_t>>(static_cast<std::int64_t>(n));
    }
    case T::number_float: return std::make_unique<toml::value<double>>(value.get<double>());
    case T::null: refuse("None (null)"); break;
    default: refuse("a binary value"); break;
  }
  return nullptr;  // not reached
}

}  // namespace

std::string to_toml_as_written(const RunInput& in) {
  std::ostringstream out;
  out << "# The input as poundsim " POUNDSIM_VERSION " ran it: the file as written, with its --set\n"
         "# settings applied and its paths absolute (docs/output.md). Run it again with\n"
         "# poundsim run input.toml --out DIR\n\n"
      << as_written(in) << '\n';
  return out.str();
}

nlohmann::json input_document(const RunInput& input) { return to_json(as_written(input)); }

namespace {

/// Records in `positions` where each node of `copy` stands in the file, from `parsed`, of which
/// it is a copy (a copied toml++ node forgets its position). Nodes a setting replaced are named
/// by their setting instead.
void remember_positions(const toml::node& parsed, const toml::node& copy,
                        std::unordered_map<const toml::node*, toml::source_position>& positions) {
  if (parsed.type() != copy.type()) return;
  positions[&copy] = parsed.source().begin;
  if (const toml::table* table = parsed.as_table()) {
    for (const auto& [key, node] : *table) {
      if (const toml::node* other = copy.as_table()->get(key)) remember_positions(node, *other, positions);
    }
  } else if (const toml::array* array = parsed.as_array()) {
    const toml::array& other = *copy.as_array();
    for (std::size_t i = 0; i < array->size() && i < other.size(); ++i) {
      remember_positions((*array)[i], other[i], positions);
    }
  }
}

RunInput read_parsed(std::shared_ptr<const ParsedInput> parsed, std::string_view text, const std::string& name,
                     const std::filesystem::path& base_dir, std::vector<Setting> settings,
                     Reading reading = Reading::run) {
  Origin origin{name, {}, {}, reading};
  toml::table root = parsed->root;  // the settings change a copy
  remember_positions(parsed->root, root, origin.positions);
  RunInput run = read_root(root, origin, base_dir, settings);
  run.source = name;
  run.text = std::string(text);
  run.parsed = std::move(parsed);
  run.settings = std::move(settings);
  run.base_dir = base_dir;
  return run;
}

}  // namespace

RunInput read_input_string(std::string_view text, const std::string& name,
                           const std::filesystem::path& base_dir,
                           std::span<const std::string> overrides) {
  auto parsed = std::make_shared<ParsedInput>();
  try {
    parsed->root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: {}", name, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
  std::vector<Setting> settings;
  for (const std::string& o : overrides) settings.push_back(parse_setting(o, name));
  return read_parsed(std::move(parsed), text, name, base_dir, std::move(settings));
}

namespace {
/// A frame's per-storey arrays are bounded by limits::storeys: refused before the document is
/// converted and printed for its fingerprint, which for 10⁷ values took half a minute.
void check_frame_array_sizes(const nlohmann::json& document, const std::string& name) {
  const auto frames = document.find("frames");
  if (frames == document.end() || !frames->is_array()) return;
  for (std::size_t i = 0; i < frames->size(); ++i) {
    const nlohmann::json& frame = (*frames)[i];
    if (!frame.is_object()) continue;
    for (const auto& [key, value] : frame.items()) {
      if (value.is_array() && value.size() > static_cast<std::size_t>(limits::storeys)) {
        throw InputError(fmt::format("{}: frames[{}].{}: has {} values: a frame has at most {} storeys", name, i + 1,
                                     key, value.size(), limits::storeys));
      }
    }
  }
}
}  // namespace

RunInput read_input_document(const nlohmann::json& document, const std::string& name,
                             const std::filesystem::path& base_dir, std::span<const std::string> overrides) {
  if (!document.is_object()) {
    throw InputError(fmt::format("{}: a model is a table of tables (a dict), not {}", name, document.type_name()));
  }
  check_frame_array_sizes(document, name);
  auto parsed = std::make_shared<ParsedInput>();
  parsed->root = std::move(*to_toml_node(document, name, "")->as_table());
  // Its TOML text identifies the run in a study database (fingerprint), as a file's does.
  std::ostringstream text;
  text << parsed->root;
  std::vector<Setting> settings;
  for (const std::string& o : overrides) settings.push_back(parse_setting(o, name));
  return read_parsed(std::move(parsed), text.str(), name, base_dir, std::move(settings));
}

RunInput with_settings(const RunInput& base, std::span<const Setting> settings, Reading reading) {
  // The base's own settings first (e.g. --set on the command line), then the new ones.
  std::vector<Setting> all = base.settings;
  all.insert(all.end(), settings.begin(), settings.end());
  return read_parsed(base.parsed, base.text, base.source.string(), base.base_dir, std::move(all), reading);
}

RunInput read_input(const std::filesystem::path& file, std::span<const std::string> overrides) {
  // A directory opens as an empty stream and /dev/zero never ends: only regular files of a
  // bounded size are read, and never more than that bound.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  if (status.type() == std::filesystem::file_type::not_found) {
    throw InputError(fmt::format("{}: cannot open the model file", file.string()));
  }
  if (status.type() != std::filesystem::file_type::regular) {
    const std::string what = status.type() == std::filesystem::file_type::directory ? "a directory"
                             : ec ? ec.message()
                                  : "not a regular file";
    throw InputError(fmt::format("{}: cannot read the model file: {}", file.string(), what));
  }
  const auto too_large = [&] {
    return InputError(fmt::format("{}: the model file is larger than {} MiB", file.string(),
                                  limits::model_file_bytes >> 20));
  };
  std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec) size = limits::model_file_bytes;
  if (size > limits::model_file_bytes) throw too_large();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the model file", file.string()));
  std::string text(static_cast<std::size_t>(size) + 1, '\0');  // one more, to see it grow
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw InputError(fmt::format("{}: read error", file.string()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > size) throw InputError(fmt::format("{}: the model file grew while it was read", file.string()));
  RunInput run = read_input_string(text, file.string(), file.parent_path(), overrides);
  run.source = file;
  return run;
}

}  // namespace poundsim::io
