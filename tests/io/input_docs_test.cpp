// docs/input.md documents the fields the reader takes from their declarations (fields.hpp): each
// declared key is in its table's key table, said to be required exactly when it is, with the
// struct's default in the default column and its SI unit in the meaning; and the reader
// accepts each key it declares (a file giving the documented default reads back to the default).

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/fields.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/dimensionless.hpp"
#include "poundsim/model/laws/paper_gap.hpp"
#include "poundsim/model/model.hpp"
#include "../test_files.hpp"

namespace poundsim {
namespace {

/// A file of the repository.
std::string source_file(const std::string& relative) {
  return testing::slurp(std::filesystem::path(POUNDSIM_SOURCE_DIR) / relative);
}

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(' ');
  if (begin == std::string::npos) return {};
  return s.substr(begin, s.find_last_not_of(' ') - begin + 1);
}

/// The items of "`a`, `b`" (keys: each must be in backticks, else nothing) or of "x, y".
std::vector<std::string> split_list(const std::string& cell, bool keys = true) {
  std::vector<std::string> items;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t comma = cell.find(", ", begin);
    std::string item = trim(cell.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin));
    if (keys) {
      if (item.size() < 3 || item.front() != '`' || item.back() != '`') return {};
      item = item.substr(1, item.size() - 2);
    }
    items.push_back(item);
    if (comma == std::string::npos) return items;
    begin = comma + 2;
  }
}

/// The rows of the first Markdown table after the line that contains `marker`, by key (the
/// first column's `key`, or each of its `a`, `b`): the other columns, trimmed.
std::map<std::string, std::vector<std::string>> key_table(const std::string& doc, const std::string& marker) {
  std::map<std::string, std::vector<std::string>> rows;
  const std::size_t start = doc.find(marker);
  if (start == std::string::npos) return rows;  // the caller reports an empty table
  std::istringstream in(doc.substr(start));
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    if (line.starts_with("|")) {
      inside = true;
      std::vector<std::string> cells;
      std::string cell;
      // Cells split at " | " (a "\|" inside a cell is an escaped bar).
      std::string rest = line.substr(1);
      std::size_t at = 0;
      while ((at = rest.find('|')) != std::string::npos) {
        if (at > 0 && rest[at - 1] == '\\') {
          cell += rest.substr(0, at + 1);
        } else {
          cells.push_back(trim(cell + rest.substr(0, at)));
          cell.clear();
        }
        rest = rest.substr(at + 1);
      }
      // "`a`, `b`" documents two keys; a default column "x, y" gives each its own.
      if (cells.size() < 2) continue;
      const std::vector<std::string> keys = split_list(cells[0]);
      if (keys.empty()) continue;
      std::vector<std::string> defaults;
      if (cells.size() > 2) defaults = split_list(cells[2], false);
      for (std::size_t k = 0; k < keys.size(); ++k) {
        std::vector<std::string> row(cells.begin() + 1, cells.end());
        if (keys.size() > 1 && defaults.size() == keys.size()) row[1] = defaults[k];
        rows[keys[k]] = row;
      }
    } else if (inside) {
      break;
    }
  }
  return rows;
}

/// Where a key table says what: its columns after the key. A table without a default column
/// says "no, …, default X" in its required column.
struct Columns {
  std::size_t required = 0;
  std::optional<std::size_t> shown_default = 1;
};

