#pragma once
/// @file
/// Declared fields (fields.hpp) as JSON, for the summaries: by key, or by key and SI unit.

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "poundsim/fields.hpp"

namespace poundsim::io {

/// A field's name as summary.json names quantities: its key and its SI unit, stiffness_N_m,
/// damping_Ns_m, gap_m; the key alone when it has no unit (restitution).
template <class Field>
std::string name_with_unit(const Field& field) {
  std::string name(field.key);
  if constexpr (is_number_field<Field>) {
    if (!field.unit.empty()) {
      name += '_';
      for (const char c : field.unit) {
        if (c == '/') {
          name += '_';
        } else if (static_cast<unsigned char>(c) < 0x80) {
          name += c;  // N·s/m → Ns_m
        }
      }
    }
  }
  return name;
}

/// The value of a declared field of `s` as JSON: a number, an integer, yes/no, a choice's name.
template <class S, class Field>
nlohmann::json field_json(const S& s, const Field& field) {
  if constexpr (is_number_field<Field> || is_bool_field<Field>) {
    return s.*field.member;
  } else if constexpr (is_integer_field<Field>) {
    return static_cast<std::int64_t>(s.*field.member);
  } else {
    return std::string(field.name_of(s.*field.member));
  }
}

/// The declared fields of `s` by key, but those in `except`.
template <class S>
nlohmann::json fields_json(const S& s, std::initializer_list<std::string_view> except = {}) {
  nlohmann::json out = nlohmann::json::object();
  for_each_field<S>([&](const auto& field) {
    if (std::find(except.begin(), except.end(), field.key) != except.end()) return;
    out[std::string(field.key)] = field_json(s, field);
  });
  return out;
}

/// The declared fields of `s` into `out`, each named with its unit (name_with_unit).
template <class S>
void write_with_units(nlohmann::json& out, const S& s) {
  for_each_field<S>([&](const auto& field) { out[name_with_unit(field)] = field_json(s, field); });
}

}  // namespace poundsim::io
