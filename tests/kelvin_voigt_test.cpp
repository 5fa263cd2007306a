// The Kelvin–Voigt contact (model/laws/kelvin_voigt.hpp) against its closed forms: two free
// masses in contact are a damped oscillator in s, which separates (s = 0) after π/ω_d with exactly
// e times its closing speed; both integrators, and the energy balance closed.
#include "poundsim/model/laws/kelvin_voigt.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/model.hpp"
#include "collision.hpp"

namespace poundsim {
namespace {

TEST(KelvinVoigt, DampingRatioGivesTheRestitution) {
  // ξ = −ln e/√(π² + ln² e), and e^{−ξπ/√(1−ξ²)} = e back.
  for (const double e : {0.2, 0.5, 0.6, 0.9}) {
    const double xi = KelvinVoigt::damping_ratio(e);
    EXPECT_NEAR(std::exp(-xi * std::numbers::pi / std::sqrt(1 - xi * xi)), e, 1e-15) << e;
  }
  EXPECT_EQ(KelvinVoigt::damping_ratio(1.0), 0.0);
  EXPECT_EQ(KelvinVoigt::damping_ratio(0.0), 1.0);
  KelvinVoigt law{.parameters = {.stiffness = 1e5, .gap = 0.01, .restitution = 0.6}};
  law.bind_masses(2.0, 3.0);
  EXPECT_NEAR(law.damping, 2 * KelvinVoigt::damping_ratio(0.6) * std::sqrt(1e5 * 1.2), 1e-9);
}

/// Frames of 2 and 3 kg on storeys 10¹¹ times softer than the contact (free masses to 1e-11),
/// closing at 1.5 m/s across a gap of 0.01 m.
testing::Collision collide(Integrator integrator, double dt) {
  const KelvinVoigt law{.parameters = {.stiffness = 1e5, .gap = testing::kGap, .restitution = 0.6}};
  return testing::collide(law, dt, integrator, 0.03);
}

TEST(KelvinVoigt, TwoFreeMassesPartAfterPiOverOmegaDWithRestitutionE) {
  const double reduced = 1.2, k = 1e5, e = 0.6;
  const double xi = KelvinVoigt::damping_ratio(e);
  const double omega_d = std::sqrt(k / reduced) * std::sqrt(1 - xi * xi);
  for (const auto& [integrator, dt, tolerance] :
       {std::tuple{Integrator::exact, 1e-3, 1e-9}, std::tuple{Integrator::newmark, 1e-5, 1e-4}}) {
    const testing::Collision c = collide(integrator, dt);
    const std::string name(to_string(integrator));
    ASSERT_GT(c.contact, 0.0) << name;
    ASSERT_GT(c.separation, c.contact) << name;
    EXPECT_NEAR(c.contact, 0.01 / 1.5, 1e-9) << name;
    EXPECT_NEAR(c.closing, 1.5, 1e-9) << name;
    EXPECT_NEAR((c.separation - c.contact) * omega_d / std::numbers::pi, 1.0, tolerance) << name;
    EXPECT_NEAR(-c.parting / c.closing, e, tolerance) << name;
    EXPECT_LT(c.relative_residual, 1e-8) << name;
    // What the run reports of the contact: its duration and restitution, and the energy the
    // dashpot took, ½ m̄ v₀² (1 − e²).
    EXPECT_EQ(c.completed_contacts, 1) << name;
    EXPECT_NEAR(c.contact_time * omega_d / std::numbers::pi, 1.0, tolerance) << name;
    EXPECT_NEAR(c.longest_contact, c.separation - c.contact, 1e-12) << name;
    EXPECT_NEAR(c.mean_restitution, e, tolerance) << name;
    EXPECT_NEAR(c.gap_damping / (0.5 * reduced * 1.5 * 1.5 * (1 - e * e)), 1.0, tolerance) << name;
    if (integrator == Integrator::newmark) {
      EXPECT_NEAR(c.element_dissipation, c.gap_damping, 1e-12 * c.gap_damping) << name;
    } else {
      EXPECT_EQ(c.element_dissipation, -1) << "the exact integrator has no per-element integrals";
    }
  }
}

// Floors on storeys of 1e-3 … 1e-12 N/m are all but free: their modes are slow (|λ| dt ≪ 1) and
// their modal coefficients |c| ~ v/ω huge. Summed as V c e^{λs}, the trajectory and the guards
// carried ε v/ω of round-off, and the guard's margin 16 times that: the exact integrator found
// the contact late by ~16 ε/ω (3.6e-9 s at 1e-12 N/m), the spring already compressed, and the
// restitution came out high by 2ξω_c τ (1e-6). Summed apart (ExactPhase::slow_modes), the contact
// is found within the event resolution (16 ulps of 1 s) and the restitution is the law's.
TEST(KelvinVoigt, NearlyFreeFloorsMeetOnTimeInTheExactIntegrator) {
  const double kc = 1e5, e = 0.6, vl = 1.0, vr = -0.5;
  const KelvinVoigt law{.parameters = {.stiffness = kc, .gap = testing::kGap, .restitution = e}};
  constexpr double resolution = 16 * std::numeric_limits<double>::epsilon();
  for (const double k : {1e-3, 1e-6, 1e-9, 1e-12}) {
    const Model model = make_model({make_uniform_frame(1, testing::kLeftMass, k, 0.0),
                                    make_uniform_frame(1, testing::kRightMass, k, 0.0)},
                                   GapLaw(law));
    InitialConditions ic;
    ic.velocity = {{vl}, {vr}};
    const testing::Collision c = testing::collide(model, ic, 1e-4, Integrator::exact, 0.03);
    // Before contact each floor moves as v sin(ωt)/ω: the contact time by Newton's method.
    const double wl = std::sqrt(k / testing::kLeftMass), wr = std::sqrt(k / testing::kRightMass);
    double t = testing::kGap / (vl - vr);
    for (int i = 0; i < 8; ++i) {
      const double f = vl * std::sin(wl * t) / wl - vr * std::sin(wr * t) / wr - testing::kGap;
      t -= f / (vl * std::cos(wl * t) - vr * std::cos(wr * t));
    }
    EXPECT_NEAR(c.contact, t, resolution) << k;
    // The storeys' own effect on the restitution is of order k/k_c (2.4 k/k_c measured at 1e-3).
    EXPECT_NEAR(-c.parting / c.closing, e, 1e-12 + 10 * k / kc) << k;
    // (At 1e-6 N/m the contact phase's slow pair, ±6e-4i beside ω_c = 289 rad/s, is too nearly
    // parallel in the balanced modes and takes the matrix exponential and quadrature: 3.6e-12.)
    EXPECT_LT(c.relative_residual, 1e-11) << k;
    std::printf("[ measured ] storeys of %g N/m: contact %.3g s from its closed form, restitution %.3g from e\n", k,
                c.contact - t, -c.parting / c.closing - e);
  }
}

TEST(KelvinVoigt, IsChosenByItsNameInAModelFile) {
  const std::string text =
      "[[frames]]\nstoreys = 1\nmass = 2.0\nstiffness = 100.0\ndamping = 0.0\n"
      "[[frames]]\nstoreys = 1\nmass = 3.0\nstiffness = 100.0\ndamping = 0.0\n"
      "[gap_elements]\nlaw = \"kelvin_voigt\"\nstiffness = 1e5\ngap = 0.01\nrestitution = 0.6\n"
      "[analysis]\nkind = \"time_history\"\nduration = 0.1\ndt = 0.001\n[excitation]\nkind = \"none\"\n";
  const io::RunInput in = io::read_input_string(text, "kv.toml", ".");
  ASSERT_EQ(in.model.gaps.size(), 1U);
  const auto& law = std::get<KelvinVoigt>(in.model.gaps[0].law);
  EXPECT_EQ(law.parameters, (KelvinVoigt::Parameters{.stiffness = 1e5, .gap = 0.01, .restitution = 0.6}));
  std::string bad = text;
  bad.replace(bad.find("stiffness = 1e5"), 15, "stiffness = 0.0");
  try {
    (void)io::read_input_string(bad, "kv.toml", ".");
    ADD_FAILURE() << "a contact without spring";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("gap_elements.stiffness: must be > 0 (got 0)"), std::string::npos)
        << error.what();
  }
  // The links bind its dashpot to the floors' reduced mass.
  const std::vector<Link> links = make_links(in.model, DofLayout(in.model));
  EXPECT_NEAR(std::get<KelvinVoigt>(links.back().law).damping,
              2 * KelvinVoigt::damping_ratio(0.6) * std::sqrt(1e5 * 1.2), 1e-9);
}

}  // namespace
}  // namespace poundsim