/// Checks the documentation of S's fields in the key table after `marker`; the meaning is the
/// text of all columns.
template <Configuration S>
void expect_documented(const std::string& marker, Columns columns = {},
                       const std::string& page = "docs/input.md") {
  const auto rows = key_table(source_file(page), marker);
  ASSERT_FALSE(rows.empty()) << "no key table after " << marker;
  const S defaults{};
  const std::string text = source_file(page);
  for_each_field<S>([&](const auto& field) {
    using Field = std::decay_t<decltype(field)>;
    const std::string key(field.key);
    if constexpr (is_table_field<Field>) {  // [key], [[key]], [table.key] or [[table.key]]: a section of its own
      EXPECT_TRUE(text.find("[" + key + "]") != std::string::npos || text.find("." + key + "]") != std::string::npos)
          << page << " never names the table [….." << key << "]";
      return;
    }
    const auto row = rows.find(key);
    ASSERT_NE(row, rows.end()) << marker << ": " << page << " does not document " << key;
    ASSERT_GT(row->second.size(), std::max(columns.required, columns.shown_default.value_or(0))) << key;
    const std::string& required = row->second[columns.required];
    std::string shown_default = "—", meaning;
    for (const std::string& cell : row->second) meaning += cell + " | ";
    if (columns.shown_default) {
      shown_default = row->second[*columns.shown_default];
    } else if (const auto at = required.find("default "); at != std::string::npos) {
      shown_default = required.substr(at + 8);
      // "no (default `"linear"`)": the default inside the parentheses.
      if (at > 0 && required[at - 1] == '(' && shown_default.ends_with(")")) shown_default.pop_back();
    }
    if constexpr (!has_own_rules<Field>) {  // a field with its own rules: documented is all
      bool is_required = false;
      if constexpr (requires { field.required; }) is_required = field.required;
      // "a range (…)", "one of the two": a member of an either–or group, required by a rule.
      const bool conditional = !required.starts_with("yes") && !required.starts_with("no");
      EXPECT_EQ(required.starts_with("yes"), is_required) << key << ": required column \"" << required << "\"";
      if (is_required) {
        EXPECT_EQ(shown_default, "—") << key;
      } else if (conditional) {
        // Its default is never used: the rule asks for it, or for the other keys of its group.
      } else if constexpr (is_per_storey_field<Field> || is_optional_number_field<Field>) {
        // Not given, the value is absent (or comes from another key: damping from damping_ratio).
      } else if constexpr (is_text_field<Field> || is_number_list_field<Field>) {
        // A default that depends on other keys, when there is one: described in the meaning.
      } else if constexpr (is_per_storey_field<Field>) {
        // Not given, a per-storey value is absent (or, for damping, comes from damping_ratio).
      } else if constexpr (is_number_field<Field>) {
        char* end = nullptr;
        const double shown = std::strtod(shown_default.c_str(), &end);
        EXPECT_TRUE(!shown_default.empty() && *end == '\0') << key << ": the default \"" << shown_default
                                                              << "\" is not a number";
        EXPECT_EQ(shown, defaults.*field.member) << key << ": documented default " << shown_default;
      } else if constexpr (is_integer_field<Field>) {
        EXPECT_EQ(shown_default, std::to_string(defaults.*field.member)) << key;
      } else if constexpr (is_bool_field<Field>) {
        EXPECT_EQ(shown_default, defaults.*field.member ? "true" : "false") << key;
      } else {
        EXPECT_EQ(shown_default, "`\"" + std::string(field.name_of(defaults.*field.member)) + "\"`") << key;
        for (const auto& [name, value] : field.names) {
          EXPECT_NE(meaning.find("\"" + std::string(name) + "\""), std::string::npos)
              << key << ": the choice \"" << name << "\" is not described";
        }
      }
      if constexpr (is_number_field<Field> || is_per_storey_field<Field> || is_optional_number_field<Field> ||
                    is_number_list_field<Field>) {
        if (std::isfinite(field.range.lo) || std::isfinite(field.range.hi)) {
          EXPECT_NE(meaning.find(field.range.describe()), std::string::npos)
              << key << ": the rule \"" << field.range.describe() << "\" is not stated";
        }
        if (!field.unit.empty()) {
          EXPECT_NE(meaning.find("[" + std::string(field.unit) + "]"), std::string::npos)
              << key << ": the unit [" << field.unit << "] is not given";
        }
      }
    }
  });
}

