#include "poundsim/analysis/figures_of_merit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <type_traits>

#include <fmt/format.h>

#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/model/laws/paper_gap.hpp"
#include "poundsim/units.hpp"

namespace poundsim {

namespace {

double ratio(double value, double reference) { return reference > 0 ? value / reference : 0.0; }

template <class T>
inline constexpr bool is_vector = false;
template <class T>
inline constexpr bool is_vector<std::vector<T>> = true;

/// Calls f(out, in) for every number of `in` and the same number of `out` (whose arrays it sizes
/// like in's, its attributes copied), so that an ensemble's mean and maximum are taken figure by
/// figure.
template <DeclaredFigures S, class F>
void zip_figures(S& out, const S& in, F&& f) {
  std::apply(
      [&](const auto&... field) {
        const auto one = [&](const auto& declared) {
          auto& o = out.*declared.member;
          const auto& i = in.*declared.member;
          using T = std::decay_t<decltype(o)>;
          if constexpr (std::is_same_v<T, double>) {
            f(o, i);
          } else if constexpr (is_vector<T>) {
            o.resize(i.size());
            for (std::size_t k = 0; k < i.size(); ++k) zip_figures(o[k], i[k], f);
          } else {
            o = i;
          }
        };
        (one(field), ...);
      },
      S::figures());
}

/// How a point's columns are written: a prefix (an ensemble's maxima: "max_"), whether counts
/// keep no decimal point, and which of the conditional figures are columns.
struct ColumnRules {
  std::string prefix;
  bool counts = true;
  bool frf = false;
  bool storey_heights = false;  ///< a frame has storey heights
  bool stroke = false;          ///< an element has a stroke
};

// Where `{}` of a column goes: the frame's number, the floor's frame_floor, the joint's label.
std::string place_of(const FrameFigures&, std::size_t k) { return std::to_string(k + 1); }
std::string place_of(const FloorFigures& f, std::size_t) { return fmt::format("{}_{}", f.frame + 1, f.floor + 1); }
std::string place_of(const JointFigures& j, std::size_t) { return j.label; }
std::string place_of(const GapFigures& g, std::size_t) { return g.label; }

// Whether a figure shown only `shown` is a column of s.
bool own_heights(const FrameFigures& f) { return f.storey_heights; }
bool own_heights(const FloorFigures& f) { return f.storey_height; }
template <class S>
bool own_heights(const S&) { return true; }
bool own_stroke(const GapFigures& g) { return g.has_stroke; }
template <class S>
bool own_stroke(const S&) { return true; }

template <class S>
bool is_column(const S& s, Shown shown, const ColumnRules& rules) {
  switch (shown) {
    case Shown::always: return true;
    case Shown::frf: return rules.frf;
    case Shown::time_history: return !rules.frf;
    case Shown::storey_heights: return !rules.frf && rules.storey_heights && own_heights(s);
    case Shown::stroke: return !rules.frf && rules.stroke && own_stroke(s);
    case Shown::never: return false;
  }
  return false;
}

/// Appends the columns of s, in declaration order; `place` fills the `{}` of its columns.
template <DeclaredFigures S>
void add_columns(const S& s, const std::string& place, const ColumnRules& rules, std::vector<FigureColumn>& out) {
  std::apply(
      [&](const auto&... field) {
        const auto one = [&](const auto& declared) {
          const auto& value = s.*declared.member;
          using T = std::decay_t<decltype(value)>;
          if constexpr (is_vector<T>) {
            for (std::size_t k = 0; k < value.size(); ++k) add_columns(value[k], place_of(value[k], k), rules, out);
          } else if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
            if (declared.column.empty() || !is_column(s, declared.shown, rules)) return;
            out.push_back({rules.prefix + fmt::format(fmt::runtime(declared.column), place), static_cast<double>(value),
                           rules.counts && declared.count});
          }
        };
        (one(field), ...);
      },
      S::figures());
}

ColumnRules time_history_rules(const TimeHistoryFigures& t, std::string prefix, bool counts) {
  ColumnRules rules{.prefix = std::move(prefix), .counts = counts, .frf = false, .storey_heights = false, .stroke = false};
  rules.storey_heights = std::any_of(t.frames.begin(), t.frames.end(), [](const FrameFigures& f) { return f.storey_heights; });
  rules.stroke = std::any_of(t.gaps.begin(), t.gaps.end(), [](const GapFigures& g) { return g.has_stroke; });
  return rules;
}

/// The declared columns of S as the docs write them, `place` in their `{}`.
template <DeclaredFigures S>
void declared_columns(const std::string& place, std::vector<DeclaredColumn>& out) {
  std::apply(
      [&](const auto&... field) {
        const auto one = [&](const auto& declared) {
          if (!declared.column.empty()) {
            out.push_back({fmt::format(fmt::runtime(declared.column), place), declared.unit, declared.meaning});
          }
        };
        (one(field), ...);
      },
      S::figures());
}

/// Whether `column` is an instance of the declared pattern (its `{}` any non-empty text).
bool instance_of(std::string_view column, std::string_view pattern) {
  const std::size_t hole = pattern.find("{}");
  if (hole == std::string_view::npos) return column == pattern;
  const std::string_view before = pattern.substr(0, hole), after = pattern.substr(hole + 2);
  return column.size() > before.size() + after.size() && column.starts_with(before) && column.ends_with(after);
}

/// The unit of the first declared pattern of S that `column` is an instance of, exact names first.
template <DeclaredFigures S>
std::optional<std::string_view> unit_among(std::string_view column, bool with_holes) {
  std::optional<std::string_view> unit;
  std::apply(
      [&](const auto&... field) {
        const auto one = [&](const auto& declared) {
          const bool holed = declared.column.find("{}") != std::string_view::npos;
          if (!unit && !declared.column.empty() && holed == with_holes && instance_of(column, declared.column)) {
            unit = declared.unit;
          }
        };
        (one(field), ...);
      },
      S::figures());
  return unit;
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
          add_columns(r, "", ColumnRules{.prefix = "", .counts = true, .frf = true, .storey_heights = false, .stroke = false}, out);
        } else if constexpr (std::is_same_v<R, TimeHistoryFigures>) {
          add_columns(r, "", time_history_rules(r, "", true), out);
        } else {
          out.push_back({"records", static_cast<double>(r.records), true});
          // A mean of counts need not be whole.
          add_columns(r.mean, "", time_history_rules(r.mean, "", false), out);
          add_columns(r.max, "", time_history_rules(r.max, "max_", false), out);
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

std::optional<std::string_view> declared_unit(std::string_view column) {
  for (const bool holes : {false, true}) {
    for (const auto& unit : {unit_among<FrfFigures>(column, holes), unit_among<TimeHistoryFigures>(column, holes),
                             unit_among<FrameFigures>(column, holes), unit_among<FloorFigures>(column, holes),
                             unit_among<JointFigures>(column, holes), unit_among<GapFigures>(column, holes)}) {
      if (unit) return unit;
    }
  }
  if (column.starts_with("max_")) return declared_unit(column.substr(4));  // an ensemble's maximum
  return std::nullopt;
}

std::vector<DeclaredColumn> declared_figure_columns() {
  std::vector<DeclaredColumn> out;
  declared_columns<FrfFigures>("", out);
  declared_columns<TimeHistoryFigures>("", out);
  declared_columns<FrameFigures>("<f>", out);
  declared_columns<FloorFigures>("<f>_<i>", out);
  declared_columns<JointFigures>("<joint>", out);
  declared_columns<GapFigures>("<joint>", out);
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
