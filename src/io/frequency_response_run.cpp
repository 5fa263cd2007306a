#include "poundsim/io/frequency_response_run.hpp"

#include <algorithm>
#include <chrono>
#include <complex>
#include <limits>
#include <numbers>
#include <tuple>
#include <map>

#include <fmt/format.h>

#include "poundsim/error.hpp"
#include "poundsim/io/json_fields.hpp"
#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/units.hpp"

namespace poundsim::io {

FrequencyResponseOptions frequency_response_options(const RunInput& input) {
  if (!input.frf) throw InputError(fmt::format("{}: no [frf] table", input.source.string()));
  const FrfSettings& f = *input.frf;
  FrequencyResponseOptions o;
  o.amplitude = f.amplitude_g * standard_gravity;
  o.ratios = f.ratios;
  o.method = f.method;
  o.sweep = f.sweep;
  o.steady = f.steady;
  o.shooting = f.shooting;
  o.continuation = f.continuation;
  o.time_history = input.analysis.options;
  o.threads = f.threads;
  o.lanes = f.lanes;
  return o;
}

Table frf_table(const Model& model, const std::vector<FrfPoint>& points) {
  const auto frames = static_cast<std::size_t>(model.frame_count());
  const double w1 = reference_weight(model);
  Table table;
  // Per frame f (from 1): the column `pattern` of f holds values(point)[f − 1] ÷ scale.
  const auto per_frame = [&](std::string_view pattern, std::string_view unit, double scale, const auto& values) {
    for (std::size_t f = 0; f < frames; ++f) {
      auto& column = table.numbers(fmt::format(fmt::runtime(pattern), f + 1), std::string(unit));
      for (const FrfPoint& p : points) column.push_back(values(p)[f] / scale);
    }
  };
  const auto each = [&](auto& column, const auto& value) {
    for (const FrfPoint& p : points) column.push_back(value(p));
  };
  each(table.numbers("ratio", "1"), [](const FrfPoint& p) { return p.ratio; });
  per_frame("V{}_W", "1", w1, [](const FrfPoint& p) -> const auto& { return p.interacting.base_shear; });
  per_frame("V{}_free_W", "1", w1, [](const FrfPoint& p) -> const auto& { return p.free.base_shear; });
  each(table.integers("periodicity"), [](const FrfPoint& p) { return static_cast<std::int64_t>(p.periodicity); });
  each(table.texts("branch"), [](const FrfPoint& p) {
    return p.continued ? std::string("continuation") : std::string(to_string(p.branch));
  });
  each(table.integers("transient_periods"), [](const FrfPoint& p) { return static_cast<std::int64_t>(p.transient_periods); });
  each(table.numbers("omega_rad_s", "rad/s"), [](const FrfPoint& p) { return p.omega; });
  per_frame("S{}_W", "1", w1, [](const FrfPoint& p) -> const auto& { return p.interacting.storey_shear; });
  per_frame("S{}_free_W", "1", w1, [](const FrfPoint& p) -> const auto& { return p.free.storey_shear; });
  per_frame("top{}_m", "m", 1.0, [](const FrfPoint& p) -> const auto& { return p.interacting.top_displacement; });
  per_frame("top{}_free_m", "m", 1.0, [](const FrfPoint& p) -> const auto& { return p.free.top_displacement; });
  each(table.integers("events"), [](const FrfPoint& p) { return static_cast<std::int64_t>(p.events); });
  each(table.integers("impacts"), [](const FrfPoint& p) { return static_cast<std::int64_t>(p.impacts); });
  if (std::none_of(points.begin(), points.end(), [](const FrfPoint& p) { return p.continued; })) return table;
  // Continuation: the branch, the stability and what the multipliers say.
  each(table.integers("branch_id"), [](const FrfPoint& p) { return static_cast<std::int64_t>(p.branch_id); });
  each(table.integers("parent_branch"), [](const FrfPoint& p) { return static_cast<std::int64_t>(p.parent_branch); });
  each(table.integers("stable"), [](const FrfPoint& p) { return static_cast<std::int64_t>(p.stable ? 1 : 0); });
  each(table.numbers("max_multiplier", "1"), [](const FrfPoint& p) {
    return p.multipliers.empty() ? std::numeric_limits<double>::quiet_NaN() : std::abs(p.multipliers.front());
  });
  each(table.texts("bifurcation"), [](const FrfPoint& p) { return std::string(to_string(p.bifurcation)); });
  // The orbit's minimal period in seconds and its state on the Poincaré section, from which it
  // repeats: enough to restart it or check it with another solver.
  each(table.numbers("period_s", "s"), [](const FrfPoint& p) {
    return p.periodicity > 0 ? p.periodicity * 2 * std::numbers::pi / p.omega : std::numeric_limits<double>::quiet_NaN();
  });
  const DofLayout layout(model);
  for (const auto& [name, unit, of] : {std::tuple{"section_u_{}_{}", "m", &FrfPoint::section_u},
                                       std::tuple{"section_v_{}_{}", "m/s", &FrfPoint::section_v}}) {
    for (int dof = 0; dof < layout.size(); ++dof) {
      auto& column = table.numbers(fmt::format(fmt::runtime(name), layout.frame_of(dof) + 1, layout.floor_of(dof) + 1), unit);
      for (const FrfPoint& p : points) {
        const std::vector<double>& values = p.*of;
        column.push_back(values.empty() ? std::numeric_limits<double>::quiet_NaN() : values[static_cast<std::size_t>(dof)]);
      }
    }
  }
  each(table.texts("multipliers"), [](const FrfPoint& p) {
    std::string text;
    for (const std::complex<double>& m : p.multipliers) {
      if (!text.empty()) text += ' ';
      text += m.imag() == 0.0 ? fmt::format("{:.9g}", m.real()) : fmt::format("{:.9g}{:+.9g}j", m.real(), m.imag());
    }
    return text;
  });
  return table;
}

FrequencyResponseResult frequency_response_result(const RunInput& input, std::vector<FrfPoint> points,
                                                  double run_time) {
  FrequencyResponseResult result{.input = input, .points = std::move(points), .branches = {}, .run_time = run_time};
  const Model& model = input.model;
  const double w1 = reference_weight(model);
  for (const FrfPoint& p : result.points) {
    // Continued orbits: the peaks a response can settle on are those of the stable ones.
    if (p.continued && !p.stable) continue;
    BranchPeaks& b = result.branches[p.continued ? std::string("continuation") : std::string(to_string(p.branch))];
    b.frames.resize(static_cast<std::size_t>(model.frame_count()));
    ++b.points;
    ++b.periodicity[p.periodicity];
    for (std::size_t f = 0; f < b.frames.size(); ++f) {
      FramePeaks& fr = b.frames[f];
      const double v = p.interacting.base_shear[f] / w1;
      const double vf = p.free.base_shear[f] / w1;
      if (v > fr.peak_v_w) {
        fr.peak_v_w = v;
        fr.peak_ratio = p.ratio;
      }
      if (vf > fr.peak_free_v_w) {
        fr.peak_free_v_w = vf;
        fr.peak_free_ratio = p.ratio;
      }
    }
  }
  return result;
}

std::string report(const FrequencyResponseResult& r, const std::filesystem::path& out_dir) {
  std::string text = fmt::format("poundsim {}: {} (frequency response, {} points, {:.3f} s)\n", POUNDSIM_VERSION,
                                 r.input.source.string(), r.input.frf->ratios.size(), r.run_time);
  for (const auto& [branch, b] : r.branches) {
    for (std::size_t f = 0; f < b.frames.size(); ++f) {
      const FramePeaks& p = b.frames[f];
      text += fmt::format("  {:<4} frame {}: peak V/W {:.4f} at ω̄/ω₁ = {:.3f} (free {:.4f} at {:.3f})\n", branch,
                          f + 1, p.peak_v_w, p.peak_ratio, p.peak_free_v_w, p.peak_free_ratio);
    }
  }
  text += fmt::format("  wrote {}/frf.csv, summary.json, input.toml\n", out_dir.string());
  return text;
}

nlohmann::json to_json(const FrequencyResponseResult& result) {
  using nlohmann::json;
  const RunInput& input = result.input;
  const Model& model = input.model;
  const double w1 = reference_weight(model);
  json branches = json::object();
  for (const auto& [name, b] : result.branches) {
    json periodicity = json::object();
    for (const auto& [k, n] : b.periodicity) periodicity[std::to_string(k)] = n;
    json frames = json::array();
    for (std::size_t f = 0; f < b.frames.size(); ++f) {
      const FramePeaks& p = b.frames[f];
      frames.push_back({{"frame", f + 1},
                        {"peak_V_W", p.peak_v_w}, {"peak_ratio", p.peak_ratio},
                        {"peak_free_V_W", p.peak_free_v_w}, {"peak_free_ratio", p.peak_free_ratio}});
    }
    branches[name] = {{"points", b.points}, {"periodicity", periodicity}, {"frames", frames}};
  }
  const FrfSettings& f = *input.frf;
  json frames = json::array();
  for (const Frame& fr : model.frames) {
    const Eigen::VectorXd w = natural_frequencies(fr);
    frames.push_back({{"storeys", fr.storeys()},
                      {"weight_N", weight(fr)},
                      {"natural_frequencies_rad_s", std::vector<double>(w.begin(), w.end())}});
  }
  json continuation = nullptr;
  if (f.method == FrfMethod::continuation) {
    std::vector<double> ratios;
    for (const FrfPoint& p : result.points) ratios.push_back(p.ratio);
    continuation = to_json(continued_branches(result.points, ratios), "ratio");
    continuation["simulated_points"] =
        std::count_if(result.points.begin(), result.points.end(), [](const FrfPoint& p) { return !p.continued; });
  }
  json summary{{"poundsim_version", POUNDSIM_VERSION},
               {"input", input.source.string()},
               {"title", input.title},
               {"analysis",
                {{"kind", "frf"},
                 {"integrator", std::string(to_string(input.analysis.options.integrator))},
                 {"amplitude_g", f.amplitude_g},
                 {"points", f.ratios.size()},
                 {"ratio_min", f.ratios.front()},
                 {"ratio_max", f.ratios.back()},
                 {"method", std::string(name_in(frf_method_names, f.method))},
                 {"sweep", std::string(to_string(f.sweep))},
                 {"steps_per_period", f.steady.steps_per_period},
                 {"tolerance", f.steady.tolerance},
                 {"max_periods", f.steady.max_periods},
                 {"max_periodicity", f.steady.max_periodicity},
                 {"window_periods", f.steady.window_periods}}},
               {"omega1_rad_s", reference_frequency(model)},
               {"weight1_N", w1},
               {"frames", frames},
               {"branches", branches},
               {"run_time_s", result.run_time}};
  if (!continuation.is_null()) summary["continuation"] = std::move(continuation);
  if (input.dimensionless) {
    const DimensionlessParameters& d = *input.dimensionless;
    summary["dimensionless"] = fields_json(d, {"mass1"});  // a response is per unit mass: no scale
  }
  return summary;
}

ContinuedBranches continued_branches(const std::vector<FrfPoint>& points, const std::vector<double>& at) {
  ContinuedBranches out;
  std::map<int, ContinuedBranch> by_branch;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const FrfPoint& p = points[i];
    if (!p.continued) continue;
    const auto [it, fresh] = by_branch.try_emplace(p.branch_id);
    ContinuedBranch& b = it->second;
    if (fresh) b = {.branch = p.branch_id, .periodicity = p.periodicity, .parent = p.parent_branch, .points = 0,
                    .stable_points = 0, .min = at[i], .max = at[i]};
    ++b.points;
    if (p.stable) ++b.stable_points;
    b.min = std::min(b.min, at[i]);
    b.max = std::max(b.max, at[i]);
    if (p.bifurcation != BifurcationKind::none) {
      out.bifurcations.push_back({.branch = p.branch_id, .kind = p.bifurcation, .at = at[i],
                                  .max_multiplier = p.multipliers.empty() ? 0.0 : std::abs(p.multipliers.front())});
    }
  }
  for (auto& [id, b] : by_branch) out.branches.push_back(b);
  return out;
}