/// The keys a table's key table documents are exactly those its structs declare (but the arrays
/// of tables, documented in sections of their own).
template <Configuration... S>
void expect_exactly_documented(const std::string& marker, const std::string& page = "docs/input.md") {
  std::set<std::string> declared, documented;
  const auto collect = [&](const auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (is_table_field<Field>) return;
    declared.insert(std::string(field.key));
  };
  (for_each_field<S>(collect), ...);
  for (const auto& [key, row] : key_table(source_file(page), marker)) documented.insert(key);
  EXPECT_EQ(documented, declared) << page << ", " << marker;
}

TEST(InputDocs, AnalysisKeysAreDocumentedAsDeclared) {
  expect_documented<TimeHistoryOptions>("## `[analysis]`");
  expect_documented<io::AnalysisSettings>("## `[analysis]`");
  expect_exactly_documented<TimeHistoryOptions, io::AnalysisSettings>("## `[analysis]`");
}
TEST(InputDocs, FrequencyResponseKeysAreDocumentedAsDeclared) {
  expect_documented<io::FrfSettings>("## `[frf]`");
  expect_documented<SteadyStateOptions>("## `[frf]`");
  expect_exactly_documented<io::FrfSettings, SteadyStateOptions>("## `[frf]`");
}
TEST(InputDocs, DimensionlessKeysAreDocumentedAsDeclared) {
  expect_documented<DimensionlessParameters>("`[model.dimensionless]`:", {.required = 0, .shown_default = {}});
  expect_documented<io::keys::DimensionlessJoint>("`[model.dimensionless]`:", {.required = 0, .shown_default = {}});
  expect_exactly_documented<DimensionlessParameters, io::keys::DimensionlessJoint>("`[model.dimensionless]`:");
  expect_documented<io::keys::DimensionlessModel>("`[model]`:", {.required = 0, .shown_default = {}});
  expect_exactly_documented<io::keys::DimensionlessModel>("`[model]`:");
}
TEST(InputDocs, TheOtherTablesDocumentExactlyTheirDeclaredKeys) {
  const Columns no_default{.required = 0, .shown_default = {}};
  expect_documented<io::keys::File>("The file has a **structure**", {.required = 0, .shown_default = 1});
  expect_exactly_documented<io::keys::File>("The file has a **structure**");
  expect_documented<io::keys::Frame>("`[[frames]]`:", no_default);
  expect_documented<Frame>("`[[frames]]`:", no_default);
  expect_exactly_documented<io::keys::Frame, Frame>("`[[frames]]`:");
  expect_documented<io::keys::GapElements>("`[gap_elements]` gives every element's law");
  expect_documented<io::keys::GapOverride>("`[gap_elements]` gives every element's law");
  expect_documented<io::keys::GapPair>("`[gap_elements]` gives every element's law");
  expect_exactly_documented<io::keys::GapElements, io::keys::GapOverride, io::keys::GapPair>(
      "`[gap_elements]` gives every element's law");
  expect_documented<io::keys::Output>("## `[output]`", no_default);
  expect_exactly_documented<io::keys::Output>("## `[output]`");
  expect_documented<io::keys::Initial>("## `[initial]`", no_default);
  expect_exactly_documented<io::keys::Initial>("## `[initial]`");
  expect_documented<io::keys::Excitation>("## `[excitation]`", {.required = 1, .shown_default = 2});
  expect_exactly_documented<io::keys::Excitation>("## `[excitation]`");
  expect_documented<io::ContinuedParameter>("`[parameter]`:", no_default);
  expect_exactly_documented<io::ContinuedParameter>("`[parameter]`:");
  expect_documented<io::StudyParameter>("`[[study.parameter]]`:", no_default, "docs/studies.md");
  expect_exactly_documented<io::StudyParameter>("`[[study.parameter]]`:", "docs/studies.md");
  expect_documented<io::OptimizeVariable>("`[[optimize.variable]]`:", no_default, "docs/studies.md");
  expect_exactly_documented<io::OptimizeVariable>("`[[optimize.variable]]`:", "docs/studies.md");
  expect_documented<io::OptimizeConstraint>("`[[optimize.constraint]]`:", no_default, "docs/studies.md");
  expect_exactly_documented<io::OptimizeConstraint>("`[[optimize.constraint]]`:", "docs/studies.md");
  expect_documented<io::ParetoSettings>("`[optimize.pareto]`:", no_default, "docs/studies.md");
  expect_exactly_documented<io::ParetoSettings>("`[optimize.pareto]`:", "docs/studies.md");
}
TEST(InputDocs, OptimiserKeysAreDocumentedAsDeclared) {
  expect_documented<io::OptimizeSettings>("## `analysis.kind = \"optimize\"`", {}, "docs/studies.md");
  expect_exactly_documented<io::OptimizeSettings>("## `analysis.kind = \"optimize\"`", "docs/studies.md");
}
TEST(InputDocs, StudyAndEnsembleKeysAreDocumentedAsDeclared) {
  expect_documented<io::StudySettings>("## `analysis.kind = \"study\"`", {}, "docs/studies.md");
  expect_documented<io::EnsembleSettings>("## Ensembles", {}, "docs/records.md");
  expect_exactly_documented<io::StudySettings>("## `analysis.kind = \"study\"`", "docs/studies.md");
  expect_exactly_documented<io::EnsembleSettings>("## Ensembles", "docs/records.md");
  expect_documented<io::EnsembleScaling>("`[ensemble.scaling]`:", {}, "docs/records.md");
  expect_documented<SpectrumOptions>("`[ensemble.scaling]`:", {}, "docs/records.md");
  expect_exactly_documented<io::EnsembleScaling, SpectrumOptions>("`[ensemble.scaling]`:", "docs/records.md");
}
// Each storey law has its paragraph under its `storey_law = "key"` and, when it has parameters,
// their table with exactly those keys.
TEST(InputDocs, EveryStoreyLawDocumentsExactlyItsParameters) {
  const std::string page = source_file("docs/input.md");
  [&]<class... P>(std::variant<P...>*) {
    const auto check = [&]<class Law>(Law*) {
      const std::string marker = fmt::format("`storey_law = \"{}\"`", Law::key);
      const std::size_t at = page.find(marker);
      ASSERT_NE(at, std::string::npos) << marker << " is not documented";
      if constexpr (std::tuple_size_v<decltype(Law::Parameters::fields())> == 0) {
        const std::string paragraph = page.substr(at, page.find("\n\n", at) - at);
        EXPECT_NE(paragraph.find("no parameters of its own"), std::string::npos) << marker;
      } else {
        expect_documented<typename Law::Parameters>(marker);
        expect_exactly_documented<typename Law::Parameters>(marker);
      }
    };
    (check(static_cast<typename P::Law*>(nullptr)), ...);
  }(static_cast<StoreyLawParameters*>(nullptr));
  EXPECT_EQ(storey_law_names.front(), "linear");  // the default of a file, as documented
}

