// The figures of merit of a study point, typed (analysis/figures_of_merit.hpp): band peaks of a
// frequency response, an ensemble's mean and maximum figure by figure, the ratios to bare
// pounding, and the columns they are written as.
#include "poundsim/analysis/figures_of_merit.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "poundsim/analysis/time_history.hpp"
#include "poundsim/units.hpp"
#include "test_files.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

std::map<std::string, FigureColumn> by_name(const PointFigures& figures) {
  std::map<std::string, FigureColumn> columns;
  for (const FigureColumn& c : figures.columns()) {
    EXPECT_TRUE(columns.emplace(c.name, c).second) << c.name << " twice";
  }
  return columns;
}

FrfPoint point(double ratio, double v1, double v2, double free1, double free2, int periodicity = 1) {
  FrfPoint p;
  p.ratio = ratio;
  p.interacting.base_shear = {v1, v2};
  p.free.base_shear = {free1, free2};
  p.periodicity = periodicity;
  return p;
}

// Two frames of 2 kg and 3 kg: W = 2 g. Only the points in the band count; each frame's peak is
// its largest V/W there, at the ratio where it occurs, and its ratio to the free frame's peak.
TEST(FiguresOfMerit, AFrequencyResponsesBandPeaksAndTheirRatios) {
  const Model model = testing::two_oscillators(2.0, 50.0, 0.0, 3.0, 80.0, 0.0, GapProperties{.gap = 0.01});
  const double w = 2.0 * standard_gravity;
  const std::vector<FrfPoint> response{point(0.5, 100 * w, 1 * w, 1 * w, 1 * w),  // outside the band
                                       point(0.8, 0.6 * w, 0.9 * w, 0.5 * w, 0.3 * w),
                                       point(1.0, 0.7 * w, 0.2 * w, 0.4 * w, 0.6 * w, 0),
                                       point(1.2, 0.1 * w, 0.5 * w, 0.2 * w, 0.1 * w)};
  const FrfFigures f = frf_figures(model, response, 0.8, 1.2);
  EXPECT_EQ(f.points, 3);
  EXPECT_EQ(f.non_periodic, 1);
  ASSERT_EQ(f.frames.size(), 2U);
  EXPECT_DOUBLE_EQ(f.frames[0].peak_V_W, 0.7);
  EXPECT_EQ(f.frames[0].peak_at, 1.0);
  EXPECT_DOUBLE_EQ(f.frames[0].free_peak_V_W, 0.5);
  EXPECT_DOUBLE_EQ(f.frames[0].ratio_to_free, 0.7 / 0.5);
  EXPECT_DOUBLE_EQ(f.frames[1].peak_V_W, 0.9);
  EXPECT_EQ(f.frames[1].peak_at, 0.8);
  EXPECT_DOUBLE_EQ(f.frames[1].ratio_to_free, 0.9 / 0.6);
  EXPECT_DOUBLE_EQ(f.max_peak_V_W, 0.9);
  EXPECT_DOUBLE_EQ(f.max_ratio_to_free, 1.5);

  PointFigures figures{.response = f, .bare = std::nullopt};
  EXPECT_EQ(figures.max_peak_V_W(), f.max_peak_V_W);
  EXPECT_EQ(figures.max_ratio_to_free(), f.max_ratio_to_free);
  // Bare pounding peaking at 1.4 and 0 (a frame at rest): ratios 0.5 and 0.
  const std::vector<FigureColumn> bare{{"peak_V1_W", 1.4}, {"peak_V2_W", 0.0}, {"max_peak_V_W", 1.4}};
  figures.compare_with_bare(bare);
  EXPECT_FALSE(figures.bare->time_history);  // a frequency response has no drifts to compare
  EXPECT_DOUBLE_EQ(figures.bare->ratio_to_bare[0], 0.7 / 1.4);
  EXPECT_EQ(figures.bare->ratio_to_bare[1], 0.0);
  EXPECT_DOUBLE_EQ(figures.bare->max_ratio_to_bare, 0.5);
  const auto columns = by_name(figures);
  EXPECT_EQ(columns.size(), 2U + 4 * 2 + 2 + 2 * 2 + 1);
  EXPECT_TRUE(columns.at("points").count);
  EXPECT_EQ(columns.at("non_periodic").value, 1.0);
  EXPECT_EQ(columns.at("peak_V2_at").value, 0.8);
  EXPECT_FALSE(columns.at("peak_V1_W").count);
  EXPECT_EQ(columns.at("bare_peak_V1_W").value, 1.4);
  EXPECT_EQ(columns.at("max_ratio_to_bare").value, figures.bare->max_ratio_to_bare);
  const std::vector<FigureColumn> wrong{{"peak_V1_W", 1.0}};  // no frame 2
  EXPECT_THROW(figures.compare_with_bare(wrong), std::invalid_argument);
}

