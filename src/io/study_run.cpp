#include "poundsim/io/study_run.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <limits>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <random>
#include <set>

#include <fmt/format.h>

#include "poundsim/error.hpp"
#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/io/frequency_response_run.hpp"
#include "poundsim/io/output_files.hpp"
#include "poundsim/io/time_history_run.hpp"
#include "poundsim/io/record_scaling.hpp"
#include "poundsim/io/study_database.hpp"
#include "poundsim/analysis/parallel.hpp"
#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/analysis/time_history.hpp"
#include "poundsim/units.hpp"

namespace poundsim {
// A record's figures as the ranks of an MPI job and the study database exchange them: every
// declared field under its key (figures_of_merit.hpp).
template <DeclaredFigures S>
void to_json(nlohmann::json& j, const S& s) {
  std::apply([&](const auto&... field) { ((j[std::string(field.key)] = s.*field.member), ...); }, S::figures());
}
template <DeclaredFigures S>
void from_json(const nlohmann::json& j, S& s) {
  std::apply([&](const auto&... field) { (j.at(std::string(field.key)).get_to(s.*field.member), ...); }, S::figures());
}
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(BareComparison, bare_peak_V_W, ratio_to_bare, max_ratio_to_bare, time_history,
                                   bare_peak_drift_m, ratio_to_bare_drift, bare_peak_abs_acc_g, ratio_to_bare_acc,
                                   max_ratio_to_bare_drift, max_ratio_to_bare_acc)
}  // namespace poundsim