// Each law of GapLaw has its table under its `law = "key"`, with exactly its parameters: adding
// a law to the list fails here until its docs are written.
TEST(InputDocs, EveryGapLawDocumentsExactlyItsParameters) {
  [&]<class... L>(std::variant<L...>*) {
    const auto check = [&]<class Law>(Law*) {
      const std::string marker = fmt::format("`law = \"{}\"`", Law::key);
      expect_documented<typename Law::Parameters>(marker);
      expect_exactly_documented<typename Law::Parameters>(marker);
    };
    (check(static_cast<L*>(nullptr)), ...);
  }(static_cast<GapLaw*>(nullptr));
  EXPECT_EQ(gap_law_names.front(), "paper");  // the default of a file, as documented
}

/// Every declared integer's range fits the type it is stored in (the reader narrows to it after
/// checking the range on the 64-bit value: a range wider than the type would wrap).
template <Configuration... S>
void expect_integer_ranges_fit() {
  const auto check = [](const auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (is_integer_field<Field>) {
      using T = typename Field::Value;
      EXPECT_GE(field.lo, static_cast<std::int64_t>(std::numeric_limits<T>::min())) << field.key;
      EXPECT_LE(static_cast<std::uint64_t>(field.hi), static_cast<std::uint64_t>(std::numeric_limits<T>::max()))
          << field.key;
      EXPECT_LE(field.lo, field.hi) << field.key;
    }
  };
  (for_each_field<S>(check), ...);
}