TimeHistoryFigures record(double scale, double impacts) {
  TimeHistoryFigures t;
  t.energy_residual = 1e-12 * scale;
  t.pga_g = 0.3 * scale;
  t.frames = {{.peak_V_W = 0.2 * scale, .free_peak_V_W = 0.1, .ratio_to_free = 2 * scale}};
  t.floors = {{.frame = 0, .floor = 0, .peak_u_m = 0.01 * scale, .free_peak_u_m = 0.02, .amp_u = 0.5 * scale,
               .amp_drift = 0.5 * scale, .amp_acc = 3 * scale}};
  t.joints = {{.left_frame = 0, .floor = 0, .min_gap_m = 0.04 * scale, .label = "1_1"}};
  t.impacts = impacts;
  t.max_impact_impulse_Ns = 5 * scale;
  t.max_gap_force_N = 0;
  t.max_peak_V_W = 0.2 * scale;
  t.max_ratio_to_free = 2 * scale;
  return t;
}

// Figure by figure: the mean over the records under the figure's name, the maximum as max_<name>;
// the mean of a count need not be whole and is written as a number.
TEST(FiguresOfMerit, AnEnsemblesMeanAndMaximumFigureByFigure) {
  const std::vector<TimeHistoryFigures> records{record(1.0, 3), record(2.0, 4), record(0.5, 0)};
  const EnsembleFigures e = ensemble_figures(records);
  EXPECT_EQ(e.records, 3);
  EXPECT_DOUBLE_EQ(e.mean.impacts, 7.0 / 3.0);
  EXPECT_EQ(e.max.impacts, 4.0);
  EXPECT_DOUBLE_EQ(e.mean.frames[0].peak_V_W, 0.2 * 3.5 / 3);
  EXPECT_DOUBLE_EQ(e.max.frames[0].peak_V_W, 0.4);
  EXPECT_DOUBLE_EQ(e.mean.floors[0].amp_acc, 3.5);
  EXPECT_EQ(e.max.joints[0].min_gap_m, 0.08);
  EXPECT_EQ(e.max.max_gap_force_N, 0.0);
  EXPECT_EQ(e.mean.floors[0].frame, 0);

  const PointFigures figures{.response = e, .bare = std::nullopt};
  EXPECT_EQ(figures.max_peak_V_W(), e.mean.max_peak_V_W);  // the headline is the mean's
  EXPECT_EQ(figures.peak_V_W(), std::vector<double>{e.mean.frames[0].peak_V_W});
  const auto columns = by_name(figures);
  EXPECT_TRUE(columns.at("records").count);
  EXPECT_FALSE(columns.at("impacts").count);
  EXPECT_DOUBLE_EQ(columns.at("impacts").value, 7.0 / 3.0);
  EXPECT_EQ(columns.at("max_impacts").value, 4.0);
  EXPECT_EQ(columns.at("max_min_gap_1_1_m").value, 0.08);
  EXPECT_DOUBLE_EQ(columns.at("amp_acc_1_1").value, 3.5);
  // One record's columns: the count is a count.
  const PointFigures one{.response = records[0], .bare = std::nullopt};
  EXPECT_TRUE(by_name(one).at("impacts").count);
  // Per frame 9 figures (no storey heights: no drift ratios), per floor 7, per joint 1, and 10
  // of the whole (no element with a stroke: no stroke use).
  EXPECT_EQ(by_name(one).size(), 2U + 9 + 7 + 1 + 10);
  EXPECT_THROW(static_cast<void>(ensemble_figures({})), std::invalid_argument);
}

constexpr double kMass = 2.0e5;        // [kg]
constexpr double kStiffness = 8.0e7;   // K [N/m]: ω = 20 rad/s
constexpr double kYieldForce = 4.0e5;  // F_y [N]: u_y = 5 mm
constexpr double kHeight = 3.5;        // h [m]

