#pragma once
/// @file
/// The figures of merit of one point of a study or of an optimisation (docs/studies.md), typed:
/// a frequency response's band peaks, a time history's peaks and amplifications, or an
/// ensemble's mean and maximum over its records, and optionally the ratios to bare pounding.
/// The optimiser minimises one of them (max_peak_V_W, max_ratio_to_free); `columns()` names
/// every figure as the study table's column, which io writes to the database and CSV.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <variant>
#include <vector>

#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/analysis/time_history.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// Where a declared figure is a study column.
enum class Shown : std::uint8_t {
  always,          ///< every point's
  frf,             ///< a frequency response's only
  time_history,    ///< a time history's only
  storey_heights,  ///< a time history's, where storey heights make drift ratios
  stroke,          ///< a time history's, where an element has a stroke
  never,           ///< carried by the records (a frame's number, a label), not a column
};

/// A field of a point's figures, declared once: the member, its key in the records that MPI
/// ranks and study databases exchange (the member's name), its study column — `{}` stands for
/// the frame ("2"), the floor ("2_5") or the joint's label — its unit ("1" for a ratio, "" for a
/// count), its meaning, when it is a column and whether it is a count (written without a
/// decimal point). The records, the
/// study columns, an ensemble's means and maxima and the column list in docs/studies.md all
/// come from these declarations (figures_of_merit.cpp, io/study_run.cpp).
template <class S, class T>
struct FigureField {
  std::string_view key;
  T S::*member;
  std::string_view column = {};
  std::string_view unit = {};
  std::string_view meaning = {};
  Shown shown = Shown::always;
  bool count = false;
};
template <class S, class T>
FigureField(std::string_view, T S::*) -> FigureField<S, T>;
template <class S, class T>
FigureField(std::string_view, T S::*, std::string_view, std::string_view, std::string_view) -> FigureField<S, T>;
template <class S, class T>
FigureField(std::string_view, T S::*, std::string_view, std::string_view, std::string_view, Shown)
    -> FigureField<S, T>;
template <class S, class T>
FigureField(std::string_view, T S::*, std::string_view, std::string_view, std::string_view, Shown, bool)
    -> FigureField<S, T>;

/// A struct whose fields are declared as figures.
template <class S>
concept DeclaredFigures = requires { S::figures(); };

/// One frame (columns peak_V{f}_W, free_peak_V{f}_W, ratio_to_free_{f}, peak_V{f}_at; a time
/// history's also peak_drift_{f}_m, peak_abs_acc_{f}_g, residual_drift_{f}_m,
/// hysteretic_energy_{f}_J, the free frame's free_peak_drift_{f}_m and free_peak_abs_acc_{f}_g,
/// and with storey heights the drift ratios peak_drift_ratio_{f}, free_peak_drift_ratio_{f},
/// residual_drift_ratio_{f}).
struct FrameFigures {
  double peak_V_W = 0.0;       ///< Its peak base shear ÷ W (W: frame 1's weight).
  double free_peak_V_W = 0.0;  ///< The same without gap elements.
  double ratio_to_free = 0.0;  ///< peak_V_W ÷ free_peak_V_W; 0 when the free frame is at rest.
  double peak_at = 0.0;        ///< ω̄/ω₁ of the peak (a frequency response's only).
  // A time history's, storey by storey and floor by floor the largest:
  double peak_drift_m = 0.0, free_peak_drift_m = 0.0;  ///< |u_i − u_{i−1}| [m].
  double peak_drift_ratio = 0.0, free_peak_drift_ratio = 0.0;  ///< |u_i − u_{i−1}| ÷ h_i.
  /// |ü_i + a_g| ÷ g, with the equivalent pulses of rigid impacts when the run spreads them
  /// over a duration (TimeHistoryOptions::impact_duration; FloorResponse::impact_acceleration).
  double peak_abs_acc_g = 0.0, free_peak_abs_acc_g = 0.0;
  /// |u_i − u_{i−1}| at the end of the run [m] and ÷ h_i: the residual drift of yielding storeys
  /// once the motion has died out (let it: a duration beyond the record).
  double residual_drift_m = 0.0, residual_drift_ratio = 0.0;
  double hysteretic_energy_J = 0.0;  ///< Dissipated by its yielding storeys [J].
  bool storey_heights = false;       ///< Whether it has storey heights, so drift ratios.