TEST(InputDocs, IntegerRangesFitTheirTypes) {
  expect_integer_ranges_fit<TimeHistoryOptions, SteadyStateOptions, GapProperties, DimensionlessParameters,
                            io::AnalysisSettings, io::FrfSettings, io::StudySettings, io::OptimizeSettings,
                            io::EnsembleSettings>();
}

// The reader takes its fields from the same declarations: a file that sets every declared field
// of [analysis], [frf] and [gap_elements] to a value other than its default reads them all back,
// and one outside a field's range is refused with the rule the declaration states.
TEST(InputDocs, TheReaderReadsEveryDeclaredField) {
  const std::string model =
      "[model]\nstoreys = [1, 1]\n[model.dimensionless]\nlambda2 = 200.0\nalpha = 0.25\nbeta = 1.0\n"
      "gamma = 0.5\nxi = 0.05\ndelta = 0.25\neta = 0.0\nmu = 0.0\nepsilon = 0.0\nrestitution = 1.0\n";
  const std::string frf =
      model +
      "[analysis]\nkind = \"frf\"\nintegrator = \"exact\"\nevent_tolerance = 2e-10\nlock_time = 3e-6\n"
      "rest_velocity_ratio = 0.5\nseparation = \"force\"\n"
      "[frf]\namplitude_g = 0.1\nratios = [1.0]\nsweep = \"down\"\nsteps_per_period = 64\ntolerance = 1e-5\n"
      "max_periodicity = 3\nmax_periods = 50\nwindow_periods = 9\nthreads = 3\n";
  const io::RunInput in = io::read_input_string(frf, "f.toml", ".");
  EXPECT_EQ(in.analysis.options.integrator, Integrator::exact);
  EXPECT_EQ(in.analysis.options.event_tolerance, 2e-10);
  EXPECT_EQ(in.analysis.options.lock_time, 3e-6);
  EXPECT_EQ(in.analysis.options.rest_velocity_ratio, 0.5);
  EXPECT_EQ(in.analysis.options.separation, SeparationCriterion::force);
  ASSERT_TRUE(in.frf.has_value());
  EXPECT_EQ(in.frf->amplitude_g, 0.1);
  EXPECT_EQ(in.frf->sweep, SweepMode::down);
  EXPECT_EQ(in.frf->steady.steps_per_period, 64);
  EXPECT_EQ(in.frf->steady.tolerance, 1e-5);
  EXPECT_EQ(in.frf->steady.max_periodicity, 3);
  EXPECT_EQ(in.frf->steady.max_periods, 50);
  EXPECT_EQ(in.frf->steady.window_periods, 9);
  EXPECT_EQ(in.frf->threads, 3);

  const auto refused = [&](const std::string& text) {
    try {
      (void)io::read_input_string(text, "f.toml", ".");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  std::string bad = frf;
  bad.replace(bad.find("rest_velocity_ratio = 0.5"), 25, "rest_velocity_ratio = 1.0");
  EXPECT_NE(refused(bad).find("f.toml:19:23: analysis.rest_velocity_ratio: must be in [0, 1) (got 1)"),
            std::string::npos)
      << refused(bad);
  bad = frf;
  bad.replace(bad.find("tolerance = 1e-5"), 16, "tolerance = 1.0");
  EXPECT_NE(refused(bad).find("frf.tolerance: must be in (0, 1) (got 1)"), std::string::npos) << refused(bad);

  const std::string physical =
      "[[frames]]\nstoreys = 1\nmass = 1.0\nstiffness = 100.0\ndamping = 0.0\n"
      "[[frames]]\nstoreys = 1\nmass = 1.0\nstiffness = 50.0\ndamping = 0.0\n"
      "[gap_elements]\ngap = 0.01\nstiffness = 10.0\ndamping = 0.5\nshortening = 0.002\nrestitution = 0.6\n"
      "[analysis]\nkind = \"time_history\"\nduration = 1.0\ndt = 0.01\n[excitation]\nkind = \"none\"\n";
  const io::RunInput th = io::read_input_string(physical, "p.toml", ".");
  ASSERT_EQ(th.model.gaps.size(), 1u);
  const GapProperties& g = parameters_of<PaperGap>(th.model.gaps[0]);
  EXPECT_EQ(g.gap, 0.01);
  EXPECT_EQ(g.stiffness, 10.0);
  EXPECT_EQ(g.damping, 0.5);
  EXPECT_EQ(g.shortening, 0.002);
  EXPECT_EQ(g.restitution, 0.6);
  bad = physical;
  bad.replace(bad.find("restitution = 0.6"), 17, "restitution = 1.5");
  EXPECT_NE(refused(bad).find("gap_elements.restitution: must be in [0, 1] (got 1.5)"), std::string::npos)
      << refused(bad);
  const std::string example = std::string(POUNDSIM_SOURCE_DIR) + "/examples/optimize_gap_elements.toml";
  const std::vector<std::string> settings{"optimize.global_evaluations=7", "optimize.local_evaluations=5",
                                          "optimize.relative_tolerance=0.01", "optimize.seed=4294967295",
                                          "optimize.threads=2"};
  const io::RunInput optimize = io::read_input(example, settings);
  ASSERT_TRUE(optimize.optimize.has_value());
  EXPECT_EQ(optimize.optimize->global_evaluations, 7);
  EXPECT_EQ(optimize.optimize->local_evaluations, 5);
  EXPECT_EQ(optimize.optimize->relative_tolerance, 0.01);
  EXPECT_EQ(optimize.optimize->seed, 4294967295u);
  EXPECT_EQ(optimize.optimize->threads, 2);
  try {
    (void)io::read_input(example, std::vector<std::string>{"optimize.seed=4294967296"});
    ADD_FAILURE() << "a seed beyond 32 bits was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("optimize.seed: must be ≤ 4294967295 (got 4294967296)"), std::string::npos)
        << e.what();
  }
  // [[frames]]' per-storey values (Frame::fields()): a number for every storey or one each.
  std::string heights = physical;
  heights.replace(heights.find("storeys = 1\nmass = 1.0\nstiffness = 100.0"), 40,
                  "mass = [1.0, 2.0]\nstiffness = 100.0\nstorey_height = [3.0, 3.5]\nground_damping = [0.1, 0.2]\n"
                  "modal_damping_ratios = 0.02");
  heights.replace(heights.find("storeys = 1\nmass = 1.0\nstiffness = 50.0"), 39,
                  "storeys = 2\nmass = 1.0\nstiffness = 50.0\nstorey_height = [3.0, 3.5]");
  const io::RunInput two = io::read_input_string(heights, "h.toml", ".");
  for_each_field<Frame>([&](const auto& field) {
    EXPECT_EQ((two.model.frames[0].*field.member).size(), 2U) << field.key;
  });
  EXPECT_EQ(two.model.frames[0].mass, (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(two.model.frames[1].mass, (std::vector<double>{1.0, 1.0}));
  EXPECT_EQ(two.model.frames[0].storey_height, (std::vector<double>{3.0, 3.5}));
  bad = heights;
  bad.replace(bad.find("mass = [1.0, 2.0]"), 17, "mass = [1.0, 0.0]");
  EXPECT_NE(refused(bad).find("frames[1].mass: floor 2: must be > 0 (got 0)"), std::string::npos) << refused(bad);
  bad = heights;
  bad.replace(bad.find("storey_height = [3.0, 3.5]"), 26, "storey_height = [3.0, -1]");
  EXPECT_NE(refused(bad).find("storey_height: storey 2: must be > 0 (got -1)"), std::string::npos) << refused(bad);

  bad = physical;
  bad.replace(bad.find("gap = 0.01\n"), 11, "");
  EXPECT_NE(refused(bad).find("gap_elements.gap: missing key"), std::string::npos) << refused(bad);
}

}  // namespace
}  // namespace poundsim