// An elastic–perfectly-plastic storey of height h released at rest position with v0 (no
// damping, no excitation): elastic up to u_y at t₁ = asin(ω u_y / v0)/ω with speed
// v₁ = √(v0² − ω²u_y²), then decelerated by F_y/m to its peak u_max = u_y/2 + m v0²/(2F_y) at
// t_p = t₁ + m v₁/F_y, then elastic about d_p = u_max − u_y with amplitude u_y. At T = 0.3 s it
// has not yielded again. Its figures: the peak drift ratio u_max/h, the hysteretic energy
// F_y (u_max − u_y), the drift at the end d_p + u_y cos ω(T − t_p), the peak absolute
// acceleration F_y/m (no ground motion).
TEST(FiguresOfMerit, AYieldingStoreysDriftRatioResidualDriftAndHystereticEnergyAreTheClosedForms) {
  Frame frame = make_uniform_frame(1, kMass, kStiffness, 0.0, "yielding");
  frame.storey_law = PerStorey<BilinearStorey>{std::vector<BilinearStorey::Parameters>(
      1, {.yield_force = kYieldForce, .post_yield_ratio = 0.0})};
  frame.storey_height = {kHeight};
  const double v0 = 0.4, duration = 0.3, omega = std::sqrt(kStiffness / kMass);
  const double uy = kYieldForce / kStiffness, u_max = uy / 2 + kMass * v0 * v0 / (2 * kYieldForce);
  const double t1 = std::asin(omega * uy / v0) / omega;
  const double t_peak = t1 + kMass * std::sqrt(v0 * v0 - omega * omega * uy * uy) / kYieldForce;
  ASSERT_LT(t_peak, duration);
  ASSERT_LT(omega * (duration - t_peak), std::numbers::pi);  // not back to the other side's yield
  for (const Integrator integrator : {Integrator::exact, Integrator::newmark}) {
    SCOPED_TRACE(integrator == Integrator::exact ? "exact" : "newmark");
    TimeHistoryProblem problem{.model = make_model({frame}, PaperGap{}),
                               .excitation = NoExcitation{},
                               .options = {.dt = 1e-3, .integrator = integrator},
                               .initial = {.displacement = {}, .velocity = {{v0}}},
                               .duration = duration,
                               .output_dt = 0.1};
    const TimeHistoryAnalysis run = analyse_time_history(problem);
    const PointFigures figures{.response = time_history_figures(run.model, run, 0.0), .bare = std::nullopt};
    const auto columns = by_name(figures);
    EXPECT_NEAR(columns.at("peak_drift_ratio_1").value, u_max / kHeight, 1e-9 * u_max / kHeight);
    EXPECT_NEAR(columns.at("peak_drift_ratio_1_1").value, u_max / kHeight, 1e-9 * u_max / kHeight);
    EXPECT_EQ(columns.at("max_peak_drift_ratio").value, columns.at("peak_drift_ratio_1").value);
    EXPECT_NEAR(columns.at("peak_drift_1_m").value, u_max, 1e-9 * u_max);
    EXPECT_NEAR(columns.at("hysteretic_energy_1_J").value, kYieldForce * (u_max - uy), 1e-8 * kYieldForce * u_max);
    EXPECT_EQ(columns.at("hysteretic_energy_J").value, columns.at("hysteretic_energy_1_J").value);
    const double residual = u_max - uy + uy * std::cos(omega * (duration - t_peak));
    // Newmark's elastic swing lags by its period error (ω dt)²/12 per radian.
    const double wdt = omega * 1e-3;
    const double lag = integrator == Integrator::exact ? 1e-8 * u_max / uy : 1.5 * wdt * wdt / 12 * omega * (duration - t_peak);
    EXPECT_NEAR(columns.at("residual_drift_1_m").value, residual, lag * uy);
    EXPECT_NEAR(columns.at("residual_drift_ratio_1").value, residual / kHeight, lag * uy / kHeight);
    EXPECT_NEAR(columns.at("peak_abs_acc_1_g").value, kYieldForce / kMass / standard_gravity, 1e-8);
    EXPECT_EQ(columns.at("max_peak_abs_acc_g").value, columns.at("peak_abs_acc_1_g").value);
    EXPECT_EQ(columns.count("max_stroke_use"), 0U);  // no gap element
    EXPECT_EQ(figures.figure("residual_drift_1_m"), columns.at("residual_drift_1_m").value);
    EXPECT_EQ(figures.figure("no_such_figure"), std::nullopt);
  }
}