  static constexpr auto figures() {
    using F = FrameFigures;
    using enum Shown;
    return std::tuple{
        FigureField{"peak_V_W", &F::peak_V_W, "peak_V{}_W", "1", "peak base shear ÷ W"},
        FigureField{"peak_at", &F::peak_at, "peak_V{}_at", "1", "ω̄/ω₁ of the peak", frf},
        FigureField{"free_peak_V_W", &F::free_peak_V_W, "free_peak_V{}_W", "1", "the same without gap elements"},
        FigureField{"ratio_to_free", &F::ratio_to_free, "ratio_to_free_{}", "1", "peak ÷ free peak"},
        FigureField{"peak_drift_m", &F::peak_drift_m, "peak_drift_{}_m", "m", "largest storey drift", time_history},
        FigureField{"free_peak_drift_m", &F::free_peak_drift_m, "free_peak_drift_{}_m", "m",
                    "the same without gap elements", time_history},
        FigureField{"peak_abs_acc_g", &F::peak_abs_acc_g, "peak_abs_acc_{}_g", "g", "largest absolute floor acceleration",
                    time_history},
        FigureField{"free_peak_abs_acc_g", &F::free_peak_abs_acc_g, "free_peak_abs_acc_{}_g", "g",
                    "the same without gap elements", time_history},
        FigureField{"residual_drift_m", &F::residual_drift_m, "residual_drift_{}_m", "m", "largest drift at the end",
                    time_history},
        FigureField{"hysteretic_energy_J", &F::hysteretic_energy_J, "hysteretic_energy_{}_J", "J",
                    "dissipated by its yielding storeys", time_history},
        FigureField{"peak_drift_ratio", &F::peak_drift_ratio, "peak_drift_ratio_{}", "1", "largest drift ÷ storey height",
                    storey_heights},
        FigureField{"free_peak_drift_ratio", &F::free_peak_drift_ratio, "free_peak_drift_ratio_{}", "1",
                    "the same without gap elements", storey_heights},
        FigureField{"residual_drift_ratio", &F::residual_drift_ratio, "residual_drift_ratio_{}", "1",
                    "residual drift ÷ storey height", storey_heights},
        FigureField{"storey_heights", &F::storey_heights, "", "", "", never},
    };
  }
};

/// One floor of a time history: peaks with the gap elements and without, and their ratios
/// (columns peak_u_{f}_{i}_m, free_peak_u_{f}_{i}_m, amp_u_{f}_{i}, amp_drift_{f}_{i},
/// amp_acc_{f}_{i}; a ratio is 0 when the free floor is at rest).
/// Its storey's peak drift and the floor's peak absolute acceleration: peak_drift_{f}_{i}_m,
/// peak_abs_acc_{f}_{i}_g, and with storey heights peak_drift_ratio_{f}_{i}.
struct FloorFigures {
  int frame = 0, floor = 0;  ///< 0-based.
  double peak_u_m = 0.0, free_peak_u_m = 0.0;
  double amp_u = 0.0, amp_drift = 0.0, amp_acc = 0.0;
  double peak_drift_m = 0.0, peak_drift_ratio = 0.0, peak_abs_acc_g = 0.0;
  bool storey_height = false;  ///< Whether its storey has a height, so a drift ratio.