namespace poundsim::io {

namespace {

using nlohmann::json;

std::string fnv1a(const std::string& text) {
  std::uint64_t h = 14695981039346656037ull;
  for (const unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return fmt::format("{:016x}", h);
}

json describe_model(const Model& model) {
  json frames = json::array();
  for (const Frame& f : model.frames) {
    json frame{{"m", f.mass}, {"k", f.stiffness}, {"c", f.damping}};
    // Damping besides the storey dashpots, when the frame has it.
    if (!f.ground_damping.empty()) frame["c_ground"] = f.ground_damping;
    if (!f.modal_damping_ratios.empty()) frame["modal_damping_ratios"] = f.modal_damping_ratios;
    // A storey law other than the first, and its parameters (the linear storey has none).
    if (!is_default(f.storey_law)) frame["law"] = key_of(f.storey_law);
    for_each_storey_parameter(f.storey_law, [&](const auto& field, const std::vector<double>& values) {
      frame[std::string(field.key)] = values;
    });
    frames.push_back(std::move(frame));
  }
  json gaps = json::array();
  for (const GapElement& g : model.gaps) {
    json element{g.left_frame, g.floor};
    // Elements between floors of different numbers or at a struck column differ from those at
    // corresponding floors (named only then, so that earlier studies keep their fingerprints).
    if (g.floor_right() != g.floor || g.column) {
      element.push_back(json{{"right_floor", g.floor_right()}});
      if (g.column) element.push_back(json{{"struck", g.column->struck == Side::left ? "left" : "right"}, {"weight", g.column->weight}});
    }
    std::visit(
        [&](const auto& law) {
          // A law other than the first is named, so that two laws with equal values differ.
          if (!is_default(g.law)) element.push_back(law.key);
          for_each_field<std::decay_t<decltype(law.parameters)>>(
              [&](const auto& field) { element.push_back(law.parameters.*field.member); });
        },
        g.law);
    gaps.push_back(std::move(element));
  }
  return {{"frames", frames}, {"gaps", gaps}};
}

json describe_analysis(const RunInput& in) {
  const TimeHistoryOptions& o = in.analysis.options;
  json a{{"each", to_string(in.each())},
         {"integrator", to_string(o.integrator)},
         {"event_tolerance", o.event_tolerance},
         {"lock_time", o.lock_time},
         {"separation", to_string(o.separation)}};
  // Given only (appended then: other fingerprints stay).
  if (o.impact_duration > 0) a["impact_duration"] = o.impact_duration;
  if (in.frf) {
    const FrfSettings& f = *in.frf;
    a["frf"] = {{"amplitude_g", f.amplitude_g},     {"ratios", f.ratios},
                {"sweep", to_string(f.sweep)},      {"steps", f.steady.steps_per_period},
                {"tolerance", f.steady.tolerance},  {"max_periods", f.steady.max_periods},
                {"max_periodicity", f.steady.max_periodicity}, {"window", f.steady.window_periods}};
  } else {
    a["duration"] = in.analysis.duration;
    a["dt"] = o.dt;
    if (in.ensemble) {
      a["records"] = json::array();
      for (const auto& r : in.ensemble->records) a["records"].push_back(r.string());
    }
    const ExcitationInfo& e = in.excitation_info;
    a["excitation"] = {{"kind", e.kind}, {"amplitude_g", e.amplitude_g}, {"omega", e.omega},
                       {"file", e.record_file.string()}, {"scale", e.record_scale}, {"units", e.record_units}};
    // A record given as samples is its samples (appended only then: other fingerprints stay).
    if (!e.record_samples.empty()) a["excitation"]["samples"] = {e.record_samples, e.record_options.dt};
  }
  return a;
}

/// A setting's value as JSON (a parameter of a study point).
json to_json(const SettingValue& v) {
  return std::visit(
      [](const auto& x) -> json {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, SettingArray>) {
          json array = json::array();
          for (const SettingValue& item : *x) array.push_back(to_json(item));
          return array;
        } else {
          return json(x);
        }
      },
      v.value);
}

}  // namespace

std::vector<PointValues> study_points(const StudySettings& study) {
  std::vector<PointValues> points;
  const auto& params = study.parameters;
  const auto grid_values = [](const StudyParameter& p) {
    if (!p.values.empty()) return p.values;
    std::vector<SettingValue> v;
    for (int i = 0; i < p.points; ++i) {
      const double f = static_cast<double>(i) / (p.points - 1);
      const double x = p.log ? p.min * std::pow(p.max / p.min, f) : p.min + (p.max - p.min) * f;
      v.push_back({x});
    }
    return v;
  };
  if (study.sampling == Sampling::grid) {
    std::vector<std::vector<SettingValue>> axes;
    for (const StudyParameter& p : params) axes.push_back(grid_values(p));
    std::vector<std::size_t> index(axes.size(), 0);
    if (axes.empty()) return points;
    for (;;) {
      PointValues point;
      for (std::size_t k = 0; k < axes.size(); ++k) point.push_back(make_setting(params[k].key, axes[k][index[k]]));
      points.push_back(std::move(point));
      // Odometer: the last parameter varies fastest.
      std::size_t k = axes.size();
      while (k > 0) {
        --k;
        if (++index[k] < axes[k].size()) break;
        index[k] = 0;
        if (k == 0) return points;
      }
    }
  }
  if (study.sampling == Sampling::list) {
    const std::size_t n = params.empty() ? 0 : params.front().values.size();
    for (std::size_t i = 0; i < n; ++i) {
      PointValues point;
      for (const StudyParameter& p : params) point.push_back(make_setting(p.key, p.values[i]));
      points.push_back(std::move(point));
    }
    return points;
  }
  std::mt19937_64 rng(study.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < study.samples; ++i) {
    PointValues point;
    for (const StudyParameter& p : params) {
      const double f = unit(rng);
      const double x = p.log ? p.min * std::pow(p.max / p.min, f) : p.min + (p.max - p.min) * f;
      point.push_back(make_setting(p.key, {x}));
    }
    points.push_back(std::move(point));
  }
  return points;
}

std::string fingerprint(const RunInput& input) {
  json overrides = json::array();
  for (const Setting& s : input.settings) overrides.push_back(s.text);
  // The records' contents too (a record edited in place changes every result), and the version
  // that computed the results.
  std::vector<std::filesystem::path> files;
  if (!input.excitation_info.record_file.empty()) files.push_back(input.excitation_info.record_file);
  if (input.ensemble) files.insert(files.end(), input.ensemble->records.begin(), input.ensemble->records.end());
  json records = json::array();
  for (const std::filesystem::path& file : files) {
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in && !in.eof()) throw InputError(fmt::format("{}: cannot be read again", file.string()));
    records.push_back(fnv1a(bytes));
  }
  json d{{"model", describe_model(input.model)}, {"analysis", describe_analysis(input)}, {"text", input.text},
         {"overrides", overrides}, {"records", records}, {"version", POUNDSIM_VERSION}};
  return fnv1a(d.dump());
}

Model bare_pounding_model(const RunInput& point) {
  Model bare = bare_pounding(point.model);
  // An input built in code may leave the joints out: they are then the elements' gaps.
  if (!point.joint_widths.empty()) {
    assert(point.joint_widths.size() == bare.gaps.size());
    for (std::size_t k = 0; k < bare.gaps.size(); ++k) {
      // bare_pounding's stop, or a slab's contact law, closes at the joint width.
      std::visit([&](auto& law) { law.parameters.gap = point.joint_widths[k]; }, bare.gaps[k].law);
    }
  }
  return bare;
}

std::string baseline_key(const RunInput& point) {
  json d{{"model", describe_model(bare_pounding_model(point))}, {"analysis", describe_analysis(point)}};
  return fnv1a(d.dump());
}

