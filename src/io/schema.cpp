#include "poundsim/io/schema.hpp"

#include <cmath>
#include <limits>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "poundsim/io/input.hpp"

namespace poundsim::io {
namespace {

using Json = nlohmann::ordered_json;

/// What a law of a closed set (GapLaw, StoreyLawParameters) contributes to its table.
template <class A>
struct LawAlternative {
  using Parameters = std::decay_t<decltype(std::declval<A&>().parameters)>;
  static constexpr std::string_view key = A::key;
  static constexpr bool per_storey = false;  ///< a gap element's parameters: one value each
};
template <class L>
struct LawAlternative<PerStorey<L>> {
  using Parameters = typename L::Parameters;
  static constexpr std::string_view key = L::key;
  static constexpr bool per_storey = true;  ///< a storey law's: a number for every storey or one each
};

std::string description(std::string_view meaning, std::string_view unit) {
  return unit.empty() ? std::string(meaning) : fmt::format("{} [{}]", meaning, unit);
}

Json number_in(const Interval& range) {
  Json s{{"type", "number"}};
  if (std::isfinite(range.lo)) s[range.lo_open ? "exclusiveMinimum" : "minimum"] = range.lo;
  if (std::isfinite(range.hi)) s[range.hi_open ? "exclusiveMaximum" : "maximum"] = range.hi;
  return s;
}

Json array_of(Json items) { return Json{{"type", "array"}, {"items", std::move(items)}, {"minItems", 1}}; }

/// A number for every storey (or floor: `item`), or an array of one each.
Json per_storey(const Interval& range, std::string_view meaning, std::string_view unit, std::string_view item) {
  return Json{{"anyOf", Json::array({number_in(range), array_of(number_in(range))})},
              {"description", description(meaning, unit) + fmt::format(", one per {} or one for all", item)}};
}

Json shaped(Shape shape, std::span<const std::string_view> names) {
  const Json number{{"type", "number"}}, integer{{"type", "integer"}};
  Json text{{"type", "string"}};
  if (!names.empty()) text = Json{{"enum", Json(std::vector<std::string>(names.begin(), names.end()))}};
  switch (shape) {
    case Shape::any: return Json::object();
    case Shape::number: return number;
    case Shape::integer: return integer;
    case Shape::text: return text;
    case Shape::numbers: return array_of(number);
    case Shape::number_or_numbers: return Json{{"anyOf", Json::array({number, array_of(number)})}};
    case Shape::integers: return array_of(integer);
    case Shape::texts: return array_of(text);
    case Shape::rows: return Json{{"type", "array"}, {"items", Json{{"type", "array"}, {"items", number}}}};
    case Shape::scalars: return array_of(Json{{"type", Json::array({"number", "string", "boolean"})}});
  }
  return Json::object();
}

template <Configuration... S>
Json object_schema();

/// The keys a table holds, their schemas and which are required; the law its tag chooses.
struct TableSchema {
  Json properties = Json::object();
  std::vector<std::string> required;
  struct Law {
    std::string tag;
    bool inherits = false;
    struct Choice {
      std::string name;
      Json properties = Json::object();
      std::vector<std::string> required;
    };
    std::vector<Choice> choices;
  };
  std::optional<Law> law;