  static constexpr auto figures() {
    using F = FloorFigures;
    using enum Shown;
    return std::tuple{
        FigureField{"frame", &F::frame, "", "", "", never},
        FigureField{"floor", &F::floor, "", "", "", never},
        FigureField{"peak_u_m", &F::peak_u_m, "peak_u_{}_m", "m", "peak displacement"},
        FigureField{"free_peak_u_m", &F::free_peak_u_m, "free_peak_u_{}_m", "m", "the same without gap elements"},
        FigureField{"amp_u", &F::amp_u, "amp_u_{}", "1", "displacement ÷ the free floor's"},
        FigureField{"amp_drift", &F::amp_drift, "amp_drift_{}", "1", "storey drift ÷ the free storey's"},
        FigureField{"amp_acc", &F::amp_acc, "amp_acc_{}", "1", "absolute acceleration ÷ the free floor's"},
        FigureField{"peak_drift_m", &F::peak_drift_m, "peak_drift_{}_m", "m", "its storey's peak drift"},
        FigureField{"peak_abs_acc_g", &F::peak_abs_acc_g, "peak_abs_acc_{}_g", "g", "peak absolute acceleration"},
        FigureField{"peak_drift_ratio", &F::peak_drift_ratio, "peak_drift_ratio_{}", "1", "peak drift ÷ storey height",
                    storey_heights},
        FigureField{"storey_height", &F::storey_height, "", "", "", never},
    };
  }
};

/// One gap element: its largest force (gap_force_{label}_N) and, for an element with a stroke
/// (the paper's, ε > 0), the share of the stroke it used, max s ÷ ε (stroke_use_{label}; above 1
/// the element hit its stop).
struct GapFigures {
  double max_force_N = 0.0;
  double stroke_use = 0.0;
  bool has_stroke = false;
  std::string label;  ///< joint_label of its ends.

  static constexpr auto figures() {
    using F = GapFigures;
    using enum Shown;
    return std::tuple{
        FigureField{"max_force_N", &F::max_force_N, "gap_force_{}_N", "N", "largest force"},
        FigureField{"stroke_use", &F::stroke_use, "stroke_use_{}", "1", "largest shortening ÷ ε", stroke},
        FigureField{"has_stroke", &F::has_stroke, "", "", "", never},
        FigureField{"label", &F::label, "", "", "", never},
    };
  }
};

/// One pair of neighbouring floors: the free frames' largest approach past closing, the joint a
/// gap-free design needs (column min_gap_{f}_{i}_m, 0 when they never close).
struct JointFigures {
  int left_frame = 0, floor = 0;  ///< 0-based.
  double min_gap_m = 0.0;
  std::string label;  ///< Its name in the columns (joint_label): "1_3", or "1_5_4" at a struck left column.

  static constexpr auto figures() {
    using F = JointFigures;
    using enum Shown;
    return std::tuple{
        FigureField{"left_frame", &F::left_frame, "", "", "", never},
        FigureField{"floor", &F::floor, "", "", "", never},
        FigureField{"min_gap_m", &F::min_gap_m, "min_gap_{}_m", "m", "the free frames' largest approach"},
        FigureField{"label", &F::label, "", "", "", never},
    };
  }
};

/// A frequency response over a band of ω̄/ω₁.
struct FrfFigures {
  long points = 0;        ///< Frequencies in the band.
  long non_periodic = 0;  ///< Of which not periodic.
  std::vector<FrameFigures> frames;
  double max_peak_V_W = 0.0;       ///< The larger of the frames' peak_V_W.
  double max_ratio_to_free = 0.0;  ///< The larger of their ratio_to_free.

  static constexpr auto figures() {
    using F = FrfFigures;
    using enum Shown;
    return std::tuple{
        FigureField{"points", &F::points, "points", "", "frequencies in the band", always, true},
        FigureField{"non_periodic", &F::non_periodic, "non_periodic", "", "of which not periodic", always, true},
        FigureField{"frames", &F::frames},
        FigureField{"max_peak_V_W", &F::max_peak_V_W, "max_peak_V_W", "1", "the larger of the frames' peak V/W"},
        FigureField{"max_ratio_to_free", &F::max_ratio_to_free, "max_ratio_to_free", "1",
                    "the larger of their ratios to the free frames"},
    };
  }
};

