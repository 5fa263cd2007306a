// A slab that strikes its neighbour's column between two floors (Karayannis & Favvata 2005;
// docs/model.md#slab-to-column). The struck point moves as w u_above + (1 − w) u_below and the
// contact force is shared by the same weights, so that an impulse J there meets the mass
// 1/m_p = w²/m_above + (1 − w)²/m_below and the contact is the two-body problem of the slab's
// floor and that mass: its closed forms hold at the point, momentum is exchanged in the ratio of
// the weights, and the energy balance closes. Input by `slab = [frame, floor]`, placed by heights.
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/model.hpp"
#include "collision.hpp"

namespace poundsim {
namespace {

constexpr double kGap = 0.01, kClosing = 1.5;

/// Frames of 1 storey (2 kg, h_slab) and 2 storeys (3 and 5 kg, 3 m each) on storeys 10¹¹ times
/// softer than the contact (free masses), the slab of the first striking the second's column at
/// the height of its floor, released at 1.5 m/s towards it.
struct Strike {
  Model model;
  InitialConditions initial;
  double w = 0.0;        ///< weight of the struck floor above
  double m_above = 0.0;  ///< [kg]
  double m_below = 0.0;  ///< [kg]; infinite: the ground
  [[nodiscard]] double point_mass() const { return 1.0 / (w * w / m_above + (1 - w) * (1 - w) / m_below); }
  [[nodiscard]] double reduced() const { return 2.0 * point_mass() / (2.0 + point_mass()); }
};

Strike strike(double slab_height, const GapLaw& law) {
  Frame slab = make_uniform_frame(1, 2.0, 1e-6, 0.0);
  slab.storey_height = {slab_height};
  Frame column = make_uniform_frame(2, 3.0, 1e-6, 0.0);
  column.mass[1] = 5.0;
  column.storey_height = {3.0, 3.0};
  Strike s;
  const bool first_storey = slab_height < 3.0;
  s.w = first_storey ? slab_height / 3.0 : (slab_height - 3.0) / 3.0;
  s.m_above = first_storey ? 3.0 : 5.0;
  s.m_below = first_storey ? std::numeric_limits<double>::infinity() : 3.0;
  const FloorPair pair{.left_frame = 0, .left_floor = 0, .right_floor = first_storey ? 0 : 1,
                       .column = ColumnStrike{.struck = Side::right, .weight = s.w}};
  s.model = make_model({slab, column}, law, {}, std::span(&pair, 1));
  s.initial.velocity = {{kClosing}, {0.0, 0.0}};
  return s;
}

testing::Collision run(const Strike& s, Integrator integrator, double dt, double duration) {
  return testing::collide(s.model, s.initial, dt, integrator, duration);
}

TEST(SlabToColumn, KelvinVoigtAtAColumnPointIsTheTwoBodyClosedFormWithThePointsMass) {
  // Slabs at 1.2 m (w = 0.4 of the first storey, the ground below) and 4 m (w = 1/3 of the
  // second, floor 1 below). The dashpot is tuned to the point's mass, so the restitution at the
  // point is exactly e after π/ω_d; the impulse J = m̄(1 + e)v₀ moves the floors by w J/m_above
  // and (1 − w) J/m_below.
  const double k = 1e5, e = 0.6;
  const KelvinVoigt law{.parameters = {.stiffness = k, .gap = kGap, .restitution = e}};
  for (const double height : {1.2, 4.0}) {
    const Strike s = strike(height, law);
    const DofLayout layout(s.model);
    const std::vector<Link> links = make_links(s.model, layout);
    EXPECT_NEAR(std::get<KelvinVoigt>(links.back().law).damping,
                2 * KelvinVoigt::damping_ratio(e) * std::sqrt(k * s.reduced()), 1e-12 * k);
    const double xi = KelvinVoigt::damping_ratio(e);
    const double omega_d = std::sqrt(k / s.reduced()) * std::sqrt(1 - xi * xi);
    const double impulse = s.reduced() * (1 + e) * kClosing;
    for (const auto& [integrator, dt, tolerance] :
         {std::tuple{Integrator::exact, 1e-3, 1e-9}, std::tuple{Integrator::newmark, 1e-5, 1e-4}}) {
      const std::string name = fmt::format("{} at {} m", to_string(integrator), height);
      const testing::Collision o = run(s, integrator, dt, 0.03);
      ASSERT_GT(o.separation, o.contact) << name;
      EXPECT_NEAR(o.contact, kGap / kClosing, 1e-9) << name;
      EXPECT_NEAR(o.closing, kClosing, 1e-9) << name;
      EXPECT_NEAR((o.separation - o.contact) * omega_d / std::numbers::pi, 1.0, tolerance) << name;
      EXPECT_NEAR(-o.parting / o.closing, e, tolerance) << name;
      const int above = layout.dof(1, height < 3.0 ? 0 : 1);
      EXPECT_NEAR(o.velocity(layout.dof(0, 0)), kClosing - impulse / 2.0, tolerance * kClosing) << name;
      EXPECT_NEAR(o.velocity(above), s.w * impulse / s.m_above, tolerance * kClosing) << name;
      if (height > 3.0) {
        EXPECT_NEAR(o.velocity(layout.dof(1, 0)), (1 - s.w) * impulse / s.m_below, tolerance * kClosing) << name;
        // No ground in the way: the momentum of the three floors is kept.
        EXPECT_NEAR(2.0 * o.velocity(0) + 3.0 * o.velocity(layout.dof(1, 0)) + 5.0 * o.velocity(above), 2.0 * kClosing,
                    1e-9 * kClosing) << name;
      }
      // The struck column stands still while the slab closes: its approach is the slab's travel.
      EXPECT_NEAR(o.max_approach, o.max_shortening + kGap, 1e-5) << name;
      EXPECT_LT(o.relative_residual, 1e-8) << name;
    }
  }
}

TEST(SlabToColumn, HertzAtAColumnPointReachesGoldsmithsOverlapWithThePointsMass) {
  // s_max = (5 m̄ v₀²/(4 k_h))^{2/5} with m̄ of the slab's floor and the point's mass.
  const double k = 1e9;
  const Strike s = strike(4.0, Hertz{.parameters = {.stiffness = k, .gap = kGap}});
  const testing::Collision o = run(s, Integrator::newmark, 5e-8, 0.009);
  ASSERT_GT(o.separation, o.contact);
  EXPECT_NEAR(o.max_shortening / std::pow(5 * s.reduced() * kClosing * kClosing / (4 * k), 0.4), 1.0, 1e-5);
  EXPECT_NEAR(-o.parting / o.closing, 1.0, 1e-6);
  EXPECT_LT(o.relative_residual, 1e-8);
  // The tangent of a force shared by weights is the weights' outer product (t n nᵀ). At steps of
  // 2e-5 s (45 per contact) Newton takes 1.87 iterations a step with it, 3.19 with the tangent
  // of two floors (±t on the slots) instead.
  const testing::Collision coarse = run(s, Integrator::newmark, 2e-5, 0.009);
  EXPECT_LT(o.mean_newton_iterations, 1.5);
  EXPECT_LT(coarse.mean_newton_iterations, 2.2);
}

TEST(SlabToColumn, AWeightNearOneIsTheFloorPairAndAMirroredModelMirrorsIt) {
  // w → 1 puts the point at the floor above: the element between two floors.
  const KelvinVoigt law{.parameters = {.stiffness = 1e5, .gap = kGap, .restitution = 0.6}};
  Strike s = strike(4.0, law);
  const FloorPair at_floor{.left_frame = 0, .left_floor = 0, .right_floor = 1};
  const FloorPair near_floor{.left_frame = 0, .left_floor = 0, .right_floor = 1,
                             .column = ColumnStrike{.struck = Side::right, .weight = 1 - 1e-12}};
  const Model floors = make_model(s.model.frames, law, {}, std::span(&at_floor, 1));
  const Model column = make_model(s.model.frames, law, {}, std::span(&near_floor, 1));
  Strike a = s, b = s;
  a.model = floors;
  b.model = column;
  const testing::Collision of = run(a, Integrator::exact, 1e-3, 0.03), oc = run(b, Integrator::exact, 1e-3, 0.03);
  for (Eigen::Index i = 0; i < of.velocity.size(); ++i) EXPECT_NEAR(oc.velocity(i), of.velocity(i), 1e-9) << i;
  EXPECT_NEAR(oc.separation, of.separation, 1e-9);

  // The same strike seen from the other side: the two-storey frame on the left, struck by the
  // slab of the one-storey frame on its right, closing at the same speed.
  const FloorPair mirrored{.left_frame = 0, .left_floor = 1, .right_floor = 0,
                           .column = ColumnStrike{.struck = Side::left, .weight = s.w}};
  Strike m = s;
  m.model = make_model({s.model.frames[1], s.model.frames[0]}, law, {}, std::span(&mirrored, 1));
  m.initial.velocity = {{0.0, 0.0}, {-kClosing}};
  EXPECT_EQ(describe(m.model.gaps[0]),
            "gap element between the column of frame 1 between floors 1 and 2 and floor 1 of frame 2");
  const DofLayout left(s.model), right(m.model);
  for (const Integrator integrator : {Integrator::exact, Integrator::newmark}) {
    const testing::Collision o = run(s, integrator, 1e-4, 0.03), mo = run(m, integrator, 1e-4, 0.03);
    // The same sums in another order: equal to round-off.
    EXPECT_NEAR(mo.separation, o.separation, 1e-11);
    EXPECT_NEAR(mo.parting, o.parting, 1e-11);
    EXPECT_NEAR(mo.velocity(right.dof(1, 0)), -o.velocity(left.dof(0, 0)), 1e-11);
    EXPECT_NEAR(mo.velocity(right.dof(0, 1)), -o.velocity(left.dof(1, 1)), 1e-11);
    EXPECT_NEAR(mo.velocity(right.dof(0, 0)), -o.velocity(left.dof(1, 0)), 1e-11);
    EXPECT_NEAR(mo.max_approach, o.max_approach, 1e-11);
  }
}

// Staggered buildings, 6 × 3.0 m beside 5 × 3.6 m (docs/model.md#slab-to-column): the roofs
// meet at 18 m; floor 5 of the left frame (15 m) strikes the right column between its floors 4
// and 5 (14.4 and 18 m, w = 1/6), and floor 4 of the right frame (14.4 m) strikes the left
// column between its floors 4 and 5 (12 and 15 m, w = 0.8).
std::string staggered(const std::string& law) {
  return "[[frames]]\nstoreys = 6\nmass = 2e5\nstiffness = 3e8\ndamping = 2e5\nstorey_height = 3.0\n"
         "[[frames]]\nstoreys = 5\nmass = 2e5\nstiffness = 2e8\ndamping = 2e5\nstorey_height = 3.6\n"
         "[gap_elements]\n" + law + "\npairing = \"listed\"\n"
         "[[gap_elements.pair]]\nframes = [1, 2]\nfloors = [6, 5]\n"
         "[[gap_elements.pair]]\nframes = [1, 2]\nslab = [1, 5]\n"
         "[[gap_elements.pair]]\nframes = [1, 2]\nslab = [2, 4]\n"
         "[initial]\nvelocity = [[0.4, 0.4, 0.4, 0.4, 0.4, 0.4], [-0.4, -0.4, -0.4, -0.4, -0.4]]\n"
         "[analysis]\nkind = \"time_history\"\nduration = 1.0\ndt = 0.0005\n[excitation]\nkind = \"none\"\n";
}

TEST(SlabToColumn, SlabsArePlacedOnTheColumnsByTheirHeights) {
  const io::RunInput in =
      io::read_input_string(staggered("law = \"kelvin_voigt\"\nstiffness = 2e9\ngap = 0.01\nrestitution = 0.7"),
                            "staggered.toml", ".");
  ASSERT_EQ(in.model.gap_count(), 3);
  // Ordered by left floor, then as listed: the left slab 5, the right slab 4 (on the left
  // column below floor 5), the roofs.
  const GapElement& left_slab = in.model.gaps[0];
  EXPECT_EQ(left_slab.floor, 4);
  EXPECT_EQ(left_slab.floor_right(), 4);
  ASSERT_TRUE(left_slab.column);
  EXPECT_EQ(left_slab.column->struck, Side::right);
  EXPECT_NEAR(left_slab.column->weight, (15.0 - 14.4) / 3.6, 1e-12);
  const GapElement& right_slab = in.model.gaps[1];
  EXPECT_EQ(right_slab.floor, 4);
  EXPECT_EQ(right_slab.floor_right(), 3);
  ASSERT_TRUE(right_slab.column);
  EXPECT_EQ(right_slab.column->struck, Side::left);
  EXPECT_NEAR(right_slab.column->weight, (14.4 - 12.0) / 3.0, 1e-12);
  EXPECT_FALSE(in.model.gaps[2].column);
  EXPECT_EQ(describe(left_slab), "gap element between floor 5 of frame 1 and the column of frame 2 between floors 4 and 5");
  const DofLayout layout(in.model);
  EXPECT_EQ(describe(make_links(in.model, layout)[static_cast<std::size_t>(layout.size()) + 1], layout),
            "the Kelvin–Voigt contact between the column of frame 1 between floors 4 and 5 and floor 4 of frame 2");
  // The echo writes the slabs, which read back to the same weights.
  const io::RunInput again = io::read_input_string(io::to_toml(in), "input.toml", ".");
  ASSERT_EQ(again.model.gap_count(), 3);
  for (int p = 0; p < 3; ++p) EXPECT_EQ(again.model.gaps[p].column, in.model.gaps[p].column) << p;
  EXPECT_EQ(io::to_toml(again), io::to_toml(in));
  EXPECT_NE(io::to_toml(in).find("slab = [ 2, 4 ]"), std::string::npos) << io::to_toml(in);
}

std::string error_of(const std::string& text) {
  try {
    (void)io::read_input_string(text, "staggered.toml", ".");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SlabToColumn, BadSlabsAreRefusedNamingTheKey) {
  const std::string kv = "law = \"kelvin_voigt\"\nstiffness = 2e9\ngap = 0.01\nrestitution = 0.7";
  const std::string base = staggered(kv);
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = base;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  // The paper's element has a stop, whose impacts and locking join two floors.
  const std::string paper = error_of(staggered("law = \"paper\"\nstiffness = 2e9\ngap = 0.01\nshortening = 0.005\nrestitution = 0.7"));
  EXPECT_NE(paper.find("gap_elements.law: \"paper\" for the gap element between floor 5 of frame 1 and the column of "
                       "frame 2 between floors 4 and 5: a slab that strikes a column takes a contact law without a stop"),
            std::string::npos) << paper;
  // So does an override that gives a slab the paper's element.
  const std::string override = error_of(
      base + "[[gap_elements.override]]\nframes = [1, 2]\nfloor = 5\nright_floor = 5\nlaw = \"paper\"\n"
             "stiffness = 2e9\ngap = 0.01\nshortening = 0.005\nrestitution = 0.7\n");
  EXPECT_NE(override.find("gap_elements.override[1].law: \"paper\" for the gap element between floor 5 of frame 1"),
            std::string::npos) << override;
  // A slab above the neighbour's roof has no column to strike.
  const std::string high = error_of(with("slab = [1, 5]", "slab = [1, 5]\n[[gap_elements.pair]]\nframes = [1, 2]\nslab = [1, 6]"));
  EXPECT_NE(high.find("gap_elements.pair[3].slab"), std::string::npos) << high;
  // 6 × 3.0 = 18 and 5 × 3.6 = 18.000000000000004 are the same height: that slab meets a floor,
  // which already has an element (the roofs).
  EXPECT_NE(high.find("already has a gap element"), std::string::npos) << high;
  // Left storeys of 3.8 m put floor 5 at 19 m, above the right roof (18 m).
  const std::string above = error_of(with("storey_height = 3.0", "storey_height = 3.8"));
  EXPECT_NE(above.find("gap_elements.pair[2].slab"), std::string::npos) << above;
  EXPECT_NE(above.find("above the roof of frame 2 (18 m)"), std::string::npos) << above;
  EXPECT_NE(error_of(with("slab = [1, 5]", "slab = [1, 5]\nfloors = [5, 5]")).find("give floors"), std::string::npos);
  const std::string frame = error_of(with("slab = [1, 5]", "slab = [3, 5]"));
  EXPECT_NE(frame.find("gap_elements.pair[2].slab"), std::string::npos) << frame;
  EXPECT_NE(frame.find("one of the pair's frames"), std::string::npos) << frame;
  const std::string no_heights = error_of(with("storey_height = 3.6\n", ""));
  EXPECT_NE(no_heights.find("missing key: storey_height"), std::string::npos) << no_heights;
  EXPECT_NE(no_heights.find("frames[2]"), std::string::npos) << no_heights;
  // The right slab 4 and the left slab 5 both have floor 5 of frame 1 at their left: an override
  // names one by its right floor too.
  const std::string ambiguous =
      error_of(base + "[[gap_elements.override]]\nframes = [1, 2]\nfloor = 5\nrestitution = 0.5\n");
  EXPECT_NE(ambiguous.find("gap_elements.override[1].floor"), std::string::npos) << ambiguous;
  EXPECT_NE(ambiguous.find("give right_floor"), std::string::npos) << ambiguous;
  const std::string nowhere =
      error_of(base + "[[gap_elements.override]]\nframes = [1, 2]\nfloor = 5\nright_floor = 2\nrestitution = 0.5\n");
  EXPECT_NE(nowhere.find("gap_elements.override[1].right_floor: no gap element joins floor 5 of frame 1 to floor 2 "
                         "of frame 2"), std::string::npos) << nowhere;
}

TEST(SlabToColumn, AnOverrideNamesASlabByItsRightFloorAndTheEchoKeepsIt) {
  // The right slab 4 (left floor 5, right floor 4) gets its own restitution; every element a
  // joint wider than its gap, so the echo writes an override per element, named unambiguously.
  const std::string text = staggered("law = \"kelvin_voigt\"\nstiffness = 2e9\ngap = 0.01\nrestitution = 0.7\n"
                                     "joint_width = 0.02") +
                           "[[gap_elements.override]]\nframes = [1, 2]\nfloor = 5\nright_floor = 4\nrestitution = 0.5\n";
  const io::RunInput in = io::read_input_string(text, "staggered.toml", ".");
  ASSERT_EQ(in.model.gap_count(), 3);
  EXPECT_EQ(std::get<KelvinVoigt>(in.model.gaps[0].law).parameters.restitution, 0.7);  // the left slab 5
  EXPECT_EQ(std::get<KelvinVoigt>(in.model.gaps[1].law).parameters.restitution, 0.5);  // the right slab 4
  EXPECT_EQ(in.joint_widths, (std::vector<double>{0.02, 0.02, 0.02}));
  const std::string echo = io::to_toml(in);
  EXPECT_NE(echo.find("right_floor = 4"), std::string::npos) << echo;
  const io::RunInput again = io::read_input_string(echo, "input.toml", ".");
  EXPECT_EQ(io::to_toml(again), echo);
  EXPECT_EQ(again.joint_widths, in.joint_widths);
  for (int p = 0; p < 3; ++p) EXPECT_EQ(again.model.gaps[p].law, in.model.gaps[p].law) << p;
}

TEST(SlabToColumn, AnInitialOverlapIsJudgedAtTheColumnPoint) {
  // Left floor 5 at 15 m faces the right column at w = 1/6 between its floors 4 and 5. At rest
  // with the right floors 4 and 5 at −0.03 and +0.03 m, the point is at −0.02 m: 0.02 m from the
  // slab, 0.01 m into the gap, so the element starts in contact with k·0.01; with floor 5 alone
  // at −0.05 m (which would overlap as a floor) the point is at −0.0083 m, clear of the slab.
  const auto start_force = [](const std::string& right) {
    std::string text = staggered("law = \"kelvin_voigt\"\nstiffness = 2e9\ngap = 0.01\nrestitution = 0.7");
    const std::string velocity = "velocity = [[0.4, 0.4, 0.4, 0.4, 0.4, 0.4], [-0.4, -0.4, -0.4, -0.4, -0.4]]";
    text.replace(text.find(velocity), velocity.size(), "displacement = [[0, 0, 0, 0, 0, 0], " + right + "]");
    const io::RunInput in = io::read_input_string(text, "staggered.toml", ".");
    Simulator sim(in.model, in.excitation, in.analysis.options, in.initial);
    return sim.gap_force(0);
  };
  EXPECT_NEAR(start_force("[0, 0, 0, -0.03, 0.03]"), 2e9 * 0.01, 1e-6 * 2e7);
  EXPECT_EQ(start_force("[0, 0, 0, 0, -0.05]"), 0.0);
}

TEST(SlabToColumn, StaggeredFramesPoundWithTheBalanceClosedAndNewmarkConvergesToExact) {
  // The Kelvin–Voigt contacts are piecewise linear: the exact integrator is the reference, and
  // Newmark's peak displacements (refined between steps) approach it at second order.
  const io::RunInput in =
      io::read_input_string(staggered("law = \"kelvin_voigt\"\nstiffness = 2e9\ngap = 0.01\nrestitution = 0.7"),
                            "staggered.toml", ".");
  const auto peaks = [&](Integrator integrator, double dt) {
    TimeHistoryOptions options = in.analysis.options;
    options.integrator = integrator;
    options.dt = dt;
    Simulator sim(in.model, in.excitation, options, in.initial);
    sim.advance_to(1.0);
    const ResponseStatistics& st = sim.statistics();
    EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-9) << to_string(integrator);
    for (const GapResponse& g : st.gaps) EXPECT_GT(g.contacts, 0) << to_string(integrator);
    // Each element's facing points come closest when it is most compressed.
    for (std::size_t k = 0; k < st.neighbours.size(); ++k) {
      EXPECT_NEAR(st.neighbours[k].max_approach, st.gaps[k].shortening.value + 0.01, 2e-5) << k;
    }
    std::vector<double> p;
    for (const FloorResponse& f : st.floors) p.push_back(f.displacement.value);
    return p;
  };
  const std::vector<double> exact = peaks(Integrator::exact, 5e-4);
  const std::vector<double> coarse = peaks(Integrator::newmark, 2e-5), fine = peaks(Integrator::newmark, 1e-5);
  double error_coarse = 0, error_fine = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    error_coarse = std::max(error_coarse, std::abs(coarse[i] - exact[i]) / std::abs(exact[i]));
    error_fine = std::max(error_fine, std::abs(fine[i] - exact[i]) / std::abs(exact[i]));
  }
  EXPECT_LT(error_fine, 2e-7);
  EXPECT_NEAR(std::log2(error_coarse / error_fine), 2.0, 0.3) << error_coarse << " " << error_fine;
}

TEST(SlabToColumn, SlabsOnColumnsBesideRoofsThatImpactAndLock) {
  // The roofs carry the paper's element (impacts at its stroke, locking), the slabs Kelvin–Voigt
  // contacts on the columns: the stop reactions of locked roofs see the slabs' forces shared by
  // weights, and the exact integrator's reaction guards the assembled n nᵀ.
  const std::string text =
      staggered("law = \"kelvin_voigt\"\nstiffness = 2e9\ngap = 0.01\nrestitution = 0.7") +
      "[[gap_elements.override]]\nframes = [1, 2]\nfloor = 6\nlaw = \"paper\"\nstiffness = 2e8\ngap = 0.01\n"
      "shortening = 0.002\nrestitution = 0.5\n";
  const io::RunInput in = io::read_input_string(text, "staggered.toml", ".");
  ASSERT_TRUE(std::holds_alternative<PaperGap>(in.model.gaps[2].law));
  std::vector<double> peaks[2];
  for (const Integrator integrator : {Integrator::exact, Integrator::newmark}) {
    TimeHistoryOptions options = in.analysis.options;
    options.integrator = integrator;
    options.dt = integrator == Integrator::exact ? 5e-4 : 1e-5;
    Simulator sim(in.model, in.excitation, options, in.initial);
    sim.advance_to(1.0);
    const ResponseStatistics& st = sim.statistics();
    EXPECT_GT(st.gaps[2].impacts, 0) << to_string(integrator);
    EXPECT_GT(st.gaps[0].contacts + st.gaps[1].contacts, 0) << to_string(integrator);
    EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-9) << to_string(integrator);
    for (const FloorResponse& f : st.floors) peaks[integrator == Integrator::exact ? 0 : 1].push_back(f.displacement.value);
  }
  for (std::size_t i = 0; i < peaks[0].size(); ++i) EXPECT_NEAR(peaks[1][i], peaks[0][i], 1e-5 * peaks[0][i]) << i;
}