json to_json(const PointFigures& figures) {
  json columns = json::object();
  for (const FigureColumn& c : figures.columns()) {
    if (c.count) {
      columns[c.name] = static_cast<long>(c.value);
    } else {
      columns[c.name] = c.value;
    }
  }
  return columns;
}

std::vector<FigureColumn> figure_columns_of(const json& columns) {
  std::vector<FigureColumn> out;
  for (const auto& [name, value] : columns.items()) {
    out.push_back({name, value.get<double>(), value.is_number_integer()});
  }
  return out;
}

namespace {

FrfFigures frf_figures_of(const RunInput& point, int threads, double band_min, double band_max) {
  FrequencyResponseOptions o = frequency_response_options(point);
  o.threads = threads;
  return frf_figures(point.model, frequency_response(point.model, o), band_min, band_max);
}

TimeHistoryFigures time_history_figures_of(const RunInput& point) {
  // Outputs at the start and the end only: the peaks are all a point needs.
  const TimeHistoryAnalysis run = analyse_time_history({.model = point.model,
                                                        .excitation = point.excitation,
                                                        .options = point.analysis.options,
                                                        .initial = point.initial,
                                                        .duration = point.analysis.duration,
                                                        .output_dt = point.analysis.duration},
                                                       {}, &process_free_runs());
  return time_history_figures(point.model, run, point.excitation_info.record_pga_g);
}

/// Mean and maximum over the records of every numeric metric.
struct Aggregate {
  json mean = json::object(), max = json::object();
};

Aggregate aggregate(const std::vector<json>& per_record) {
  std::map<std::string, std::pair<double, double>> sums;  // key → (sum, max)
  for (const json& r : per_record) {
    for (const auto& [k, v] : r.items()) {
      if (!v.is_number()) continue;
      auto [it, fresh] = sums.try_emplace(k, 0.0, -std::numeric_limits<double>::infinity());
      it->second.first += v.get<double>();
      it->second.second = std::max(it->second.second, v.get<double>());
    }
  }
  Aggregate a;
  for (const auto& [k, sm] : sums) {
    a.mean[k] = sm.first / static_cast<double>(per_record.size());
    a.max[k] = sm.second;
  }
  return a;
}

EnsembleFigures ensemble_figures_of(const RunInput& point, int threads) {
  const std::vector<double> factors = record_factors(point);
  std::vector<TimeHistoryFigures> per_record(point.ensemble->records.size());
  parallel_for(static_cast<int>(per_record.size()), threads, [&](int k) {
    const auto r = static_cast<std::size_t>(k);
    per_record[r] = record_figures(point, r, factors.empty() ? std::nullopt : std::optional<double>(factors[r]));
  });
  return ensemble_figures(per_record);
}

std::pair<double, double> band_of(const RunInput& point) {
  if (point.study) return {point.study->band_min, point.study->band_max};
  if (point.optimize) return {point.optimize->band_min, point.optimize->band_max};
  return {0.0, std::numeric_limits<double>::infinity()};
}

}  // namespace

std::vector<double> record_factors(const RunInput& point) {
  // The factors depend on the point's model (T₁ of a frame), so each point scales its records.
  return point.ensemble && point.ensemble->scaling ? suite_scaling(point).factors : std::vector<double>{};
}

TimeHistoryFigures record_figures(const RunInput& point, std::size_t record, std::optional<double> factor) {
  std::vector<Setting> settings{make_setting("excitation.file", {point.ensemble->records.at(record).string()})};
  if (factor) settings.push_back(make_setting("excitation.scale", {*factor}));
  RunInput one = with_settings(point, settings, Reading::ensemble_record);
  one.model = point.model;  // the point's model as given (e.g. made bare), the record from the file
  return time_history_figures_of(one);
}

std::string to_bytes(const TimeHistoryFigures& figures) { return cbor_bytes(json(figures)); }

TimeHistoryFigures time_history_figures_from_bytes(const std::string& bytes) {
  return json::from_cbor(bytes).get<TimeHistoryFigures>();
}

namespace {
// The response's kind names its field: {"frf": …} | {"time_history": …} | {"ensemble": …}.
constexpr std::array<const char*, 3> kResponseKinds{"frf", "time_history", "ensemble"};
}  // namespace

std::string to_bytes(const PointFigures& figures) {
  json value = json::object();
  std::visit([&](const auto& response) { value[kResponseKinds[figures.response.index()]] = response; }, figures.response);
  if (figures.bare) value["bare"] = *figures.bare;
  return cbor_bytes(value);
}

PointFigures point_figures_from_bytes(const std::string& bytes) {
  const json value = json::from_cbor(bytes);
  PointFigures figures;
  if (value.contains("frf")) {
    figures.response = value["frf"].get<FrfFigures>();
  } else if (value.contains("time_history")) {
    figures.response = value["time_history"].get<TimeHistoryFigures>();
  } else {
    figures.response = value.at("ensemble").get<EnsembleFigures>();
  }
  if (value.contains("bare")) figures.bare = value["bare"].get<BareComparison>();
  return figures;
}

