// The bilinear impact law (model/laws/impact.hpp) against its closed forms: two free masses
// colliding through it load on K1 to δ_y and on K2 to the penetration s_m where the loading
// curve's area is ½ m̄ v₀², unload on K1 to the line K2 s and on it to s = 0; the loop dissipates
// (K1 − K2) δ_y (s_m − δ_y), and Muthukumar's derivation dissipates ΔE at s_m = δ_m.
#include "poundsim/model/laws/impact.hpp"

#include <cmath>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/model.hpp"
#include "collision.hpp"

namespace poundsim {
namespace {

/// The penetration where the loading curve's area is `energy` [m] (beyond δ_y).
double max_penetration(const Impact& law, double energy) {
  const double k1 = law.k1(), k2 = law.k2(), dy = law.yield_penetration();
  const double beyond = energy - 0.5 * k1 * dy * dy;  // ½ K2 x² + K1 δ_y x = beyond
  return dy + (-k1 * dy + std::sqrt(k1 * k1 * dy * dy + 2.0 * k2 * beyond)) / k2;
}

/// Two free masses (m̄ = 1.2 kg) closing at v₀ across the law's gap.
testing::Collision collide(const Impact& law, double v0, Integrator integrator, double dt) {
  const Model model = make_model({make_uniform_frame(1, testing::kLeftMass, 1e-6, 0.0),
                                  make_uniform_frame(1, testing::kRightMass, 1e-6, 0.0)},
                                 GapLaw(law));
  InitialConditions ic;
  ic.velocity = {{v0}, {0.0}};
  return testing::collide(model, ic, dt, integrator, 0.1);
}

constexpr double kReduced = testing::kReduced;

void expect_closed_form(const Impact& law, double v0, double s_m, double dissipated) {
  const double kinetic = 0.5 * kReduced * v0 * v0;
  for (const auto& [integrator, dt, tolerance] :
       {std::tuple{Integrator::exact, 1e-3, 1e-9}, std::tuple{Integrator::newmark, 1e-6, 1e-4}}) {
    const testing::Collision c = collide(law, v0, integrator, dt);
    const std::string name(to_string(integrator));
    ASSERT_GT(c.separation, c.contact) << name;
    EXPECT_EQ(c.completed_contacts, 1) << name;
    EXPECT_NEAR(c.max_shortening / s_m, 1.0, tolerance) << name;
    EXPECT_NEAR(c.gap_damping / dissipated, 1.0, tolerance) << name;
    // The floors part with what the loop left: e_eff = √(1 − D/(½ m̄ v₀²)).
    EXPECT_NEAR(-c.parting / v0, std::sqrt(1.0 - dissipated / kinetic), tolerance) << name;
    EXPECT_LT(c.relative_residual, 1e-8) << name;
  }
}

TEST(ImpactLaw, OneImpactYieldsToTheClosedFormPenetrationAndLoop) {
  const Impact law{.parameters = {.k1 = 1e5, .k2 = 2e4, .yield_penetration = 1e-3, .gap = testing::kGap}};
  const double v0 = 1.5;
  const double s_m = max_penetration(law, 0.5 * kReduced * v0 * v0);
  const double dissipated = (1e5 - 2e4) * 1e-3 * (s_m - 1e-3);
  EXPECT_GT(s_m, 8e-3);
  expect_closed_form(law, v0, s_m, dissipated);
}

TEST(ImpactLaw, MuthukumarsDerivationDissipatesDeltaEAtTheMaxPenetration) {
  const Impact law{.parameters = {.gap = testing::kGap, .stiffness = 1e7, .max_penetration = 5e-3,
                                  .restitution = 0.6, .yield_ratio = 0.1}};
  ASSERT_FALSE(law.parameters.rule_violation());
  const double dm = 5e-3, keff = 1e7 * std::sqrt(dm);
  const double delta_e = 1e7 * std::pow(dm, 2.5) * (1 - 0.36) / 2.5;
  EXPECT_NEAR(law.parameters.target_dissipation(), delta_e, 1e-12 * delta_e);
  EXPECT_NEAR(law.k1(), keff + delta_e / (0.1 * dm * dm), 1e-9 * keff);
  EXPECT_NEAR(law.k2(), keff - delta_e / (0.9 * dm * dm), 1e-9 * keff);
  EXPECT_NEAR(law.yield_penetration(), 0.1 * dm, 1e-18);
  // The closing speed whose loading area to δ_m is ½ m̄ v₀²: K_eff δ_m²/2 + ΔE/2.
  const double loading = 0.5 * keff * dm * dm + 0.5 * delta_e;
  const double v0 = std::sqrt(2.0 * loading / kReduced);
  EXPECT_NEAR(max_penetration(law, loading) / dm, 1.0, 1e-12);
  expect_closed_form(law, v0, dm, delta_e);
}

TEST(ImpactLaw, ParametersAreOneWholeSet) {
  using P = Impact::Parameters;
  const auto blamed = [](const P& p) { return p.rule_violation() ? p.rule_violation()->keys.front() : "none"; };
  EXPECT_EQ(blamed(P{.k1 = 1e5, .k2 = 2e4, .yield_penetration = 1e-3}), "none");
  EXPECT_EQ(blamed(P{.k1 = 1e5, .k2 = 2e5, .yield_penetration = 1e-3}), "k2");
  EXPECT_EQ(blamed(P{.k1 = 1e5, .k2 = 2e4}), "yield_penetration");
  EXPECT_EQ(blamed(P{}), "k1");
  EXPECT_EQ(blamed(P{.stiffness = 1e7, .max_penetration = 5e-3}), "restitution");
  EXPECT_EQ(blamed(P{.k1 = 1e5, .stiffness = 1e7, .max_penetration = 5e-3, .restitution = 0.6}), "k1");
  EXPECT_EQ(blamed(P{.stiffness = 1e7, .restitution = 0.6}), "max_penetration");
  EXPECT_EQ(blamed(P{.stiffness = 1e7, .max_penetration = 5e-3, .restitution = 0.0, .yield_ratio = 0.9}),
            "yield_ratio");
}

TEST(ImpactLaw, IsChosenByItsNameInAModelFile) {
  const std::string text =
      "[[frames]]\nstoreys = 1\nmass = 2.0\nstiffness = 100.0\ndamping = 0.0\n"
      "[[frames]]\nstoreys = 1\nmass = 3.0\nstiffness = 100.0\ndamping = 0.0\n"
      "[gap_elements]\nlaw = \"impact\"\nk1 = 1e5\nk2 = 2e4\nyield_penetration = 0.001\ngap = 0.01\n"
      "[analysis]\nkind = \"time_history\"\nduration = 0.1\ndt = 0.001\n[excitation]\nkind = \"none\"\n";
  const io::RunInput in = io::read_input_string(text, "impact.toml", ".");
  ASSERT_EQ(in.model.gaps.size(), 1U);
  EXPECT_EQ(std::get<Impact>(in.model.gaps[0].law).parameters,
            (Impact::Parameters{.k1 = 1e5, .k2 = 2e4, .yield_penetration = 1e-3, .gap = 0.01}));
}

}  // namespace
}  // namespace poundsim
