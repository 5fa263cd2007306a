#pragma once
/// @file
/// Configuration fields declared once. A configuration struct (TimeHistoryOptions,
/// SteadyStateOptions, GapProperties, …) lists its fields in a static `fields()`: for each, the
/// key it has in a model file, the member it sets, its SI unit, the values it admits and what it
/// means. Its default is the member's initialiser. The same list drives
///   - the struct's own validation (first_violation(), used by its validate()),
///   - the model-file reader (io/input.cpp reads every declared field of a table generically,
///     with the file, line, column and key in its messages),
///   - the documentation check (tests/io/input_docs_test.cpp: docs/input.md lists every declared
///     key of a table with its default and unit).
///   - the input's JSON Schema (io/schema.hpp), with the tables' tree (TableField) and the laws
///     a tag chooses (LawField).
/// Rules between fields (lock_time ≥ 10 × event_tolerance, max_periods ≥ 2 × max_periodicity + 2)
/// stay in the struct's validate(), after the fields' own ranges.

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>
#include <type_traits>
#include <utility>

#include <fmt/format.h>

namespace poundsim {

/// The values a number admits: an interval with open or closed ends; never NaN or ±∞.
struct Interval {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  [[nodiscard]] constexpr bool contains(double v) const {
    if (!(v == v) || v == std::numeric_limits<double>::infinity() ||
        v == -std::numeric_limits<double>::infinity()) {
      return false;
    }
    const bool above = lo_open ? v > lo : v >= lo;
    const bool below = hi_open ? v < hi : v <= hi;
    return above && below;
  }
  /// The rule as a message says it: "> 0", "≥ 0", "in [0, 1)".
  [[nodiscard]] std::string describe() const {
    const bool bounded_below = std::isfinite(lo), bounded_above = std::isfinite(hi);
    if (bounded_below && bounded_above) {
      return fmt::format("in {}{:g}, {:g}{}", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
    }
    if (bounded_below) return fmt::format("{} {:g}", lo_open ? ">" : "≥", lo);
    if (bounded_above) return fmt::format("{} {:g}", hi_open ? "<" : "≤", hi);
    return "finite";
  }
};

inline constexpr Interval any_finite{};
inline constexpr Interval positive{.lo = 0.0, .lo_open = true};
inline constexpr Interval non_negative{.lo = 0.0};
inline constexpr Interval unit_interval{.lo = 0.0, .hi = 1.0};
inline constexpr Interval below_one{.lo = 0.0, .hi = 1.0, .hi_open = true};    ///< [0, 1)
inline constexpr Interval open_unit{.lo = 0.0, .hi = 1.0, .lo_open = true, .hi_open = true};

/// A real-valued field in an SI unit ("" for a ratio).
template <class S>
struct NumberField {
  std::string_view key;
  double S::*member;
  std::string_view unit;
  Interval range;
  std::string_view meaning;
  bool required = false;  ///< A file must give it (in the table that does not inherit it).
};

/// An integer field with its closed range (within T's); the value of a file is checked before it
/// is narrowed to T.
template <class S, class T = int>
struct IntegerField {
  using Value = T;  ///< The member's type: [lo, hi] must fit it (InputDocs.IntegerRangesFitTheirTypes).
  std::string_view key;
  T S::*member;
  std::int64_t lo;
  std::int64_t hi;
  std::string_view meaning;
  std::string_view hint = {};  ///< Added to a message about the range ("0 means all cores").
};

/// A yes/no field.
template <class S>
struct BoolField {
  std::string_view key;
  bool S::*member;
  std::string_view meaning;
};

/// A number for each storey (or floor) of a frame, bottom up: a file gives one number for every
/// storey or an array of one each, and each must lie in `range`.
template <class S>
struct PerStoreyField {
  std::string_view key;
  std::vector<double> S::*member;
  std::string_view unit;
  Interval range;
  std::string_view meaning;
  bool required = false;            ///< A file must give it (else the member stays empty).
  std::string_view item = "storey";  ///< What the i-th value belongs to, in messages: "floor 2: …"
};

/// A text field. An empty text is refused; `names`, when given, are the texts it admits.
template <class S>
struct TextField {
  std::string_view key;
  std::string S::*member;
  std::string_view meaning;
  bool required = false;                          ///< A file must give it.
  std::span<const std::string_view> names = {};  ///< The admitted texts (none: any).
  std::string_view hint = {};                     ///< Added to a message about an empty text.
};

/// A number that may be absent (no default): std::optional<double>, in an SI unit.
template <class S>
struct OptionalNumberField {
  std::string_view key;
  std::optional<double> S::*member;
  std::string_view unit;
  Interval range;
  std::string_view meaning;
};

/// A list of numbers, each in `range`, of min_items to max_items items; `increasing` asks them
/// to increase strictly. A file may give a single number for a list of one.
template <class S>
struct NumberListField {
  std::string_view key;
  std::vector<double> S::*member;
  std::string_view unit;
  Interval range;
  std::string_view meaning;
  std::size_t min_items = 1;
  std::size_t max_items = std::numeric_limits<std::size_t>::max();
  bool increasing = false;
  bool required = false;  ///< A file must give it.
};

/// The shape of a value a file gives for a key read by its table's own rules (CustomField): what
/// the input's JSON Schema (io/schema.hpp) admits for it. The table's reader checks the rest.
enum class Shape : std::uint8_t {
  any,                ///< anything the reader's rules admit
  number,             ///< a number
  integer,            ///< an integer
  text,               ///< a string
  numbers,            ///< an array of numbers
  number_or_numbers,  ///< a number, or an array of numbers
  integers,           ///< an array of integers
  texts,              ///< an array of strings
  rows,               ///< an array of arrays of numbers
  scalars,            ///< an array of numbers, strings or booleans
};

/// A key read by its table's own rules (a list, a key whose default depends on others): declared
/// so that the table's keys are all in one place, documented and checked.
template <class S>
struct CustomField {
  std::string_view key;
  std::string_view meaning;
  Shape shape = Shape::any;
  std::span<const std::string_view> names = {};  ///< A text's admitted values (none: any).
};

/// A sub-table ([key]) or an array of tables ([[key]]) whose keys the structs Child... declare.
template <class S, class... Child>
struct TableField {
  std::string_view key;
  std::string_view meaning;
  bool array = false;     ///< [[key]]: one table or more
  bool required = false;  ///< Every file gives it.
};

/// The tag that chooses a law of the closed set Laws (model/law.hpp's GapLaw or
/// StoreyLawParameters): the table holds the chosen law's declared parameters besides its own
/// keys. The first law is the default.
template <class S, class Laws>
struct LawField {
  std::string_view key;
  std::string_view meaning;
  /// The table inherits a law from its parent (an override): without the tag it may hold any
  /// law's parameters, and none is required.
  bool inherits = false;
};

/// The name of `value` in a closed set of named values ("?" if it has none).
template <class E, std::size_t N>
[[nodiscard]] constexpr std::string_view name_in(const std::array<std::pair<std::string_view, E>, N>& names, E value) {
  for (const auto& [name, v] : names) {
    if (v == value) return name;
  }
  return "?";
}

/// One of a closed set of named values, stored as the enum E.
template <class S, class E, std::size_t N>
struct ChoiceField {
  std::string_view key;
  E S::*member;
  std::array<std::pair<std::string_view, E>, N> names;
  std::string_view meaning;
  bool required = false;  ///< The file must give it (else the member's initialiser is the default).