PointFigures point_figures(const RunInput& point, int threads, const std::vector<FigureColumn>* bare) {
  const auto [lo, hi] = band_of(point);
  PointFigures figures;
  switch (point.each()) {
    case PointRun::frf: figures.response = frf_figures_of(point, threads, lo, hi); break;
    case PointRun::ensemble: figures.response = ensemble_figures_of(point, threads); break;
    case PointRun::time_history: figures.response = time_history_figures_of(point); break;
  }
  if (bare != nullptr) figures.compare_with_bare(*bare);
  return figures;
}

PointFigures baseline_figures(const RunInput& point, int threads) {
  RunInput bare = point;
  bare.model = bare_pounding_model(point);
  return point_figures(bare, threads, nullptr);
}

namespace {
StudyResult run_points(const RunInput& input, const std::filesystem::path& out_dir, const StudyRunOptions& options,
                       AnalysisKind kind, const SuiteScaling* scaling = nullptr);
}

StudyResult run_study(const RunInput& input, const std::filesystem::path& out_dir,
                      const StudyRunOptions& options) {
  if (!input.study) throw InputError(fmt::format("{}: no [study] table", input.source.string()));
  return run_points(input, out_dir, options, AnalysisKind::study);
}

namespace {

/// An ensemble as the study it is: one time history per record, over the record files (and, for a
/// scaled suite, their factors as excitation.scale, a second list beside the files, so that the
/// database and ensemble.csv keep each record's factor).
RunInput ensemble_as_study(const RunInput& input, std::optional<SuiteScaling>& scaling) {
  if (!input.ensemble) throw InputError(fmt::format("{}: no [ensemble] table", input.source.string()));
  RunInput as_study = input;
  StudySettings study;
  study.each = PointRun::time_history;
  study.sampling = Sampling::list;
  study.baseline = input.ensemble->baseline;
  study.threads = input.ensemble->threads;
  StudyParameter records;
  records.key = "excitation.file";
  for (const auto& r : input.ensemble->records) records.values.push_back({r.string()});
  study.parameters.push_back(std::move(records));
  if (input.ensemble->scaling) {
    scaling = suite_scaling(input);
    StudyParameter scales;
    scales.key = "excitation.scale";
    for (const double f : scaling->factors) scales.values.push_back({f});
    study.parameters.push_back(std::move(scales));
  }
  as_study.study = study;
  return as_study;
}

}  // namespace

StudyResult run_ensemble(const RunInput& input, const std::filesystem::path& out_dir,
                         const StudyRunOptions& options) {
  std::optional<SuiteScaling> scaling;
  const RunInput as_study = ensemble_as_study(input, scaling);
  return run_points(as_study, out_dir, options, AnalysisKind::ensemble, scaling ? &*scaling : nullptr);
}

json to_json(const StudyResult& result) {
  const StudySettings& study = result.study;
  json best;
  if (result.lowest_max_peak) {
    const BestPoint& b = *result.lowest_max_peak;
    best = {{"id", b.id}, {"parameters", b.parameters}, {"metrics", b.metrics}};
  }
  json summary{{"poundsim_version", POUNDSIM_VERSION},
               {"input", result.source.string()},
               {"title", result.title},
               {"analysis", {{"kind", to_string(result.kind)}, {"each", to_string(study.each)}, {"sampling", to_string(study.sampling)},
                             {"band", {study.band_min, study.band_max}}, {"baseline", study.baseline}}},
               {"parameters", result.parameters},
               {"points", result.points},
               {"finished", result.finished},
               {"failed", result.failed},
               {"skipped_as_finished", result.skipped_as_finished},
               {"run_this_time", result.run_this_time},
               {"complete", result.complete()},
               {"lowest_max_peak", best},
               {"database", result.database.string()},
               {"run_time_s", result.run_time}};
  if (result.kind == AnalysisKind::ensemble) {
    json per_record = json::array();
    for (const StudyDatabase::Row& r : result.rows) {
      json entry{{"record", r.parameters.value("excitation.file", json())}, {"status", r.status}};
      if (r.status == "done") {
        for (const std::string_view k :
             {std::string_view("pga_g"), column_names::max_peak_V_W, column_names::max_ratio_to_free, std::string_view("impacts"),
              std::string_view("max_impact_impulse_Ns")}) {
          entry[std::string(k)] = r.metrics.value(std::string(k), json());
        }
      } else {
        entry["error"] = r.error;
      }
      per_record.push_back(std::move(entry));
    }
    summary["records"] = per_record;
    if (!result.scaling.is_null()) summary["scaling"] = result.scaling;
    if (!result.mean.is_null()) {
      summary["mean"] = result.mean;
      summary["max"] = result.max;
    }
  }
  return summary;
}

