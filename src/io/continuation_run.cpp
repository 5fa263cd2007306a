#include "poundsim/io/continuation_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>
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
  ContinuationRunResult result{.input = input, .points = {}, .start_model = {}, .run_time = 0};
  for (const double p : {c.min, *c.start, c.max}) {
    try {
      Model model = model_with(input, c, p);
      if (p == *c.start) result.start_model = std::move(model);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: parameter.key: at {} = {}: {}", c.where, c.key, p, e.what()));
    }
  }
  // A corrector step may try a value just past an end (the point there is discarded, and the
  // branch's last point is shot on the end itself): the model is held at the end beyond it.
  const auto model_at = [&](double p) { return model_with(input, c, std::clamp(p, c.min, c.max)); };
  try {
    result.points = parameter_response_by_continuation(model_at, c.min, c.max, *c.start, frequency_response_options(input));
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", input.source.string(), e.what()));
  }
  result.run_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

namespace {

/// The continued points' responses and their parameters, as two columns.
std::pair<std::vector<FrfPoint>, std::vector<double>> split(const std::vector<ParameterPoint>& points) {
  std::pair<std::vector<FrfPoint>, std::vector<double>> out;
  out.first.reserve(points.size());
  out.second.reserve(points.size());
  for (const ParameterPoint& p : points) {
    out.first.push_back(p.response);
    out.second.push_back(p.parameter);
  }
  return out;
}

}  // namespace

Table continuation_table(const ContinuationRunResult& result) {
  auto [responses, parameters] = split(result.points);
  Table table = frf_table(result.start_model, responses);
  table.columns().push_front({.name = "parameter", .unit = "", .values = std::move(parameters)});
  return table;
}

nlohmann::json to_json(const ContinuationRunResult& result) {
  const RunInput& input = result.input;
  const ContinuedParameter& c = parameter_of(input);
  const FrfSettings& f = *input.frf;
  const auto [responses, parameters] = split(result.points);
  nlohmann::json summary = to_json(continued_branches(responses, parameters), "parameter");
  summary.update({{"poundsim_version", POUNDSIM_VERSION},
                  {"input", input.source.string()},
                  {"title", input.title},
                  {"analysis",
                   {{"kind", "continuation"},
                    {"integrator", "exact"},
                    {"amplitude_g", f.amplitude_g},
                    {"ratio", f.ratios.front()},
                    {"steps_per_period", f.steady.steps_per_period}}},
                  {"parameter", {{"key", c.key}, {"min", c.min}, {"max", c.max}, {"start", *c.start}}},
                  {"omega1_rad_s", reference_frequency(result.start_model)},
                  {"weight1_N", reference_weight(result.start_model)},
                  {"points", result.points.size()},
                  {"run_time_s", result.run_time}});
  return summary;
}

std::string report(const ContinuationRunResult& result, const std::filesystem::path& out_dir) {
  const ContinuedParameter& c = parameter_of(result.input);
  const auto [responses, parameters] = split(result.points);
  const ContinuedBranches continued = continued_branches(responses, parameters);
  std::string text = fmt::format(
      "poundsim {}: {} (continuation in {} from {} to {} at ω̄/ω₁ = {}, {} points, {:.3f} s)\n", POUNDSIM_VERSION,
      result.input.source.string(), c.key, c.min, c.max, result.input.frf->ratios.front(), result.points.size(),
      result.run_time);
  for (const ContinuedBranch& b : continued.branches) {
    text += fmt::format("  branch {}: period {}, {} from {:.6g} to {:.6g}, {} of {} points stable\n", b.branch,
                        b.periodicity, c.key, b.min, b.max, b.stable_points, b.points);
  }
  for (const ContinuedBifurcation& b : continued.bifurcations) {
    text += fmt::format("  {} on branch {} at {} = {:.9g}\n", to_string(b.kind), b.branch, c.key, b.at);
  }
  text += fmt::format("  wrote {}/orbits.csv, summary.json, input.toml\n", out_dir.string());
  return text;
}

ContinuationRunResult run_continuation(const RunInput& input, const std::filesystem::path& out_dir) {
  ContinuationRunResult result = analyse_continuation(input);
  OutputTransaction out(out_dir);
  write_table(out, "orbits.csv", continuation_table(result));
  out.write_json("summary.json", to_json(result));
  // As written: the key names the file's own form (model.dimensionless.…), which to_toml rewrites.
  out.open("input.toml").text(to_toml_as_written(input));
  out.commit();
  return result;
}

}  // namespace poundsim::io