  [[nodiscard]] constexpr std::optional<E> parse(std::string_view name) const {
    for (const auto& [n, value] : names) {
      if (n == name) return value;
    }
    return std::nullopt;
  }
  [[nodiscard]] constexpr std::string_view name_of(E value) const { return name_in(names, value); }
};

template <class S>
NumberField(std::string_view, double S::*, std::string_view, Interval, std::string_view) -> NumberField<S>;
template <class S>
NumberField(std::string_view, double S::*, std::string_view, Interval, std::string_view, bool)
    -> NumberField<S>;
template <class S, class T>
IntegerField(std::string_view, T S::*, std::int64_t, std::int64_t, std::string_view) -> IntegerField<S, T>;
template <class S, class T>
IntegerField(std::string_view, T S::*, std::int64_t, std::int64_t, std::string_view, std::string_view)
    -> IntegerField<S, T>;
template <class S>
BoolField(std::string_view, bool S::*, std::string_view) -> BoolField<S>;

template <class F>
inline constexpr bool is_number_field = false;
template <class S>
inline constexpr bool is_number_field<NumberField<S>> = true;
template <class F>
inline constexpr bool is_integer_field = false;
template <class S, class T>
inline constexpr bool is_integer_field<IntegerField<S, T>> = true;
template <class F>
inline constexpr bool is_per_storey_field = false;
template <class S>
inline constexpr bool is_per_storey_field<PerStoreyField<S>> = true;
template <class F>
inline constexpr bool is_custom_field = false;
template <class S>
inline constexpr bool is_custom_field<CustomField<S>> = true;
template <class F>
inline constexpr bool is_table_field = false;
template <class S, class... C>
inline constexpr bool is_table_field<TableField<S, C...>> = true;
template <class F>
inline constexpr bool is_law_field = false;
template <class S, class L>
inline constexpr bool is_law_field<LawField<S, L>> = true;
template <class F>
inline constexpr bool is_text_field = false;
template <class S>
inline constexpr bool is_text_field<TextField<S>> = true;
template <class F>
inline constexpr bool is_optional_number_field = false;
template <class S>
inline constexpr bool is_optional_number_field<OptionalNumberField<S>> = true;
template <class F>
inline constexpr bool is_number_list_field = false;
template <class S>
inline constexpr bool is_number_list_field<NumberListField<S>> = true;
/// A field its table's reader reads by rules of its own, not by the generic reader.
template <class F>
inline constexpr bool has_own_rules = is_custom_field<F> || is_table_field<F> || is_law_field<F>;
template <class F>
inline constexpr bool is_bool_field = false;
template <class S>
inline constexpr bool is_bool_field<BoolField<S>> = true;
template <class S, class E, std::size_t N>
ChoiceField(std::string_view, E S::*, std::array<std::pair<std::string_view, E>, N>, std::string_view)
    -> ChoiceField<S, E, N>;
template <class S, class E, std::size_t N>
ChoiceField(std::string_view, E S::*, std::array<std::pair<std::string_view, E>, N>, std::string_view, bool)
    -> ChoiceField<S, E, N>;
template <class F>
inline constexpr bool is_choice_field = false;
template <class S, class E, std::size_t N>
inline constexpr bool is_choice_field<ChoiceField<S, E, N>> = true;


/// A struct that declares its fields.
template <class S>
concept Configuration = requires { S::fields(); };

/// Calls f(field) for every declared field of S, in declaration order.
template <Configuration S, class F>
constexpr void for_each_field(F&& f) {
  std::apply([&](const auto&... field) { (f(field), ...); }, S::fields());
}

/// The keys the structs S declare, in order: the keys their table's reader accepts.
template <Configuration... S>
std::vector<std::string_view> declared_keys() {
  std::vector<std::string_view> keys;
  (for_each_field<S>([&](const auto& field) { keys.push_back(field.key); }), ...);
  return keys;
}

/// The value of `field` in `s` as a message shows it: "1e-10 s", "8", "\"force\"" (not for a
/// field read by its table's own rules, which names no member).
template <class S>
std::string field_value_text(const NumberField<S>& field, const S& s) {
  return field.unit.empty() ? fmt::format("{}", s.*field.member)
                            : fmt::format("{} {}", s.*field.member, field.unit);
}
template <class S, class T>
std::string field_value_text(const IntegerField<S, T>& field, const S& s) {
  return fmt::format("{}", s.*field.member);
}
template <class S>
std::string field_value_text(const BoolField<S>& field, const S& s) {
  return s.*field.member ? "true" : "false";
}
template <class S, class E, std::size_t N>
std::string field_value_text(const ChoiceField<S, E, N>& field, const S& s) {
  return fmt::format("\"{}\"", field.name_of(s.*field.member));
}

/// A rule between fields that the values break: the keys it involves, the one to blame first
/// first (the reader blames the first its table gives, so an override is blamed for what it
/// changed), and why.
struct FieldRule {
  std::vector<std::string_view> keys;
  std::string message;
};

/// The first declared field of `s` outside its range, as "key = value must be rule"; nothing when
/// all are admissible.
template <Configuration S>
std::optional<std::string> first_violation(const S& s) {
  std::optional<std::string> found;
  for_each_field<S>([&](const auto& field) {
    if (found) return;
    using Field = std::decay_t<decltype(field)>;
    if constexpr (is_number_field<Field>) {
      if (!field.range.contains(s.*field.member)) {
        found = fmt::format("{} = {} must be {}", field.key, field_value_text(field, s), field.range.describe());
      }
    } else if constexpr (is_integer_field<Field>) {
      const auto v = static_cast<std::int64_t>(s.*field.member);
      if (v < field.lo || v > field.hi) {
        found = fmt::format("{} = {} must be in [{}, {}]", field.key, v, field.lo, field.hi);
      }
    } else if constexpr (is_per_storey_field<Field>) {
      const std::vector<double>& values = s.*field.member;
      for (std::size_t i = 0; i < values.size() && !found; ++i) {
        if (!field.range.contains(values[i])) {
          found = fmt::format("{}[{}] = {}{}{} must be {}", field.key, i + 1, values[i], field.unit.empty() ? "" : " ",
                              field.unit, field.range.describe());
        }
      }
    } else if constexpr (is_optional_number_field<Field>) {
      const std::optional<double>& v = s.*field.member;
      if (v && !field.range.contains(*v)) found = fmt::format("{} = {} must be {}", field.key, *v, field.range.describe());
    } else if constexpr (is_number_list_field<Field>) {
      const std::vector<double>& values = s.*field.member;
      for (std::size_t i = 0; i < values.size() && !found; ++i) {
        if (!field.range.contains(values[i])) {
          found = fmt::format("{}[{}] = {} must be {}", field.key, i + 1, values[i], field.range.describe());
        }
      }
    } else if constexpr (is_choice_field<Field>) {
      if (field.name_of(s.*field.member).empty()) found = fmt::format("{} has no name", field.key);
    }
  });
  return found;
}

/// Throws std::invalid_argument "what: …" when a declared field of `s` is out of its range or the
/// rule between its fields (s.rule_violation()) is broken: a law's parameters, checked once.
template <Configuration S>
void validate_fields(const S& s, std::string_view what) {
  if (const std::optional<std::string> violation = first_violation(s)) {
    throw std::invalid_argument(fmt::format("{}: {}", what, *violation));
  }
  if constexpr (requires { s.rule_violation(); }) {
    if (const auto rule = s.rule_violation()) throw std::invalid_argument(fmt::format("{}: {}", what, rule->message));
  }
}

}  // namespace poundsim
