#include "poundsim/analysis/figures_of_merit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/model/laws/paper_gap.hpp"
#include "poundsim/units.hpp"

namespace poundsim {

namespace {

double ratio(double value, double reference) { return reference > 0 ? value / reference : 0.0; }

/// Calls f(out, in) for every figure of `in` and the same figure of `out` (whose arrays it sizes
/// like in's), so that an ensemble's mean and maximum are taken figure by figure.
template <class F>
void zip_figures(TimeHistoryFigures& out, const TimeHistoryFigures& in, F&& f) {
  f(out.energy_residual, in.energy_residual);
  f(out.pga_g, in.pga_g);
  out.frames.resize(in.frames.size());
  for (std::size_t k = 0; k < in.frames.size(); ++k) {
    FrameFigures& o = out.frames[k];
    const FrameFigures& i = in.frames[k];
    f(o.peak_V_W, i.peak_V_W);
    f(o.free_peak_V_W, i.free_peak_V_W);
    f(o.ratio_to_free, i.ratio_to_free);
    f(o.peak_drift_m, i.peak_drift_m);
    f(o.free_peak_drift_m, i.free_peak_drift_m);
    f(o.peak_drift_ratio, i.peak_drift_ratio);
    f(o.free_peak_drift_ratio, i.free_peak_drift_ratio);
    f(o.peak_abs_acc_g, i.peak_abs_acc_g);
    f(o.free_peak_abs_acc_g, i.free_peak_abs_acc_g);
    f(o.residual_drift_m, i.residual_drift_m);
    f(o.residual_drift_ratio, i.residual_drift_ratio);
    f(o.hysteretic_energy_J, i.hysteretic_energy_J);
    o.storey_heights = i.storey_heights;
  }
  out.floors.resize(in.floors.size());
  for (std::size_t k = 0; k < in.floors.size(); ++k) {
    FloorFigures& o = out.floors[k];
    const FloorFigures& i = in.floors[k];
    o.frame = i.frame;
    o.floor = i.floor;
    f(o.peak_u_m, i.peak_u_m);
    f(o.free_peak_u_m, i.free_peak_u_m);
    f(o.amp_u, i.amp_u);
    f(o.amp_drift, i.amp_drift);
    f(o.amp_acc, i.amp_acc);
    f(o.peak_drift_m, i.peak_drift_m);
    f(o.peak_drift_ratio, i.peak_drift_ratio);
    f(o.peak_abs_acc_g, i.peak_abs_acc_g);
    o.storey_height = i.storey_height;
  }
  out.joints.resize(in.joints.size());
  for (std::size_t k = 0; k < in.joints.size(); ++k) {
    out.joints[k].left_frame = in.joints[k].left_frame;
    out.joints[k].floor = in.joints[k].floor;
    out.joints[k].label = in.joints[k].label;
    f(out.joints[k].min_gap_m, in.joints[k].min_gap_m);
  }
  out.gaps.resize(in.gaps.size());
  for (std::size_t k = 0; k < in.gaps.size(); ++k) {
    out.gaps[k].label = in.gaps[k].label;
    out.gaps[k].has_stroke = in.gaps[k].has_stroke;
    f(out.gaps[k].max_force_N, in.gaps[k].max_force_N);
    f(out.gaps[k].stroke_use, in.gaps[k].stroke_use);
  }
  f(out.impacts, in.impacts);
  f(out.max_impact_impulse_Ns, in.max_impact_impulse_Ns);
  f(out.max_velocity_jump_m_s, in.max_velocity_jump_m_s);
  f(out.max_gap_force_N, in.max_gap_force_N);
  f(out.max_peak_V_W, in.max_peak_V_W);
  f(out.max_ratio_to_free, in.max_ratio_to_free);
  f(out.max_peak_drift_m, in.max_peak_drift_m);
  f(out.max_peak_drift_ratio, in.max_peak_drift_ratio);
  f(out.max_peak_abs_acc_g, in.max_peak_abs_acc_g);
  f(out.max_residual_drift_m, in.max_residual_drift_m);
  f(out.max_residual_drift_ratio, in.max_residual_drift_ratio);
  f(out.max_stroke_use, in.max_stroke_use);
  f(out.hysteretic_energy_J, in.hysteretic_energy_J);
}

void add_columns(const TimeHistoryFigures& t, const std::string& prefix, bool counts,
                 std::vector<FigureColumn>& out) {
  const auto add = [&](std::string name, double value, bool count = false) {
    out.push_back({prefix + name, value, counts && count});
  };
  add("energy_residual", t.energy_residual);
  add("pga_g", t.pga_g);
  bool drift_ratios = false, strokes = false;
  for (std::size_t f = 0; f < t.frames.size(); ++f) {
    const FrameFigures& frame = t.frames[f];
    add(fmt::format("peak_V{}_W", f + 1), frame.peak_V_W);
    add(fmt::format("free_peak_V{}_W", f + 1), frame.free_peak_V_W);
    add(fmt::format("ratio_to_free_{}", f + 1), frame.ratio_to_free);
    add(fmt::format("peak_drift_{}_m", f + 1), frame.peak_drift_m);
    add(fmt::format("free_peak_drift_{}_m", f + 1), frame.free_peak_drift_m);
    add(fmt::format("peak_abs_acc_{}_g", f + 1), frame.peak_abs_acc_g);
    add(fmt::format("free_peak_abs_acc_{}_g", f + 1), frame.free_peak_abs_acc_g);
    add(fmt::format("residual_drift_{}_m", f + 1), frame.residual_drift_m);
    add(fmt::format("hysteretic_energy_{}_J", f + 1), frame.hysteretic_energy_J);
    if (frame.storey_heights) {
      drift_ratios = true;
      add(fmt::format("peak_drift_ratio_{}", f + 1), frame.peak_drift_ratio);
      add(fmt::format("free_peak_drift_ratio_{}", f + 1), frame.free_peak_drift_ratio);
      add(fmt::format("residual_drift_ratio_{}", f + 1), frame.residual_drift_ratio);
    }
  }
  for (const FloorFigures& floor : t.floors) {
    const std::string at = fmt::format("{}_{}", floor.frame + 1, floor.floor + 1);
    add("peak_u_" + at + "_m", floor.peak_u_m);
    add("free_peak_u_" + at + "_m", floor.free_peak_u_m);
    add("amp_u_" + at, floor.amp_u);
    add("amp_drift_" + at, floor.amp_drift);
    add("amp_acc_" + at, floor.amp_acc);
    add("peak_drift_" + at + "_m", floor.peak_drift_m);
    add("peak_abs_acc_" + at + "_g", floor.peak_abs_acc_g);
    if (floor.storey_height) add("peak_drift_ratio_" + at, floor.peak_drift_ratio);
  }
  for (const JointFigures& j : t.joints) add("min_gap_" + j.label + "_m", j.min_gap_m);
  for (const GapFigures& g : t.gaps) {
    add("gap_force_" + g.label + "_N", g.max_force_N);
    if (g.has_stroke) {
      strokes = true;
      add("stroke_use_" + g.label, g.stroke_use);
    }
  }
  add(std::string(column_names::max_peak_V_W), t.max_peak_V_W);
  add(std::string(column_names::max_ratio_to_free), t.max_ratio_to_free);
  add("impacts", t.impacts, true);
  add("max_impact_impulse_Ns", t.max_impact_impulse_Ns);
  add("max_velocity_jump_m_s", t.max_velocity_jump_m_s);
  add("max_gap_force_N", t.max_gap_force_N);
  add("max_peak_drift_m", t.max_peak_drift_m);
  add("max_peak_abs_acc_g", t.max_peak_abs_acc_g);
  add("max_residual_drift_m", t.max_residual_drift_m);
  add("hysteretic_energy_J", t.hysteretic_energy_J);
  if (drift_ratios) {
    add("max_peak_drift_ratio", t.max_peak_drift_ratio);
    add("max_residual_drift_ratio", t.max_residual_drift_ratio);
  }
  if (strokes) add("max_stroke_use", t.max_stroke_use);
}

/// The figures a point is compared by: a single response's, or an ensemble's mean.
struct Headline {
  double max_peak_V_W, max_ratio_to_free;
  const std::vector<FrameFigures>* frames;
};

Headline headline(const PointFigures& p) {
  return std::visit(
      [](const auto& r) -> Headline {
        if constexpr (std::is_same_v<std::decay_t<decltype(r)>, EnsembleFigures>) {
          return {r.mean.max_peak_V_W, r.mean.max_ratio_to_free, &r.mean.frames};
        } else {
          return {r.max_peak_V_W, r.max_ratio_to_free, &r.frames};
        }
      },
      p.response);
}

}  // namespace

double PointFigures::max_peak_V_W() const { return headline(*this).max_peak_V_W; }

double PointFigures::max_ratio_to_free() const { return headline(*this).max_ratio_to_free; }

std::vector<double> PointFigures::peak_V_W() const {
  std::vector<double> peaks;
  for (const FrameFigures& f : *headline(*this).frames) peaks.push_back(f.peak_V_W);
  return peaks;
}

void PointFigures::compare_with_bare(std::span<const FigureColumn> bare_columns) {
  const auto bare_figure = [&](const std::string& name) {
    for (const FigureColumn& c : bare_columns) {
      if (c.name == name) return c.value;
    }
    throw std::invalid_argument(fmt::format("bare pounding has no figure {}", name));
  };
  const std::vector<double> peaks = peak_V_W();
  BareComparison b;
  // A single response's figures, or an ensemble's mean: the frames compared.
  const TimeHistoryFigures* history = std::visit(
      [](const auto& r) -> const TimeHistoryFigures* {
        using R = std::decay_t<decltype(r)>;
        if constexpr (std::is_same_v<R, TimeHistoryFigures>) return &r;
        if constexpr (std::is_same_v<R, EnsembleFigures>) return &r.mean;
        return nullptr;
      },
      response);
  b.time_history = history != nullptr;
  const auto compare = [](double value, double reference, std::vector<double>& bare_values,
                          std::vector<double>& ratios, double& largest) {
    bare_values.push_back(reference);
    ratios.push_back(ratio(value, reference));
    largest = std::max(largest, ratios.back());
  };
  for (std::size_t f = 0; f < peaks.size(); ++f) {
    compare(peaks[f], bare_figure(fmt::format("peak_V{}_W", f + 1)), b.bare_peak_V_W, b.ratio_to_bare,
            b.max_ratio_to_bare);
    if (history == nullptr) continue;
    const FrameFigures& frame = history->frames[f];
    compare(frame.peak_drift_m, bare_figure(fmt::format("peak_drift_{}_m", f + 1)), b.bare_peak_drift_m,
            b.ratio_to_bare_drift, b.max_ratio_to_bare_drift);
    compare(frame.peak_abs_acc_g, bare_figure(fmt::format("peak_abs_acc_{}_g", f + 1)), b.bare_peak_abs_acc_g,
            b.ratio_to_bare_acc, b.max_ratio_to_bare_acc);
  }
  bare = std::move(b);
}

std::optional<double> PointFigures::figure(std::string_view name) const {
  for (const FigureColumn& c : columns()) {
    if (c.name == name) return c.value;
  }
  return std::nullopt;
}

std::vector<FigureColumn> PointFigures::columns() const {
  std::vector<FigureColumn> out;
  std::visit(
      [&](const auto& r) {
        using R = std::decay_t<decltype(r)>;
        if constexpr (std::is_same_v<R, FrfFigures>) {
          out.push_back({"points", static_cast<double>(r.points), true});
          out.push_back({"non_periodic", static_cast<double>(r.non_periodic), true});
          for (std::size_t f = 0; f < r.frames.size(); ++f) {
            out.push_back({fmt::format("peak_V{}_W", f + 1), r.frames[f].peak_V_W});
            out.push_back({fmt::format("peak_V{}_at", f + 1), r.frames[f].peak_at});
            out.push_back({fmt::format("free_peak_V{}_W", f + 1), r.frames[f].free_peak_V_W});
            out.push_back({fmt::format("ratio_to_free_{}", f + 1), r.frames[f].ratio_to_free});
          }
          out.push_back({std::string(column_names::max_peak_V_W), r.max_peak_V_W});
          out.push_back({std::string(column_names::max_ratio_to_free), r.max_ratio_to_free});
        } else if constexpr (std::is_same_v<R, TimeHistoryFigures>) {
          add_columns(r, "", true, out);
        } else {
          out.push_back({"records", static_cast<double>(r.records), true});
          add_columns(r.mean, "", false, out);  // a mean of counts need not be whole
          add_columns(r.max, "max_", false, out);
        }
      },
      response);
  if (bare) {
    for (std::size_t f = 0; f < bare->bare_peak_V_W.size(); ++f) {
      out.push_back({fmt::format("bare_peak_V{}_W", f + 1), bare->bare_peak_V_W[f]});
      out.push_back({fmt::format("ratio_to_bare_{}", f + 1), bare->ratio_to_bare[f]});
    }
    out.push_back({"max_ratio_to_bare", bare->max_ratio_to_bare});
    if (bare->time_history) {
      for (std::size_t f = 0; f < bare->bare_peak_drift_m.size(); ++f) {
        out.push_back({fmt::format("bare_peak_drift_{}_m", f + 1), bare->bare_peak_drift_m[f]});
        out.push_back({fmt::format("ratio_to_bare_drift_{}", f + 1), bare->ratio_to_bare_drift[f]});
        out.push_back({fmt::format("bare_peak_abs_acc_{}_g", f + 1), bare->bare_peak_abs_acc_g[f]});
        out.push_back({fmt::format("ratio_to_bare_acc_{}", f + 1), bare->ratio_to_bare_acc[f]});
      }
      out.push_back({"max_ratio_to_bare_drift", bare->max_ratio_to_bare_drift});
      out.push_back({"max_ratio_to_bare_acc", bare->max_ratio_to_bare_acc});
    }
  }
  return out;
}

FrfFigures frf_figures(const Model& model, const std::vector<FrfPoint>& response, double lo, double hi) {
  const BandPeaks b = band_peaks(model, response, lo, hi);
  FrfFigures out;
  out.points = b.points;
  out.non_periodic = b.non_periodic;
  for (std::size_t f = 0; f < b.interacting.size(); ++f) {
    const FrameFigures frame{.peak_V_W = b.interacting[f],
                             .free_peak_V_W = b.free[f],
                             .ratio_to_free = ratio(b.interacting[f], b.free[f]),
                             .peak_at = b.interacting_at[f]};
    out.max_peak_V_W = std::max(out.max_peak_V_W, frame.peak_V_W);
    out.max_ratio_to_free = std::max(out.max_ratio_to_free, frame.ratio_to_free);
    out.frames.push_back(frame);
  }
  return out;
}

namespace {

/// The stroke ε of an element whose law has one (the paper's, ε > 0).
std::optional<double> stroke_of(const GapElement& g) {
  if (const auto* paper = std::get_if<PaperGap>(&g.law); paper != nullptr && !paper->parameters.is_rigid_stop()) {
    return paper->parameters.shortening;
  }
  return std::nullopt;
}

}  // namespace

TimeHistoryFigures time_history_figures(const Model& model, const TimeHistoryAnalysis& run, double pga_g) {
  const double w = reference_weight(model);
  const ResponseStatistics& stats = run.statistics;
  const ResponseStatistics& free = run.free ? *run.free : run.statistics;  // no gap elements: free already
  TimeHistoryFigures out;
  out.energy_residual = run.max_relative_residual;
  out.pga_g = pga_g;
  for (std::size_t f = 0; f < stats.base_shear.size(); ++f) {
    const FrameFigures frame{.peak_V_W = stats.base_shear[f].value / w,
                             .free_peak_V_W = free.base_shear[f].value / w,
                             .ratio_to_free = ratio(stats.base_shear[f].value / w, free.base_shear[f].value / w)};
    out.max_peak_V_W = std::max(out.max_peak_V_W, frame.peak_V_W);
    out.max_ratio_to_free = std::max(out.max_ratio_to_free, frame.ratio_to_free);
    out.frames.push_back(frame);
  }
  for (int f = 0; f < model.frame_count(); ++f) {
    const Frame& structure = model.frames[static_cast<std::size_t>(f)];
    FrameFigures& frame = out.frames[static_cast<std::size_t>(f)];
    frame.storey_heights = !structure.storey_height.empty();
    for (int i = 0; i < structure.storeys(); ++i) {
      const auto d = static_cast<std::size_t>(run.layout.dof(f, i));
      const FloorResponse& a = stats.floors[d];
      const FloorResponse& b = free.floors[d];
      // A storey without a height has no drift ratio (its columns are not written).
      const double h = frame.storey_heights ? structure.storey_height[static_cast<std::size_t>(i)] : 0.0;
      const auto per_height = [&](double drift) { return h > 0 ? drift / h : 0.0; };
      const Peak a_abs = a.absolute_acceleration_with_impacts();
      out.max_velocity_jump_m_s = std::max(out.max_velocity_jump_m_s, a.velocity_jump.value);
      const double residual = d < run.final_drift.size() ? std::abs(run.final_drift[d]) : 0.0;
      const FloorFigures floor{.frame = f,
                               .floor = i,
                               .peak_u_m = a.displacement.value,
                               .free_peak_u_m = b.displacement.value,
                               .amp_u = ratio(a.displacement.value, b.displacement.value),
                               .amp_drift = ratio(a.drift.value, b.drift.value),
                               .amp_acc = ratio(a_abs.value, b.absolute_acceleration_with_impacts().value),
                               .peak_drift_m = a.drift.value,
                               .peak_drift_ratio = per_height(a.drift.value),
                               .peak_abs_acc_g = a_abs.value / standard_gravity,
                               .storey_height = frame.storey_heights};
      frame.peak_drift_m = std::max(frame.peak_drift_m, a.drift.value);
      frame.free_peak_drift_m = std::max(frame.free_peak_drift_m, b.drift.value);
      frame.peak_drift_ratio = std::max(frame.peak_drift_ratio, floor.peak_drift_ratio);
      frame.free_peak_drift_ratio = std::max(frame.free_peak_drift_ratio, per_height(b.drift.value));
      frame.peak_abs_acc_g = std::max(frame.peak_abs_acc_g, floor.peak_abs_acc_g);
      frame.free_peak_abs_acc_g =
          std::max(frame.free_peak_abs_acc_g, b.absolute_acceleration_with_impacts().value / standard_gravity);
      frame.residual_drift_m = std::max(frame.residual_drift_m, residual);
      frame.residual_drift_ratio = std::max(frame.residual_drift_ratio, per_height(residual));
      if (d < run.storey_hysteretic.size()) frame.hysteretic_energy_J += run.storey_hysteretic[d];
      out.floors.push_back(floor);
    }
    out.max_peak_drift_m = std::max(out.max_peak_drift_m, frame.peak_drift_m);
    out.max_peak_drift_ratio = std::max(out.max_peak_drift_ratio, frame.peak_drift_ratio);
    out.max_peak_abs_acc_g = std::max(out.max_peak_abs_acc_g, frame.peak_abs_acc_g);
    out.max_residual_drift_m = std::max(out.max_residual_drift_m, frame.residual_drift_m);
    out.max_residual_drift_ratio = std::max(out.max_residual_drift_ratio, frame.residual_drift_ratio);
    out.hysteretic_energy_J += frame.hysteretic_energy_J;
  }
  for (const NeighbourResponse& nb : free.neighbours) {
    out.joints.push_back({.left_frame = nb.left_frame,
                          .floor = nb.floor,
                          .min_gap_m = std::max(0.0, nb.max_approach),
                          .label = joint_label(nb.left_frame, nb.floor, nb.right_floor, nb.column)});
  }
  int impacts = 0;
  for (std::size_t p = 0; p < stats.gaps.size(); ++p) {
    const GapResponse& g = stats.gaps[p];
    const GapElement& element = model.gaps[p];
    impacts += g.impacts;
    out.max_impact_impulse_Ns = std::max(out.max_impact_impulse_Ns, g.impulse.value);
    out.max_gap_force_N = std::max(out.max_gap_force_N, g.force.value);
    GapFigures figures{.max_force_N = g.force.value,
                       .label = joint_label(element.left_frame, element.floor, element.floor_right(), element.column)};
    if (const std::optional<double> stroke = stroke_of(element)) {
      figures.has_stroke = true;
      figures.stroke_use = g.shortening.value / *stroke;
      out.max_stroke_use = std::max(out.max_stroke_use, figures.stroke_use);
    }
    out.gaps.push_back(std::move(figures));
  }
  out.impacts = impacts;
  return out;
}

EnsembleFigures ensemble_figures(std::span<const TimeHistoryFigures> records) {
  if (records.empty()) throw std::invalid_argument("an ensemble's figures need at least one record");
  EnsembleFigures out;
  out.records = static_cast<long>(records.size());
  // Figure by figure, in record order: the sum from 0, the maximum from −∞.
  zip_figures(out.mean, records.front(), [](double& sum, double) { sum = 0.0; });
  zip_figures(out.max, records.front(), [](double& max, double) { max = -std::numeric_limits<double>::infinity(); });
  for (const TimeHistoryFigures& r : records) {
    zip_figures(out.mean, r, [](double& sum, double x) { sum += x; });
    zip_figures(out.max, r, [](double& max, double x) { max = std::max(max, x); });
  }
  const auto n = static_cast<double>(records.size());
  zip_figures(out.mean, records.front(), [&](double& sum, double) { sum /= n; });
  return out;
}

}  // namespace poundsim
