#include "poundsim/io/continuation_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/error.hpp"
#include "poundsim/io/frequency_response_run.hpp"
#include "poundsim/io/output_files.hpp"
#include "poundsim/model/dimensionless.hpp"

namespace poundsim::io {

namespace {

const ContinuedParameter& parameter_of(const RunInput& input) {
  if (!input.parameter || !input.frf) {
    throw InputError(fmt::format("{}: analysis.kind = \"continuation\" needs [frf] and [parameter]", input.source.string()));
  }
  return *input.parameter;
}

/// The model with the parameter at p, read as the file would be with `--set key=p`.
Model model_with(const RunInput& input, const ContinuedParameter& c, double p) {
  const Setting setting = make_setting(c.key, {p});
  return with_settings(input, {&setting, 1}).model;
}

}  // namespace

ContinuationRunResult analyse_continuation(const RunInput& input) {
  const ContinuedParameter& c = parameter_of(input);
  const auto start = std::chrono::steady_clock::now();
  // The ends and the start first: a value the model refuses is the file's error, named where the
  // key is given, before any run.
  for (const double p : {c.min, c.start, c.max}) {
    try {
      (void)model_with(input, c, p);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: parameter.key: at {} = {}: {}", c.where, c.key, p, e.what()));
    }
  }
  // A corrector step may try a value just past an end (the point there is discarded, and the
  // branch's last point is shot on the end itself): the model is held at the end beyond it.
  const auto model_at = [&](double p) { return model_with(input, c, std::clamp(p, c.min, c.max)); };
  ContinuationRunResult result{.input = input, .points = {}, .run_time = 0};
  try {
    result.points = parameter_response_by_continuation(model_at, c.min, c.max, c.start, frequency_response_options(input));
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", input.source.string(), e.what()));
  }
  result.run_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

Table continuation_table(const ContinuationRunResult& result) {
  std::vector<FrfPoint> responses;
  responses.reserve(result.points.size());
  for (const ParameterPoint& p : result.points) responses.push_back(p.response);
  const ContinuedParameter& c = parameter_of(result.input);
  Table table = frf_table(model_with(result.input, c, c.start), responses);
  TableColumn parameter{.name = "parameter", .unit = "", .values = TableColumn::Numbers{}};
  auto& values = std::get<TableColumn::Numbers>(parameter.values);
  for (const ParameterPoint& p : result.points) values.push_back(p.parameter);
  table.columns().push_front(std::move(parameter));
  return table;
}

nlohmann::json to_json(const ContinuationRunResult& result) {
  using nlohmann::json;
  const RunInput& input = result.input;
  const ContinuedParameter& c = parameter_of(input);
  const FrfSettings& f = *input.frf;
  std::map<int, json> by_branch;
  json bifurcations = json::array();
  for (const ParameterPoint& point : result.points) {
    const FrfPoint& p = point.response;
    json& b = by_branch[p.branch_id];
    if (b.is_null()) {
      b = {{"branch", p.branch_id}, {"periodicity", p.periodicity}, {"parent", p.parent_branch}, {"points", 0},
           {"stable_points", 0}, {"parameter_min", point.parameter}, {"parameter_max", point.parameter}};
    }
    b["points"] = b["points"].get<int>() + 1;
    if (p.stable) b["stable_points"] = b["stable_points"].get<int>() + 1;
    b["parameter_min"] = std::min(b["parameter_min"].get<double>(), point.parameter);
    b["parameter_max"] = std::max(b["parameter_max"].get<double>(), point.parameter);
    if (p.bifurcation != BifurcationKind::none) {
      bifurcations.push_back({{"branch", p.branch_id}, {"kind", std::string(to_string(p.bifurcation))},
                              {"parameter", point.parameter},
                              {"max_multiplier", p.multipliers.empty() ? 0.0 : std::abs(p.multipliers.front())}});
    }
  }
  json branches = json::array();
  for (auto& [id, b] : by_branch) branches.push_back(std::move(b));
  return {{"poundsim_version", POUNDSIM_VERSION},
          {"input", input.source.string()},
          {"title", input.title},
          {"analysis",
           {{"kind", "continuation"},
            {"integrator", "exact"},
            {"amplitude_g", f.amplitude_g},
            {"ratio", f.ratios.front()},
            {"steps_per_period", f.steady.steps_per_period}}},
          {"parameter", {{"key", c.key}, {"min", c.min}, {"max", c.max}, {"start", c.start}}},
          {"omega1_rad_s", reference_frequency(model_with(input, c, c.start))},
          {"weight1_N", reference_weight(model_with(input, c, c.start))},
          {"points", result.points.size()},
          {"branches", branches},
          {"bifurcations", bifurcations},
          {"run_time_s", result.run_time}};
}

std::string report(const ContinuationRunResult& result, const std::filesystem::path& out_dir) {
  const ContinuedParameter& c = parameter_of(result.input);
  const nlohmann::json summary = to_json(result);
  std::string text = fmt::format(
      "poundsim {}: {} (continuation in {} from {} to {} at ω̄/ω₁ = {}, {} points, {:.3f} s)\n", POUNDSIM_VERSION,
      result.input.source.string(), c.key, c.min, c.max, result.input.frf->ratios.front(), result.points.size(),
      result.run_time);
  for (const auto& b : summary["branches"]) {
    text += fmt::format("  branch {}: period {}, {} from {:.6g} to {:.6g}, {} of {} points stable\n", b["branch"].get<int>(),
                        b["periodicity"].get<int>(), c.key, b["parameter_min"].get<double>(),
                        b["parameter_max"].get<double>(), b["stable_points"].get<int>(), b["points"].get<int>());
  }
  for (const auto& b : summary["bifurcations"]) {
    text += fmt::format("  {} on branch {} at {} = {:.9g}\n", b["kind"].get<std::string>(), b["branch"].get<int>(), c.key,
                        b["parameter"].get<double>());
  }
  text += fmt::format("  wrote {}/orbits.csv, summary.json, input.toml\n", out_dir.string());
  return text;
}

ContinuationRunResult run_continuation(const RunInput& input, const std::filesystem::path& out_dir) {
  ContinuationRunResult result = analyse_continuation(input);
  OutputTransaction out(out_dir);
  write_csv(out.open("orbits.csv"), continuation_table(result));
  out.write_json("summary.json", to_json(result));
  // As written: the key names the file's own form (model.dimensionless.…), which to_toml rewrites.
  out.open("input.toml").text(to_toml_as_written(input));
  out.commit();
  return result;
}

}  // namespace poundsim::io