/// A time history.
struct TimeHistoryFigures {
  double energy_residual = 0.0;  ///< The largest relative residual of the energy balance.
  double pga_g = 0.0;            ///< The record's peak ground acceleration [g] (0: harmonic).
  std::vector<FrameFigures> frames;
  std::vector<FloorFigures> floors;  ///< Frame by frame, bottom up.
  std::vector<JointFigures> joints;  ///< Every pair of facing floors.
  std::vector<GapFigures> gaps;      ///< In Model::gaps order.
  double impacts = 0.0;  ///< A count; a double because an ensemble's mean need not be whole.
  double max_impact_impulse_Ns = 0.0;
  /// The largest jump of a floor's velocity at a rigid impact or a lock [m/s] (0 without): what
  /// the impacts do to the floors, whether or not the accelerations include them.
  double max_velocity_jump_m_s = 0.0;
  double max_gap_force_N = 0.0;
  double max_peak_V_W = 0.0;
  double max_ratio_to_free = 0.0;
  // The worse frame's (columns of the same names; the drift ratios only when a frame has
  // storey heights, the stroke use only when an element has a stroke):
  double max_peak_drift_m = 0.0, max_peak_drift_ratio = 0.0, max_peak_abs_acc_g = 0.0;
  double max_residual_drift_m = 0.0, max_residual_drift_ratio = 0.0;
  double max_stroke_use = 0.0;
  double hysteretic_energy_J = 0.0;  ///< Of every yielding storey [J].

  static constexpr auto figures() {
    using F = TimeHistoryFigures;
    using enum Shown;
    return std::tuple{
        FigureField{"energy_residual", &F::energy_residual, "energy_residual", "1", "largest relative residual of the balance"},
        FigureField{"pga_g", &F::pga_g, "pga_g", "g", "the record's peak ground acceleration"},
        FigureField{"frames", &F::frames},
        FigureField{"floors", &F::floors},
        FigureField{"joints", &F::joints},
        FigureField{"gaps", &F::gaps},
        FigureField{"max_peak_V_W", &F::max_peak_V_W, "max_peak_V_W", "1", "the larger of the frames' peak V/W"},
        FigureField{"max_ratio_to_free", &F::max_ratio_to_free, "max_ratio_to_free", "1",
                    "the larger of their ratios to the free frames"},
        FigureField{"impacts", &F::impacts, "impacts", "", "number of impacts", always, true},
        FigureField{"max_impact_impulse_Ns", &F::max_impact_impulse_Ns, "max_impact_impulse_Ns", "N·s",
                    "largest impulse of one impact"},
        FigureField{"max_velocity_jump_m_s", &F::max_velocity_jump_m_s, "max_velocity_jump_m_s", "m/s",
                    "largest jump of a floor's velocity at a rigid impact"},
        FigureField{"max_gap_force_N", &F::max_gap_force_N, "max_gap_force_N", "N", "largest element force"},
        FigureField{"max_peak_drift_m", &F::max_peak_drift_m, "max_peak_drift_m", "m", "the worse frame's peak drift"},
        FigureField{"max_peak_abs_acc_g", &F::max_peak_abs_acc_g, "max_peak_abs_acc_g", "g",
                    "the worse frame's peak absolute acceleration"},
        FigureField{"max_residual_drift_m", &F::max_residual_drift_m, "max_residual_drift_m", "m",
                    "the worse frame's residual drift"},
        FigureField{"hysteretic_energy_J", &F::hysteretic_energy_J, "hysteretic_energy_J", "J",
                    "dissipated by every yielding storey"},
        FigureField{"max_peak_drift_ratio", &F::max_peak_drift_ratio, "max_peak_drift_ratio", "1",
                    "the worse frame's peak drift ratio", storey_heights},
        FigureField{"max_residual_drift_ratio", &F::max_residual_drift_ratio, "max_residual_drift_ratio", "1",
                    "the worse frame's residual drift ratio", storey_heights},
        FigureField{"max_stroke_use", &F::max_stroke_use, "max_stroke_use", "1", "the largest element's stroke use", stroke},
    };
  }
};

/// An ensemble of time histories (one per record): the mean and the maximum of every figure
/// over the records (columns: the mean under the figure's name, the maximum as max_<name>).
struct EnsembleFigures {
  long records = 0;
  TimeHistoryFigures mean, max;

  static constexpr auto figures() {
    using F = EnsembleFigures;
    return std::tuple{FigureField{"records", &F::records}, FigureField{"mean", &F::mean}, FigureField{"max", &F::max}};
  }
};