  void add(std::string_view key, Json schema, bool is_required) {
    properties[std::string(key)] = std::move(schema);
    if (is_required) required.emplace_back(key);
  }
  [[nodiscard]] Json finish() const;
};

/// The schema of one declared field, with its description and default (`defaults` holds S's).
template <class S, class Field>
Json field_schema(const Field& field, const S& defaults) {
  Json s;
  if constexpr (is_number_field<Field>) {
    s = number_in(field.range);
    if (!field.required && std::isfinite(defaults.*field.member)) s["default"] = defaults.*field.member;
    s["description"] = description(field.meaning, field.unit);
  } else if constexpr (is_integer_field<Field>) {
    s = Json{{"type", "integer"}, {"minimum", field.lo}, {"maximum", field.hi}};
    // A member outside its range (a grid's points, 0 for a list of values) is no default.
    const auto value = static_cast<std::int64_t>(defaults.*field.member);
    if (value >= field.lo && value <= field.hi) s["default"] = defaults.*field.member;
    s["description"] = field.hint.empty() ? std::string(field.meaning) : fmt::format("{} ({})", field.meaning, field.hint);
  } else if constexpr (is_bool_field<Field>) {
    s = Json{{"type", "boolean"}, {"default", defaults.*field.member}, {"description", field.meaning}};
  } else if constexpr (is_choice_field<Field>) {
    std::vector<std::string> names;
    for (const auto& entry : field.names) names.emplace_back(entry.first);
    s = Json{{"enum", names}};
    if (!field.required) s["default"] = std::string(field.name_of(defaults.*field.member));
    s["description"] = field.meaning;
  } else if constexpr (is_per_storey_field<Field>) {
    s = per_storey(field.range, field.meaning, field.unit, field.item);
  } else if constexpr (is_text_field<Field>) {
    s = field.names.empty() ? Json{{"type", "string"}, {"minLength", 1}} : shaped(Shape::text, field.names);
    if (!field.required && !(defaults.*field.member).empty()) s["default"] = defaults.*field.member;
    s["description"] = field.meaning;
  } else if constexpr (is_optional_number_field<Field>) {
    s = number_in(field.range);
    s["description"] = description(field.meaning, field.unit);
  } else if constexpr (is_number_list_field<Field>) {
    Json list = array_of(number_in(field.range));
    if (field.max_items != std::numeric_limits<std::size_t>::max()) list["maxItems"] = field.max_items;
    if (field.min_items > 1) {
      list["minItems"] = field.min_items;
      s = std::move(list);
    } else {
      s = Json{{"anyOf", Json::array({number_in(field.range), std::move(list)})}};
    }
    s["description"] = description(field.meaning, field.unit);
  } else if constexpr (is_custom_field<Field>) {
    s = shaped(field.shape, field.names);
    s["description"] = field.meaning;
  }
  return s;
}

template <class S, class... Child>
Json table_schema(const TableField<S, Child...>& field) {
  Json s = object_schema<Child...>();
  if (field.array) s = array_of(std::move(s));
  s["description"] = field.meaning;
  return s;
}

/// What choosing the law A admits: its parameters, required unless the table inherits them.
template <class A>
TableSchema::Law::Choice law_choice(bool inherits) {
  using Alt = LawAlternative<A>;
  using Parameters = typename Alt::Parameters;
  TableSchema::Law::Choice choice{.name = std::string(Alt::key), .properties = Json::object(), .required = {}};
  const Parameters defaults{};
  for_each_field<Parameters>([&](const auto& parameter) {
    Json s = field_schema(parameter, defaults);
    if constexpr (Alt::per_storey && is_number_field<std::decay_t<decltype(parameter)>>) {
      s = per_storey(parameter.range, parameter.meaning, parameter.unit, "storey");
    }
    choice.properties[std::string(parameter.key)] = std::move(s);
    if constexpr (requires { parameter.required; }) {
      if (parameter.required && !inherits) choice.required.emplace_back(parameter.key);
    }
  });
  return choice;
}

/// The choices of the closed set of laws Laws (a std::variant), in its order.
template <class Laws>
struct LawChoices;
template <class... A>
struct LawChoices<std::variant<A...>> {
  static std::vector<TableSchema::Law::Choice> of(bool inherits) { return {law_choice<A>(inherits)...}; }
};

template <class S, class Laws>
TableSchema::Law law_schema(const LawField<S, Laws>& field) {
  return TableSchema::Law{.tag = std::string(field.key), .inherits = field.inherits,
                          .choices = LawChoices<Laws>::of(field.inherits)};
}

template <Configuration S>
void add_fields(TableSchema& table) {
  const S defaults{};
  for_each_field<S>([&](const auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (is_table_field<Field>) {
      table.add(field.key, table_schema(field), field.required);
    } else if constexpr (is_law_field<Field>) {
      table.law = law_schema(field);
      std::vector<std::string> names;
      for (const auto& choice : table.law->choices) names.push_back(choice.name);
      Json tag{{"enum", names}};
      if (!field.inherits) tag["default"] = names.front();
      tag["description"] = field.meaning;
      table.add(field.key, std::move(tag), false);
    } else {
      bool is_required = false;
      if constexpr (requires { field.required; }) is_required = field.required;
      table.add(field.key, field_schema(field, defaults), is_required);
    }
  });
}

/// A table whose tag chooses a law: every law's keys are named (for completion), and each choice
/// of the tag admits the table's own keys and its law's parameters only.
Json TableSchema::finish() const {
  Json s{{"type", "object"}, {"properties", properties}};
  if (!required.empty()) s["required"] = required;
  if (!law) {
    s["additionalProperties"] = false;
    return s;
  }
  std::vector<std::string> all_keys;
  for (const auto& [key, value] : properties.items()) all_keys.push_back(key);
  Json branches = Json::array();
  for (std::size_t i = 0; i < law->choices.size(); ++i) {
    const Law::Choice& choice = law->choices[i];
    std::vector<std::string> keys = all_keys;
    for (const auto& [key, value] : choice.properties.items()) {
      keys.push_back(key);
      if (!s["properties"].contains(key)) s["properties"][key] = Json{{"description", value["description"]}};
    }
    Json then{{"properties", choice.properties}, {"propertyNames", Json{{"enum", keys}}}};
    if (!choice.required.empty()) then["required"] = choice.required;
    branches.push_back(Json{{"if", Json{{"properties", Json{{law->tag, Json{{"const", choice.name}}}}}, {"required", {law->tag}}}},
                            {"then", then}});
    if (i == 0 && !law->inherits) {
      branches.push_back(Json{{"if", Json{{"not", Json{{"required", {law->tag}}}}}}, {"then", then}});
    }
  }
  s["additionalProperties"] = false;
  s["allOf"] = std::move(branches);
  return s;
}

template <Configuration... S>
Json object_schema() {
  TableSchema table;
  (add_fields<S>(table), ...);
  return table.finish();
}

}  // namespace

std::string input_schema() {
  Json schema{{"$schema", "http://json-schema.org/draft-07/schema#"},
              {"title", "poundsim model file"},
              {"description", "A poundsim model file (TOML), as docs/input.md documents it; generated by "
                              "`poundsim schema` from the declared keys."}};
  schema.update(object_schema<keys::File>());
  return schema.dump(2) + "\n";
}

}  // namespace poundsim::io