std::string report(const StudyResult& r, const std::filesystem::path& out_dir) {
  const bool ensemble = r.kind == AnalysisKind::ensemble;
  std::string text = fmt::format("poundsim {}: {} ({}, {} {}: {} finished, {} of them now, {} failed; {:.3f} s)\n",
                                 POUNDSIM_VERSION, r.source.string(), to_string(r.kind), r.points, ensemble ? "records" : "points",
                                 r.finished, r.run_this_time, r.failed, r.run_time);
  const char* incomplete = r.complete() ? "" : " (incomplete: run again to go on)";
  if (ensemble) {
    if (!r.mean.is_null()) {
      for (std::size_t f = 1; r.mean.contains(fmt::format("peak_V{}_W", f)); ++f) {
        const std::string key = fmt::format("peak_V{}_W", f), ratio = fmt::format("ratio_to_free_{}", f);
        text += fmt::format("  frame {}: peak V/W mean {:.4f}, max {:.4f}; pounding ÷ free mean {:.3f}, max {:.3f}\n",
                            f, r.mean[key].get<double>(), r.max[key].get<double>(), r.mean[ratio].get<double>(),
                            r.max[ratio].get<double>());
      }
    }
    text += fmt::format("  wrote {}/ensemble.sqlite, ensemble.csv, summary.json, input.toml{}\n", out_dir.string(), incomplete);
    return text;
  }
  if (r.lowest_max_peak) {
    const BestPoint& b = *r.lowest_max_peak;
    text += fmt::format("  lowest larger peak V/W {:.4f} at point {}: {}\n", b.metrics[std::string(column_names::max_peak_V_W)].get<double>(),
                        b.id, b.parameters.dump());
  }
  text += fmt::format("  wrote {}/study.sqlite, study.csv, summary.json, input.toml{}\n", out_dir.string(), incomplete);
  return text;
}

namespace {

/// A column of JSON values as a table column: whole numbers, numbers (null → NaN, a missing
/// value) or, when any is neither, text (a number as the shortest form that reads back, null
/// empty, a string as it is, anything else as JSON).
void add_json_column(Table& table, std::string name, const std::vector<const json*>& values) {
  const bool numbers = std::all_of(values.begin(), values.end(), [](const json* v) { return v->is_number() || v->is_null(); });
  const bool integers = std::all_of(values.begin(), values.end(), [](const json* v) { return v->is_number_integer(); });
  if (integers) {
    const std::string unit = column_unit(name);
    auto& column = table.integers(std::move(name), unit);
    for (const json* v : values) column.push_back(v->get<std::int64_t>());
  } else if (numbers) {
    const std::string unit = column_unit(name);
    auto& column = table.numbers(std::move(name), unit);
    for (const json* v : values) column.push_back(v->is_null() ? std::nan("") : v->get<double>());
  } else {
    auto& column = table.texts(std::move(name));
    for (const json* v : values) {
      column.push_back(v->is_number()   ? fmt::format("{}", v->get<double>())
                       : v->is_string() ? v->get<std::string>()
                       : v->is_null()   ? std::string()
                                        : v->dump());
    }
  }
}

}  // namespace

namespace {

/// Each point's input: the settings `all` (study_points of input's study) applied to `input`.
std::vector<RunInput> points_of(const RunInput& input, const std::vector<PointValues>& all, AnalysisKind kind) {
  const StudySettings& study = *input.study;
  std::vector<RunInput> points;
  points.reserve(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    try {
      points.push_back(with_settings(input, all[i], kind == AnalysisKind::ensemble ? Reading::ensemble_record : Reading::run));
    } catch (const InputError& e) {
      std::string values;
      for (const Setting& s : all[i]) values += fmt::format("{}{} = {}", values.empty() ? "" : ", ", s.key, to_text(s.value));
      // An error that a parameter's value caused is reported where the file defines that
      // parameter; any other names the file.
      std::string where = input.source.string();
      for (const StudyParameter& p : study.parameters) {
        if (!p.where.empty() && p.key == e.setting()) where = p.where;
      }
      throw InputError(fmt::format("{}: {} {} ({}): {}", where, kind == AnalysisKind::ensemble ? "ensemble record" : "study point",
                                   i + 1, values, e.what()));
    }
  }
  return points;
}

}  // namespace