nlohmann::json to_json(const ContinuedBranches& continued, std::string_view x) {
  using nlohmann::json;
  const std::string name(x), lo = name + "_min", hi = name + "_max";
  json branches = json::array(), bifurcations = json::array();
  for (const ContinuedBranch& b : continued.branches) {
    branches.push_back({{"branch", b.branch}, {"periodicity", b.periodicity}, {"parent", b.parent},
                        {"points", b.points}, {"stable_points", b.stable_points}, {lo, b.min}, {hi, b.max}});
  }
  for (const ContinuedBifurcation& b : continued.bifurcations) {
    bifurcations.push_back({{"branch", b.branch}, {"kind", std::string(to_string(b.kind))}, {name, b.at},
                            {"max_multiplier", b.max_multiplier}});
  }
  return {{"branches", std::move(branches)}, {"bifurcations", std::move(bifurcations)}};
}

FrequencyResponseResult analyse_frequency_response(const RunInput& input,
                                                   const std::function<void(int, int)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  FrequencyResponseOptions options = frequency_response_options(input);
  options.progress = progress;
  std::vector<FrfPoint> points;
  try {
    points = frequency_response(input.model, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", input.source.string(), e.what()));
  }
  const double run_time =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return frequency_response_result(input, std::move(points), run_time);
}

FrequencyResponseResult run_frequency_response(const RunInput& input, const std::filesystem::path& out_dir,
                                               const std::function<void(int, int)>& progress) {
  FrequencyResponseResult result = analyse_frequency_response(input, progress);
  OutputTransaction out(out_dir);
  write_table(out, "frf.csv", frf_table(input.model, result.points));
  out.write_json("summary.json", to_json(result));
  out.open("input.toml").text(to_toml(input));
  out.commit();
  return result;
}

}  // namespace poundsim::io
