// The pounding system on its own, without a simulator: its guards at a state, and what a fired
// guard does — against the closed forms of contact and of an impact with restitution.
#include "poundsim/dynamics/system.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "test_models.hpp"

namespace poundsim {
namespace {

/// The least a loop provides: the phase of each configuration, and an ear for the events.
class Recorder final : public EventHandler {
 public:
  explicit Recorder(const PoundingSystem& system) : system_(system) {}
  LinearPhase& activate(const ContactState& c) override {
    std::unique_ptr<LinearPhase>& phase = phases_[c.config];
    if (!phase) phase = std::make_unique<LinearPhase>(system_.model(), system_.layout(), c.config, 1e-3);
    if (!phase->is_unreduced()) phase->set_link_lengths(c.link_length);
    return *phase;
  }
  void on_event(const KinematicState& x, int gap, EventKind kind, double left_before, double right_before,
                double impulse) override {
    events.push_back(Event{x.t, gap, kind, left_before - right_before, 0.0, impulse, left_before, right_before,
                           0.0, 0.0});
  }
  void on_impact_loss(double loss) override { impact_loss += loss; }

  std::vector<Event> events;
  double impact_loss = 0.0;

 private:
  const PoundingSystem& system_;
  std::map<ContactConfiguration, std::unique_ptr<LinearPhase>> phases_;
};

constexpr double kGap = 0.01;

/// Two single-storey frames of 2 and 3 kg with one gap element between them.
PoundingSystem two_frames(GapProperties gap) {
  return PoundingSystem(testing::two_oscillators(2.0, 50.0, 0.0, 3.0, 80.0, 0.0, gap), NoExcitation{},
                        EventRules{});
}

KinematicState state_at(double u1, double u2, double v1, double v2) {
  KinematicState x;
  x.resize(2);
  x.u << u1, u2;
  x.v << v1, v2;
  return x;
}

/// The system's state after the events fired at the first state past the gap.
struct AfterEvents {
  KinematicState x;
  ContactState contact;
  std::vector<double> g, dg;
};

/// Starts open (u₁ − u₂ = δ − 1e-6, u̇₁ = 0.4, u̇₂ = −0.2), moves to s = 1e-9 as an integrator
/// reaches it, and applies the events whose guards fired there.
AfterEvents fire_just_past_the_gap(const PoundingSystem& system, Recorder& recorder) {
  AfterEvents r{state_at(kGap - 1e-6, 0.0, 0.4, -0.2), {}, std::vector<double>(2), std::vector<double>(2)};
  r.contact = system.initial_contact(r.x);
  LinearPhase& phase = recorder.activate(r.contact);
  system.refresh_flags(r.contact);
  r.x.u(0) = kGap + 1e-9;
  system.equilibrate(phase, r.x, r.contact);
  system.evaluate_guards(r.x, phase, r.contact, r.g, r.dg);
  EXPECT_GT(r.g[0], 0.0);
  const std::vector<double> fired = r.g;
  system.apply_events(fired, r.x, r.contact, phase, r.g, r.dg, recorder);
  return r;
}

TEST(PoundingSystem, AnOpenElementsGuardIsItsShorteningAndFiresPastTheGap) {
  const PoundingSystem system = two_frames({.gap = kGap, .restitution = 0.5});
  Recorder recorder(system);
  KinematicState x = state_at(0.004, -0.001, 0.3, -0.2);
  ContactState c = system.initial_contact(x);
  const LinearPhase& phase = recorder.activate(c);
  system.refresh_flags(c);
  std::vector<double> g(2), dg(2);
  system.evaluate_guards(x, phase, c, g, dg);
  // s = u₁ − u₂ − δ = −0.005 (less its round-off level), ṡ = 0.5; no separation guard while open.
  EXPECT_NEAR(g[0], -0.005, 1e-15);
  EXPECT_LT(g[0], -0.005);
  EXPECT_EQ(dg[0], 0.5);
  EXPECT_EQ(g[1], -std::numeric_limits<double>::infinity());
  x.u(0) = kGap + x.u(1) + 1e-6;
  system.evaluate_guards(x, phase, c, g, dg);
  EXPECT_GT(g[0], 0.0);
  EXPECT_EQ(system.gap_force(x, c, 0), 0.0);
  EXPECT_NEAR(system.shortening(x, 0), 1e-6, 1e-17);
}

// Bare pounding (k = c = ε = 0): the fired guard is an impact with restitution e between the two
// floors, m₁ v₁ + m₂ v₂ kept and the closing speed reversed times e; the loss is ½ m̄ (1 − e²) w².
TEST(PoundingSystem, AFiredStopIsAnImpactWithRestitution) {
  const double e = 0.5;
  const PoundingSystem system = two_frames({.gap = kGap, .restitution = e});
  Recorder recorder(system);
  auto [x, c, g, dg] = fire_just_past_the_gap(system, recorder);

  const double m1 = 2.0, m2 = 3.0, w = 0.6;
  const double momentum = m1 * 0.4 + m2 * -0.2;
  EXPECT_NEAR(m1 * x.v(0) + m2 * x.v(1), momentum, 1e-15);
  EXPECT_NEAR(x.v(0) - x.v(1), -e * w, 1e-15);
  const double reduced = m1 * m2 / (m1 + m2);
  EXPECT_NEAR(recorder.impact_loss, 0.5 * reduced * (1 - e * e) * w * w, 1e-15);
  ASSERT_EQ(recorder.events.size(), 1U);
  EXPECT_EQ(recorder.events[0].kind, EventKind::impact);
  EXPECT_NEAR(recorder.events[0].impulse, reduced * (1 + e) * w, 1e-15);
  // After it the floors part: nothing fires, the accelerations are the springs' −k u / m again.
  EXPECT_FALSE(g[0] > 0 || g[1] > 0);
  EXPECT_NEAR(x.a(0), -50.0 * (kGap + 1e-9) / m1, 1e-15);
  EXPECT_EQ(x.a(1), 0.0);
}

// A gap element with a stroke: reaching the gap is a contact (no impulse), after which it pushes
// the floors apart with F = k s + c ṡ.
TEST(PoundingSystem, AFiredApproachWithAStrokeIsAContactAndTheElementPushes) {
  const GapProperties p{.stiffness = 1e4, .damping = 20.0, .gap = kGap, .shortening = 0.005, .restitution = 0.8};
  const PoundingSystem system = two_frames(p);
  Recorder recorder(system);
  auto [x, c, g, dg] = fire_just_past_the_gap(system, recorder);
  ASSERT_EQ(recorder.events.size(), 1U);
  EXPECT_EQ(recorder.events[0].kind, EventKind::contact);
  EXPECT_EQ(recorder.impact_loss, 0.0);
  EXPECT_EQ(x.v(0), 0.4);  // no jump
  const double force = contact_force(p, 1e-9, 0.6);
  EXPECT_DOUBLE_EQ(system.gap_force(x, c, 0), force);
  EXPECT_NEAR(x.a(0), (-50.0 * (kGap + 1e-9) - force) / 2.0, 1e-12);
  EXPECT_NEAR(x.a(1), force / 3.0, 1e-12);
  // In contact its stop guard is s − ε and its separation guard −s.
  EXPECT_NEAR(g[0], 1e-9 - 0.005, 1e-15);
  EXPECT_NEAR(g[1], -1e-9, 1e-15);
}

// The law's own state: under the force criterion, a separation with the spring still compressed
// leaves the element's free end relaxing, s_e(t) = s₀ exp(−k (t − t₀)/c) (PaperGap::State), which
// the system keeps for the link's law and its next approach guard measures against.
TEST(PoundingSystem, AForceSeparationLeavesTheLawsStateRelaxing) {
  const GapProperties p{.stiffness = 1e4, .damping = 20.0, .gap = kGap, .shortening = 0.005, .restitution = 0.8};
  const PoundingSystem system(testing::two_oscillators(2.0, 50.0, 0.0, 3.0, 80.0, 0.0, p), NoExcitation{},
                              EventRules{.separation = SeparationCriterion::force});
  Recorder recorder(system);
  const double s0 = 0.002, t0 = 1.5;
  // In contact, s = 0.002 and ṡ = −1.3: F = k s + c ṡ = 20 − 26 = −6 N, tensile, so it separates.
  KinematicState x = state_at(kGap + s0, 0.0, -0.8, 0.5);
  x.t = t0;
  ContactState c = system.initial_contact(x);
  ASSERT_EQ(c.config[0], PaperGap::link_mode(GapMode::contact));
  const PaperGap& law = std::get<PaperGap>(system.contact_links()[0].law);
  EXPECT_EQ(c.states.at(law, 0), PaperGap::State{});
  LinearPhase& phase = recorder.activate(c);
  system.refresh_flags(c);
  std::vector<double> g(2), dg(2);
  system.evaluate_guards(x, phase, c, g, dg);
  EXPECT_NEAR(g[1], 6.0, 1e-12);
  const std::vector<double> fired{0.0, g[1]};
  system.apply_events(fired, x, c, phase, g, dg, recorder);
  ASSERT_EQ(recorder.events.size(), 1U);
  EXPECT_EQ(recorder.events[0].kind, EventKind::separation);
  EXPECT_EQ(c.config[0], PaperGap::link_mode(GapMode::open));
  EXPECT_EQ(c.states.at(law, 0), (PaperGap::State{.released_shortening = s0, .release_time = t0}));
  // The approach guard is s − s_e: zero at the release, and k/c·1 ms later s_e has decayed by e^−½.
  EXPECT_NEAR(g[0], 0.0, 1e-15);
  x.t = t0 + 1e-3;
  system.evaluate_guards(x, recorder.activate(c), c, g, dg);
  EXPECT_NEAR(g[0], s0 * (1 - std::exp(-0.5)), 1e-15);
  // A restart at t0 + 1 ms makes the release time relative to the new origin.
  c.states.shift_clock(x.t);
  EXPECT_NEAR(c.states.at(law, 0).release_time, -1e-3, 1e-15);
}

}  // namespace
}  // namespace poundsim