// A rigid impact of equal masses with e = 1 exchanges their velocities. Frame 2 (undamped,
// ω = 20 rad/s) released from rest position with −v0 meets frame 1 (at rest, heavily damped)
// across the gap δ at speed v_c = √(v0² − ω²δ²): frame 1 leaves with −v_c, frame 2 stops. The
// velocity jump of each floor is v_c; spread over a half-sine pulse of duration τ it adds
// π v_c / (2τ) to the floors' accelerations at the impact: on frame 2 to the spring's ω²δ, in the
// pulse's direction; on frame 1 to its rest before (0) and to the dashpot's c v_c / m against it
// after, so π v_c / (2τ) alone. Frame 1's storey shear jumps from 0 to
// c v_c, its peak (overdamped: c² > 4km, the shear relaxes from there). Without τ the
// accelerations are those at the states, and the velocity jump is reported alone.
TEST(FiguresOfMerit, ARigidImpactsVelocityJumpEquivalentPulseAndPostImpactShearAreTheClosedForms) {
  const double m = 1e4, k = 4e6, c = 1e6, delta = 0.01, v0 = 0.5, omega = std::sqrt(k / m);
  const double vc = std::sqrt(v0 * v0 - omega * omega * delta * delta);
  for (const double tau : {0.0, 2e-3}) {
    for (const Integrator integrator : {Integrator::exact, Integrator::newmark}) {
      SCOPED_TRACE(fmt::format("tau {} s, {}", tau, integrator == Integrator::exact ? "exact" : "newmark"));
      TimeHistoryProblem problem{
          .model = testing::two_oscillators(m, k, c, m, k, 0.0, {.gap = delta, .restitution = 1.0}),
          .excitation = NoExcitation{},
          .options = {.dt = 1e-3, .integrator = integrator, .impact_duration = tau},
          .initial = {.displacement = {}, .velocity = {{0.0}, {-v0}}},
          .duration = 0.06,
          .output_dt = 0.01};
      const TimeHistoryAnalysis run = analyse_time_history(problem);
      ASSERT_EQ(run.statistics.gaps[0].impacts, 1);
      const double tol = integrator == Integrator::exact ? 1e-9 : 1e-6;
      for (const FloorResponse& floor : run.statistics.floors) {
        EXPECT_NEAR(floor.velocity_jump.value, vc, tol * vc);
      }
      EXPECT_NEAR(run.statistics.storey_shear[0].value, c * vc, tol * c * vc);
      const PointFigures figures{.response = time_history_figures(run.model, run, 0.0), .bare = std::nullopt};
      const auto columns = by_name(figures);
      EXPECT_NEAR(columns.at("max_velocity_jump_m_s").value, vc, tol * vc);
      const FloorResponse& left = run.statistics.floors[0];
      const FloorResponse& right = run.statistics.floors[1];
      if (tau == 0) {
        EXPECT_EQ(left.impact_acceleration.value, 0.0);
        // Frame 1 moves off with the dashpot's deceleration c v_c / m at most.
        EXPECT_NEAR(columns.at("peak_abs_acc_1_g").value * standard_gravity, c * vc / m, 1e-6 * c * vc / m);
        continue;
      }
      const double pulse = std::numbers::pi * vc / (2 * tau);
      EXPECT_NEAR(left.impact_absolute_acceleration.value, pulse, tol * pulse);
      EXPECT_NEAR(right.impact_absolute_acceleration.value, pulse + omega * omega * delta, tol * pulse);
      EXPECT_NEAR(columns.at("peak_abs_acc_2_g").value * standard_gravity, pulse + omega * omega * delta, tol * pulse);
      EXPECT_EQ(columns.at("max_peak_abs_acc_g").value,
                std::max(columns.at("peak_abs_acc_1_g").value, columns.at("peak_abs_acc_2_g").value));
      EXPECT_EQ(left.acceleration_with_impacts().value, left.impact_acceleration.value);
    }
  }
}