TEST(SlabToColumn, HertzdampSlabsCloseTheBalanceAtSecondOrder) {
  // Newmark's trapezoidal work of a nonlinear force leaves a residual O(h²): it must fall by 4
  // when h halves, which a force shared by other weights than the point's motion would not do,
  // and it is below 1e-8 of the input at h = 1.25e-6 s.
  const io::RunInput in = io::read_input_string(
      staggered("law = \"hertzdamp\"\nstiffness = 5e10\ngap = 0.01\nrestitution = 0.6"), "staggered.toml", ".");
  const auto residual = [&](double dt) {
    TimeHistoryOptions options = in.analysis.options;
    options.dt = dt;
    Simulator sim(in.model, in.excitation, options, in.initial);
    sim.advance_to(0.15);
    for (const GapResponse& g : sim.statistics().gaps) EXPECT_GT(g.contacts, 0);
    EXPECT_GT(sim.energy().gap_damping, 0.0);
    return sim.energy_meter().max_relative_residual();
  };
  const double coarse = residual(2e-5), fine = residual(1e-5);
  EXPECT_NEAR(std::log2(coarse / fine), 2.0, 0.2) << coarse << " " << fine;
  EXPECT_LT(residual(1.25e-6), 1e-8);
}

}  // namespace
}  // namespace poundsim