std::vector<RunInput> point_inputs(const RunInput& input, AnalysisKind kind) {
  if (kind == AnalysisKind::ensemble && !input.study) {
    std::optional<SuiteScaling> scaling;
    const RunInput as_study = ensemble_as_study(input, scaling);
    return points_of(as_study, study_points(*as_study.study), kind);
  }
  return points_of(input, study_points(*input.study), kind);
}

namespace {

/// A point to run: its 0-based id (its row), its input and its bare-pounding reference's key.
struct Todo {
  long id;
  RunInput input;
  std::string baseline;
};

/// What one point (or bare-pounding reference) computes, wherever it runs: a task names it (and
/// carries its reference's peaks), the result is what the database stores. Both are CBOR, which
/// keeps every double to the bit.
std::string compute_task(const std::map<long, const Todo*>& by_id, const std::string& task_bytes) {
  const json task = json::from_cbor(task_bytes);
  const Todo& t = *by_id.at(task.at("id").get<long>());
  if (task.at("phase") == "baseline") return cbor_bytes(json{{"figures", io::to_json(baseline_figures(t.input, 1))}});
  const auto point_start = std::chrono::steady_clock::now();
  std::string status = "done", error;
  json metrics = json::object();
  try {
    std::optional<std::vector<FigureColumn>> bare;
    if (!task.at("bare").is_null()) bare = figure_columns_of(task.at("bare"));
    metrics = io::to_json(point_figures(t.input, 1, bare ? &*bare : nullptr));
  } catch (const SimulationError& e) {
    status = "failed";
    error = e.what();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - point_start).count();
  return cbor_bytes(json{{"status", status}, {"error", error}, {"metrics", metrics}, {"seconds", seconds}});
}

/// One study or ensemble run on the coordinator (or alone): the points still to run, the
/// database, and the phases that run the bare-pounding references and then the points.
class PointsRun {
 public:
  PointsRun(const StudySettings& study, const std::vector<PointValues>& all, const StudyRunOptions& options,
            std::vector<Todo> todo)
      : study_(study), all_(all), options_(options), todo_(std::move(todo)),
        ranks_(options.distribution != nullptr && options.distribution->ranks() > 1 ? options.distribution : nullptr) {}

  /// On a worker rank: the bare-pounding references, then the points, as the coordinator sends them.
  bool serve() {
    index_todo();
    // Both phases, whatever the first's end: the coordinator ends the second too.
    const bool baselines_stopped = ranks_->run_phase({}, compute(), {}, {});
    const bool points_stopped = ranks_->run_phase({}, compute(), {}, {});
    return baselines_stopped || points_stopped;
  }
  [[nodiscard]] bool is_worker() const { return ranks_ != nullptr && !ranks_->is_coordinator(); }

  /// Drops the points the database holds (and those beyond max_points), then runs the rest.
  void run(StudyDatabase& db, const std::set<long>& finished) {
    std::erase_if(todo_, [&](const Todo& t) { return finished.contains(t.id); });
    if (options_.max_points && static_cast<long>(todo_.size()) > *options_.max_points) {
      todo_.resize(static_cast<std::size_t>(*options_.max_points));
    }
    index_todo();
    run_baselines(db);
    run_todo(db);
  }
  [[nodiscard]] int run_this_time() const { return static_cast<int>(todo_.size()); }

 private:
  void index_todo() {
    for (const Todo& t : todo_) by_id_[t.id] = &t;
  }
  [[nodiscard]] std::function<std::string(const std::string&)> compute() const {
    return [this](const std::string& bytes) { return compute_task(by_id_, bytes); };
  }
  [[nodiscard]] bool stop_requested() const { return options_.stop_requested && options_.stop_requested(); }

  /// Bare-pounding references, each computed once and stored.
  void run_baselines(StudyDatabase& db) {
    std::vector<const Todo*> missing;
    for (const Todo& t : todo_) {
      if (t.baseline.empty() || baselines_.contains(t.baseline)) continue;
      if (auto stored = db.baseline(t.baseline)) {
        baselines_[t.baseline] = *stored;
      } else {
        baselines_[t.baseline] = json();
        missing.push_back(&t);
      }
    }
    if (ranks_ != nullptr) {
      std::vector<std::string> tasks;
      for (const Todo* t : missing) tasks.push_back(cbor_bytes(json{{"phase", "baseline"}, {"id", t->id}}));
      const auto store = [&](std::size_t k, const std::string& result) {
        const json m = json::from_cbor(result).at("figures");
        db.record_baseline(missing[k]->baseline, m);
        baselines_[missing[k]->baseline] = m;
      };
      if (ranks_->run_phase(tasks, compute(), store, [&] { return stop_requested(); })) {
        // The workers wait for the points' phase, which they learn is stopped too.
        ranks_->run_phase({}, compute(), {}, [] { return true; });
        throw RunStopped();
      }
      return;
    }
    std::mutex baseline_mutex;
    parallel_for(static_cast<int>(missing.size()), study_.threads, [&](int k) {
      if (stop_requested()) throw RunStopped();
      const Todo& t = *missing[static_cast<std::size_t>(k)];
      const json m = io::to_json(baseline_figures(t.input, 1));
      db.record_baseline(t.baseline, m);
      const std::lock_guard lock(baseline_mutex);
      baselines_[t.baseline] = m;
    });
  }