// The paper's element uses its stroke up to the stop: an element that reached it (an impact)
// used all of it, s ÷ ε = 1; a softer push uses the share max s ÷ ε of it, which the monitor's
// largest shortening gives. Elements without a stroke (a rigid stop) have no stroke use.
TEST(FiguresOfMerit, StrokeUseIsTheLargestShorteningOverTheStroke) {
  const double epsilon = 0.01;
  const auto run_with = [&](double v0, GapProperties gap) {
    TimeHistoryProblem problem{.model = testing::two_oscillators(1e4, 4e6, 0.0, 1e4, 4e6, 0.0, gap),
                               .excitation = NoExcitation{},
                               .options = {.dt = 1e-3, .integrator = Integrator::exact},
                               .initial = {.displacement = {}, .velocity = {{v0}, {0.0}}},
                               .duration = 0.5,
                               .output_dt = 0.1};
    return analyse_time_history(problem);
  };
  const GapProperties element{.stiffness = 1e6, .damping = 0.0, .gap = 0.005, .shortening = epsilon, .restitution = 0.5};
  for (const double v0 : {0.3, 1.5}) {
    SCOPED_TRACE(v0);
    const TimeHistoryAnalysis run = run_with(v0, element);
    const PointFigures figures{.response = time_history_figures(run.model, run, 0.0), .bare = std::nullopt};
    const auto columns = by_name(figures);
    const GapResponse& g = run.statistics.gaps[0];
    ASSERT_GT(g.contacts, 0);
    EXPECT_EQ(columns.at("stroke_use_1_1").value, g.shortening.value / epsilon);
    EXPECT_EQ(columns.at("max_stroke_use").value, columns.at("stroke_use_1_1").value);
    EXPECT_EQ(columns.at("gap_force_1_1_N").value, g.force.value);
    if (g.impacts > 0) {
      EXPECT_NEAR(columns.at("stroke_use_1_1").value, 1.0, 1e-9);
    } else {
      EXPECT_LT(columns.at("stroke_use_1_1").value, 1.0);
      EXPECT_GT(columns.at("stroke_use_1_1").value, 0.0);
    }
  }
  EXPECT_GT(run_with(1.5, element).statistics.gaps[0].impacts, 0);  // the faster push hits the stop
  EXPECT_EQ(run_with(0.3, element).statistics.gaps[0].impacts, 0);
  const TimeHistoryAnalysis bare = run_with(1.5, GapProperties{.gap = 0.005, .restitution = 0.5});
  const auto columns = by_name(PointFigures{.response = time_history_figures(bare.model, bare, 0.0), .bare = std::nullopt});
  EXPECT_EQ(columns.count("stroke_use_1_1"), 0U);
  EXPECT_EQ(columns.count("max_stroke_use"), 0U);
  EXPECT_GT(bare.statistics.gaps[0].impacts, 0);
  EXPECT_EQ(columns.at("gap_force_1_1_N").value, bare.statistics.gaps[0].force.value);
}

// Every study column the figures declare is in the reference (docs/studies.md), as it writes
// them (peak_V<f>_W, min_gap_<joint>_m); and the columns a point writes are the declared ones.
TEST(FiguresOfMerit, EveryDeclaredColumnIsDocumented) {
  const std::string docs = testing::slurp(std::string(POUNDSIM_SOURCE_DIR) + "/docs/studies.md");
  const std::vector<DeclaredColumn> declared = declared_figure_columns();
  EXPECT_GT(declared.size(), 40u);
  for (const DeclaredColumn& c : declared) {
    EXPECT_NE(docs.find("`" + c.column + "`"), std::string::npos) << c.column << " is not in docs/studies.md";
    EXPECT_FALSE(c.meaning.empty()) << c.column;
  }
  // Units come from the declarations, for an instance of a pattern and for an ensemble's maximum.
  EXPECT_EQ(declared_unit("peak_drift_2_m"), "m");
  EXPECT_EQ(declared_unit("peak_drift_ratio_2_5"), "1");
  EXPECT_EQ(declared_unit("stroke_use_1_3"), "1");
  EXPECT_EQ(declared_unit("max_peak_drift_m"), "m");
  EXPECT_EQ(declared_unit("max_max_impact_impulse_Ns"), "N·s");
  EXPECT_EQ(declared_unit("impacts"), "");
  EXPECT_EQ(declared_unit("max_velocity_jump_m_s"), "m/s");
  EXPECT_EQ(declared_unit("model.dimensionless.eta"), std::nullopt);
  EXPECT_EQ(declared_unit("ratio_to_bare_1"), std::nullopt);
}

}  // namespace
}  // namespace poundsim