/// The point against bare pounding at its joints (columns bare_peak_V{f}_W, ratio_to_bare_{f},
/// max_ratio_to_bare; a time history's and an ensemble's also, per frame, its peak drift and
/// peak absolute acceleration against bare pounding's: bare_peak_drift_{f}_m,
/// ratio_to_bare_drift_{f}, bare_peak_abs_acc_{f}_g, ratio_to_bare_acc_{f}, and the larger over
/// the frames, max_ratio_to_bare_drift and max_ratio_to_bare_acc). A ratio is 0 when bare
/// pounding's figure is.
struct BareComparison {
  std::vector<double> bare_peak_V_W, ratio_to_bare;  ///< Per frame.
  double max_ratio_to_bare = 0.0;
  bool time_history = false;  ///< Whether the drifts and accelerations below are compared.
  std::vector<double> bare_peak_drift_m, ratio_to_bare_drift;    ///< Per frame.
  std::vector<double> bare_peak_abs_acc_g, ratio_to_bare_acc;    ///< Per frame.
  double max_ratio_to_bare_drift = 0.0, max_ratio_to_bare_acc = 0.0;
};

/// The columns of the two figures every point has, which the optimiser minimises and a study
/// ranks its points by.
namespace column_names {
inline constexpr std::string_view max_peak_V_W = "max_peak_V_W";
inline constexpr std::string_view max_ratio_to_free = "max_ratio_to_free";
}  // namespace column_names

/// One study column: a figure's name and value. A count is written without a decimal point.
struct FigureColumn {
  std::string name;
  double value = 0.0;
  bool count = false;
};

/// The figures of one point.
struct PointFigures {
  std::variant<FrfFigures, TimeHistoryFigures, EnsembleFigures> response;
  std::optional<BareComparison> bare;

  /// The larger of the frames' peak V/W (an ensemble's: of its mean).
  [[nodiscard]] double max_peak_V_W() const;
  /// The larger of the frames' ratio of peak V/W to the free frame's (an ensemble's: of its mean).
  [[nodiscard]] double max_ratio_to_free() const;
  /// Each frame's peak V/W (an ensemble's: its mean), what bare pounding is compared by.
  [[nodiscard]] std::vector<double> peak_V_W() const;
  /// Adds the ratios to bare pounding, whose figures are `bare` (the columns of the same point
  /// made bare: bare_pounding_model). Throws std::invalid_argument when a figure compared is
  /// not among them.
  void compare_with_bare(std::span<const FigureColumn> bare);
  /// Every figure as a study column (docs/studies.md), in no particular order.
  [[nodiscard]] std::vector<FigureColumn> columns() const;
  /// The figure of column `name`; nothing when the point has no such column.
  [[nodiscard]] std::optional<double> figure(std::string_view name) const;
};

/// A declared study column: its name as docs/studies.md writes it — `<f>` for the frame,
/// `<f>_<i>` for the floor, `<joint>` for a joint's label (peak_V<f>_W, min_gap_<joint>_m) —
/// its unit and its meaning.
struct DeclaredColumn {
  std::string column;
  std::string_view unit, meaning;
};
[[nodiscard]] std::vector<DeclaredColumn> declared_figure_columns();

/// The declared unit of a study column of a point's figures (peak_drift_2_m: "m"; an
/// ensemble's maxima, max_<name>, the unit of <name>); none for a column no figure declares.
[[nodiscard]] std::optional<std::string_view> declared_unit(std::string_view column);

/// The figures of a frequency response of `model` over lo ≤ ω̄/ω₁ ≤ hi (band_peaks).
[[nodiscard]] FrfFigures frf_figures(const Model& model, const std::vector<FrfPoint>& response, double lo,
                                     double hi);

/// The figures of a time history of `model` (analyse_time_history, which also ran the free
/// frames) under a record of peak ground acceleration `pga_g` [g].
[[nodiscard]] TimeHistoryFigures time_history_figures(const Model& model, const TimeHistoryAnalysis& run,
                                                      double pga_g);

/// The mean and the maximum of each figure over `records` (at least one, all of one model).
[[nodiscard]] EnsembleFigures ensemble_figures(std::span<const TimeHistoryFigures> records);

}  // namespace poundsim