  /// The points, each stored by the thread or the rank that ran it as it ends.
  void run_todo(StudyDatabase& db) {
    std::atomic<int> done{0};
    const int total = run_this_time();
    // The run begins: a progress bar's clock and rate start here, not at the first point's end.
    if (options_.progress) options_.progress(0, total);
    std::vector<std::string> tasks;
    for (const Todo& t : todo_) {
      tasks.push_back(cbor_bytes(json{{"phase", "point"}, {"id", t.id},
                                    {"bare", t.baseline.empty() ? json() : baselines_.at(t.baseline)}}));
    }
    // Called by a worker thread too: the database and the counts are safe to share.
    const auto store = [&](std::size_t k, const std::string& bytes) {
      const Todo& t = todo_[k];
      const json r = json::from_cbor(bytes);
      json parameters = json::object();
      for (const Setting& s : all_[static_cast<std::size_t>(t.id)]) parameters[s.key] = to_json(s.value);
      db.record(t.id, parameters, r.at("status").get<std::string>(), r.at("error").get<std::string>(),
                r.at("metrics"), r.at("seconds").get<double>());
      const int count = ++done;
      if (options_.progress) options_.progress(count, total);
    };
    if (ranks_ != nullptr) {
      if (ranks_->run_phase(tasks, compute(), store, [&] { return stop_requested(); })) throw RunStopped();
      return;
    }
    parallel_for(total, study_.threads, [&](int k) {
      if (stop_requested()) throw RunStopped();
      const auto i = static_cast<std::size_t>(k);
      store(i, compute_task(by_id_, tasks[i]));
    });
  }

  const StudySettings& study_;
  const std::vector<PointValues>& all_;  ///< Every point's settings, by id.
  const StudyRunOptions& options_;
  std::vector<Todo> todo_;
  PointDistribution* ranks_;
  std::map<long, const Todo*> by_id_;  ///< Filled once `todo_` no longer changes.
  std::map<std::string, json> baselines_;
};

/// Every point, read (and so validated) before the database is touched or anything runs.
std::vector<Todo> todo_of(const RunInput& input, const std::vector<PointValues>& all, AnalysisKind kind) {
  std::vector<Todo> todo;
  for (RunInput& point : points_of(input, all, kind)) {
    std::string key = input.study->baseline ? baseline_key(point) : std::string();
    todo.push_back({static_cast<long>(todo.size()), std::move(point), std::move(key)});
  }
  return todo;
}

/// The run's result from the whole database, earlier runs included: counts, the point with the
/// lowest larger peak, and an ensemble's mean and maximum over its records.
void collect_rows(const StudyDatabase& db, AnalysisKind kind, StudyResult& result) {
  result.rows = db.rows();
  std::vector<json> done_metrics;
  for (const StudyDatabase::Row& r : result.rows) {
    ++result.finished;
    if (r.status != "done") {
      ++result.failed;
      continue;
    }
    done_metrics.push_back(r.metrics);
    const std::string ranked_by(column_names::max_peak_V_W);
    const double objective = r.metrics.value(ranked_by, std::numeric_limits<double>::infinity());
    if (!result.lowest_max_peak ||
        objective < result.lowest_max_peak->metrics[ranked_by].get<double>()) {
      result.lowest_max_peak = BestPoint{r.id + 1, r.parameters, r.metrics};
    }
  }
  if (kind == AnalysisKind::ensemble && !done_metrics.empty()) {
    Aggregate all_records = aggregate(done_metrics);
    result.mean = std::move(all_records.mean);
    result.max = std::move(all_records.max);
  }
}

StudyResult run_points(const RunInput& input, const std::filesystem::path& out_dir, const StudyRunOptions& options,
                       AnalysisKind kind, const SuiteScaling* scaling) {
  const std::string stem(to_string(kind));  // the files' names: study.sqlite, ensemble.csv
  const StudySettings& study = *input.study;
  const auto start = std::chrono::steady_clock::now();
  const std::vector<PointValues> all = study_points(study);
  PointsRun points(study, all, options, todo_of(input, all, kind));
  if (points.is_worker()) {
    if (points.serve()) throw RunStopped();
    StudyResult result;
    result.kind = kind;
    result.worker = true;
    return result;
  }
  OutputTransaction out(out_dir);  // creates the folder for the database too
  std::vector<std::string> parameter_keys;
  for (const StudyParameter& p : study.parameters) parameter_keys.push_back(p.key);
  const json definition{{"input", input.source.string()}, {"each", to_string(study.each)}, {"sampling", to_string(study.sampling)},
                        {"points", all.size()}, {"parameters", parameter_keys}};
  StudyDatabase db(out_dir / (stem + ".sqlite"), fingerprint(input), definition);
  const std::set<long> finished = db.finished();
  points.run(db, finished);

  StudyResult result;
  result.kind = kind;
  result.source = input.source;
  result.title = input.title;
  result.study = study;
  result.parameters = parameter_keys;
  result.points = static_cast<long>(all.size());
  result.skipped_as_finished = static_cast<long>(finished.size());
  result.run_this_time = points.run_this_time();
  result.database = out_dir / (stem + ".sqlite");
  result.run_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  collect_rows(db, kind, result);
  if (scaling != nullptr) {
    result.scaling = to_json(input, *scaling);
    result.spectra = scaled_spectra_table(input, *scaling);
    write_table(out, "spectra.csv", *result.spectra);
  }
  out.write_json("summary.json", to_json(result));
  // A study's axes name keys of the file's own form (a dimensionless key, excitation.ratio, an
  // inherited gap-element key), which to_toml rewrites: it echoes the file as written.
  out.open("input.toml").text(kind == AnalysisKind::ensemble ? to_toml(input) : to_toml_as_written(input));
  write_table(out, stem + ".csv", study_table(parameter_keys, result.rows));
  out.commit();
  return result;
}

}  // namespace

