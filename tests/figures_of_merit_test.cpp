// The figures of merit of a study point, typed (analysis/figures_of_merit.hpp): band peaks of a
// frequency response, an ensemble's mean and maximum figure by figure, the ratios to bare
// pounding, and the columns they are written as.
#include "poundsim/analysis/figures_of_merit.hpp"

#include <algorithm>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "poundsim/units.hpp"
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
  const std::vector<double> bare{1.4, 0.0};
  figures.compare_with_bare(bare);
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
  const std::vector<double> wrong{1.0};
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
  EXPECT_EQ(by_name(one).size(), 2U + 3 + 5 + 1 + 5);
  EXPECT_THROW(static_cast<void>(ensemble_figures({})), std::invalid_argument);
}

}  // namespace
}  // namespace poundsim