std::string column_unit(std::string_view name) {
  if (const std::optional<std::string_view> declared = declared_unit(name)) return std::string(*declared);
  // A column no figure declares (a parameter, a ratio to bare pounding). Longest suffix first: _m_s2 before _m_s before _m.
  for (const auto& [suffix, unit] : std::initializer_list<std::pair<std::string_view, std::string_view>>{
           {"_rad_s", "rad/s"}, {"_m_s2", "m/s2"}, {"_m_s", "m/s"}, {"_m", "m"}, {"_s", "s"}, {"_Ns", "N·s"},
           {"_N", "N"}, {"_J", "J"}, {"_g", "g"}, {"_W", "1"}, {"_at", "1"}}) {
    if (name.ends_with(suffix)) return std::string(unit);
  }
  if (name.starts_with("amp_")) return "1";
  // A ratio: a word of the name (max_ratio_to_free, gap_over_min_gap), not "acceleration"'s letters.
  for (const std::string_view word : {"ratio", "over", "amplification"}) {
    for (std::size_t at = name.find(word); at != std::string_view::npos; at = name.find(word, at + 1)) {
      const std::size_t end = at + word.size();
      if ((at == 0 || name[at - 1] == '_') && (end == name.size() || name[end] == '_')) return "1";
    }
  }
  return "";
}

Table study_table(const std::vector<std::string>& parameters, const std::vector<StudyDatabase::Row>& rows) {
  std::set<std::string> metric_keys;
  for (const auto& r : rows) {
    for (const auto& [k, v] : r.metrics.items()) metric_keys.insert(k);
  }
  Table table;
  auto& ids = table.integers("id");
  auto& status = table.texts("status");
  for (const auto& r : rows) {
    ids.push_back(r.id + 1);
    status.push_back(r.status);
  }
  const json missing;
  const auto add = [&](const std::string& key, const auto& of_row) {
    std::vector<const json*> values;
    for (const auto& r : rows) {
      const json& object = of_row(r);
      const auto it = object.find(key);
      values.push_back(it == object.end() ? &missing : &*it);
    }
    add_json_column(table, key, values);
  };
  for (const std::string& p : parameters) add(p, [](const StudyDatabase::Row& r) -> const json& { return r.parameters; });
  for (const std::string& k : metric_keys) add(k, [](const StudyDatabase::Row& r) -> const json& { return r.metrics; });
  auto& run_time = table.numbers("run_time_s", "s");
  auto& error = table.texts("error");
  for (const auto& r : rows) {
    run_time.push_back(r.run_time);
    error.push_back(r.error);
  }
  return table;
}

void export_study(const std::filesystem::path& database, const std::filesystem::path& csv) {
  const StudyDatabase db(database);
  std::vector<std::string> parameters;
  for (const auto& p : db.definition().value("parameters", json::array())) parameters.push_back(p.get<std::string>());
  OutputTransaction out(folder_of(csv));
  write_table(out, csv.filename().string(), study_table(parameters, db.rows()));
  out.commit();
}

}  // namespace poundsim::io
