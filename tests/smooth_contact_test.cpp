// The smooth contact laws (Hertz, Hertzdamp, Jankowski: model/laws/hertz.hpp, hertzdamp.hpp,
// jankowski.hpp) and Newmark's Newton iterations on them, against closed forms for two free
// masses: Hertz's largest overlap and contact duration, restitution 1 with Hertz, the energy
// balance closed, second-order convergence, quadratic Newton convergence.
#include "poundsim/model/laws/hertz.hpp"
#include "poundsim/model/laws/hertzdamp.hpp"
#include "poundsim/model/laws/jankowski.hpp"
#include "poundsim/model/laws/kelvin_voigt.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <fstream>
#include <numbers>
#include <sstream>
#include <utility>
#include <string>
#include <vector>

#include <optional>

#include <gtest/gtest.h>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/model.hpp"
#include "collision.hpp"

namespace poundsim {
namespace {

using testing::Collision;
using testing::collide;
using testing::kClosing;
using testing::kGap;
using testing::kLeftMass;
using testing::kReduced;
using testing::kRightMass;

/// Goldsmith's closed forms for two elastic spheres: s_max = (5 m̄ v₀²/(4 k_h))^{2/5} and
/// t_c = 2 I s_max / v₀, I = ∫₀¹ dx/√(1 − x^{5/2}) = √π Γ(7/5)/Γ(9/10).
double hertz_max_overlap(double k) { return std::pow(5 * kReduced * kClosing * kClosing / (4 * k), 0.4); }
double hertz_duration(double k) {
  const double integral = std::sqrt(std::numbers::pi) * std::tgamma(1.4) / std::tgamma(0.9);
  return 2 * integral * hertz_max_overlap(k) / kClosing;
}

TEST(HertzContact, TwoFreeMassesMatchGoldsmithsOverlapAndDuration) {
  const double k = 1e9;
  // Newmark's trapezoidal rule is not exact for the work of a nonlinear force: the balance's
  // residual is O((ω h)²) (the next test), 1e-8 below h = 5e-8 s, a contact of 16 000 steps.
  const Collision c = collide(Hertz{.parameters = {.stiffness = k, .gap = kGap}}, 5e-8);
  ASSERT_GT(c.separation, c.contact);
  EXPECT_NEAR(c.contact, kGap / kClosing, 1e-9);
  EXPECT_NEAR(c.max_shortening / hertz_max_overlap(k), 1.0, 1e-5);
  EXPECT_NEAR(c.max_force / (k * std::pow(hertz_max_overlap(k), 1.5)), 1.0, 2e-5);
  EXPECT_NEAR((c.separation - c.contact) / hertz_duration(k), 1.0, 1e-5);
  // The literature's rounded constant, 3.2145 (m̄²/(k_h² v₀))^{1/5}, is 0.11 % below the exact one.
  EXPECT_NEAR((c.separation - c.contact) / (3.2145 * std::pow(kReduced * kReduced / (k * k * kClosing), 0.2)), 1.0,
              2e-3);
  EXPECT_NEAR(-c.parting / c.closing, 1.0, 1e-6);  // elastic: e = 1
  EXPECT_EQ(c.completed_contacts, 1);
  EXPECT_NEAR(c.contact_time / hertz_duration(k), 1.0, 1e-5);
  EXPECT_NEAR(c.mean_restitution, 1.0, 1e-6);
  EXPECT_EQ(c.element_dissipation, 0.0);
  EXPECT_LT(c.relative_residual, 1e-8);
  EXPECT_LT(c.mean_newton_iterations, 4.0);
}

TEST(HertzContact, NewmarkConvergesAtSecondOrder) {
  const double k = 1e9, exact = hertz_duration(k);
  const Hertz law{.parameters = {.stiffness = k, .gap = kGap}};
  const Collision coarse = collide(law, 2e-5), fine = collide(law, 1e-5);
  const auto error = [&](const Collision& c) { return std::abs((c.separation - c.contact) / exact - 1.0); };
  EXPECT_NEAR(std::log2(error(coarse) / error(fine)), 2.0, 0.1) << error(coarse) << " " << error(fine);
  EXPECT_NEAR(std::log2(coarse.relative_residual / fine.relative_residual), 2.0, 0.1)
      << coarse.relative_residual << " " << fine.relative_residual;
}


/// The restitution each damped law achieves for two free masses against the e it is set for.
struct AchievedRestitution {
  double e, kelvin_voigt, lankarani_nikravesh, ye_li_zhu, jankowski;
};
std::vector<AchievedRestitution> achieved_restitution() {
  std::vector<AchievedRestitution> rows;
  const auto achieved = [](const auto& law) {
    const Collision c = collide(law, 2e-6, Integrator::newmark, 0.02);
    return -c.parting / c.closing;
  };
  for (int i = 2; i <= 9; ++i) {
    const double e = 0.1 * i;
    rows.push_back(
        {e, achieved(KelvinVoigt{.parameters = {.stiffness = 1e6, .gap = kGap, .restitution = e}}),
         achieved(Hertzdamp{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = e}}),
         achieved(Hertzdamp{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = e,
                                           .damping_model = HertzdampDamping::ye_li_zhu}}),
         achieved(Jankowski{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = e}})});
  }
  return rows;
}

/// The rows of the table under "### The restitution each law achieves" in docs/model.md.
std::vector<std::vector<double>> documented_restitution() {
  std::ifstream in(std::filesystem::path(POUNDSIM_SOURCE_DIR) / "docs" / "model.md");
  std::string line;
  while (std::getline(in, line) && line != "### The restitution each law achieves") {
  }
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.rfind("| 0.", 0) != 0) {
      if (!rows.empty()) break;
      continue;
    }
    std::vector<double> row;
    std::istringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, '|')) {
      if (cell.find_first_not_of(' ') != std::string::npos) row.push_back(std::stod(cell));
    }
    rows.push_back(row);
  }
  return rows;
}

TEST(SmoothContactRestitution, DocumentedTableIsWhatTheLawsAchieve) {
  const std::vector<AchievedRestitution> achieved = achieved_restitution();
  const std::vector<std::vector<double>> documented = documented_restitution();
  ASSERT_EQ(documented.size(), achieved.size());
  for (std::size_t i = 0; i < achieved.size(); ++i) {
    const AchievedRestitution& r = achieved[i];
    ASSERT_EQ(documented[i].size(), 5U);
    const std::array<double, 5> computed{r.e, r.kelvin_voigt, r.lankarani_nikravesh, r.ye_li_zhu, r.jankowski};
    for (std::size_t j = 0; j < computed.size(); ++j) {
      EXPECT_NEAR(documented[i][j], computed[j], 5.01e-4) << "row e = " << r.e << ", column " << j;
    }
    // What each formula is designed for.
    EXPECT_NEAR(r.kelvin_voigt, r.e, 1e-4);
    EXPECT_NEAR(r.jankowski, r.e, 0.01);
    EXPECT_NEAR(r.ye_li_zhu, r.e, 0.05);
    EXPECT_GT(r.lankarani_nikravesh, r.e);  // it assumes little dissipation
  }
  EXPECT_NEAR(achieved.back().lankarani_nikravesh, 0.9, 0.015);
}

TEST(SmoothContactEnergy, DampedLawsCloseTheBalance) {
  // Dissipation as F − F_elastic: the balance closes to the integration error, 1e-8 at dt = 5e-8 s.
  for (const auto& [name, c] :
       {std::pair{"hertzdamp", collide(Hertzdamp{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = 0.5}}, 5e-8)},
        std::pair{"ye_li_zhu", collide(Hertzdamp{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = 0.2,
                                                                  .damping_model = HertzdampDamping::ye_li_zhu}},
                                       5e-8)},
        std::pair{"jankowski", collide(Jankowski{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = 0.5}}, 5e-8)}}) {
    ASSERT_GT(c.separation, c.contact) << name;
    EXPECT_LT(c.relative_residual, 1e-8) << name;
    // The kinetic energy the contact took, ½ m̄ v₀² (1 − e_achieved²), is what the law dissipated.
    const double e = c.mean_restitution;
    EXPECT_NEAR(c.element_dissipation / (0.5 * kReduced * kClosing * kClosing * (1 - e * e)), 1.0, 1e-6) << name;
    EXPECT_NEAR(c.element_dissipation, c.gap_damping, 1e-12 * c.gap_damping) << name;
    EXPECT_LT(c.mean_newton_iterations, 4.0) << name;
  }
}


/// Records the force of element 0 at each Newton iterate.
class RecordingForces final : public SmoothForces {
 public:
  RecordingForces(const PoundingSystem& system, const ContactState& contact) : system_(system), contact_(contact) {}
  void evaluate(const KinematicState& x, std::span<ForceTangent> by_element) override {
    system_.smooth_forces(x, contact_, by_element);
    forces.push_back(by_element[0].force);
  }
  std::vector<double> forces;

 private:
  const PoundingSystem& system_;
  const ContactState& contact_;
};

/// Two free masses 0.2 mm into a Hertz contact, closing at 1.5 m/s, in the phase of a Newmark
/// step of 1e-4 s (an eighth of the contact): the start of one Newton step.
class NewtonSteps : public ::testing::Test {
 protected:
  void SetUp() override {
    x.resize(2);
    x.u << kGap + 2e-4, 0.0;
    x.v << 1.0, -0.5;
    contact = system.initial_contact(x);
    ASSERT_EQ(contact.config[0], static_cast<LinkMode>(SmoothContact::Mode::contact));
    system.refresh_flags(contact);
    step_phase.emplace(model, system.layout(), contact.config, 1e-4);
    ASSERT_TRUE(step_phase->has_smooth_links());
  }
  const Model model = make_model({make_uniform_frame(1, kLeftMass, 1e-6, 0.0), make_uniform_frame(1, kRightMass, 1e-6, 0.0)},
                                 GapLaw(Hertz{.parameters = {.stiffness = 1e9, .gap = kGap}}));
  PoundingSystem system{model, NoExcitation{}, EventRules{}};
  KinematicState x;
  ContactState contact;
  std::optional<LinearPhase> step_phase;
  NewmarkIntegrator newmark{2};
};

TEST_F(NewtonSteps, ConvergeQuadratically) {
  // From ü⁺ = ü — far from the answer.
  LinearPhase& phase = *step_phase;
  system.equilibrate(phase, x, contact);
  RecordingForces forces(system, contact);
  std::vector<ForceTangent> by_element(1);
  KinematicState end;
  end.resize(2);
  const NewtonOutcome outcome =
      newmark.step_newton(phase, x, 1e-4, 0.0, forces, by_element, NewtonOptions{.tolerance = 1e-14}, end);
  ASSERT_TRUE(outcome.converged);
  ASSERT_GE(forces.forces.size(), 4U);
  system.smooth_forces(end, contact, by_element);
  const double final_force = by_element[0].force;
  // e_{k+1} ≤ C e_k²: the ratio e_{k+1}/e_k² stays bounded while e_k falls by orders of magnitude.
  std::vector<double> error;
  for (const double f : forces.forces) error.push_back(std::abs(f - final_force) / final_force);
  for (std::size_t k = 0; k + 1 < error.size() && error[k + 1] > 1e-13; ++k) {
    EXPECT_LT(error[k + 1], 10 * error[k] * error[k] + 1e-13) << "iteration " << k + 1;
  }
  // (Seen: 3.0e-2, 8.1e-6, 6.0e-13, 0.)
  EXPECT_LE(outcome.iterations, 7);
  // The converged step satisfies the equation of motion: ü⁺ = M⁻¹(∓F).
  EXPECT_NEAR(end.a(0) * kLeftMass, -final_force, 1e-9 * final_force);
  EXPECT_NEAR(end.a(1) * kRightMass, final_force, 1e-9 * final_force);
}

TEST(NewtonStep, FailureNamesTheTimeAndTheElement) {
  const Model model = make_model({make_uniform_frame(1, kLeftMass, 1e-6, 0.0), make_uniform_frame(1, kRightMass, 1e-6, 0.0)},
                                 GapLaw(Hertz{.parameters = {.stiffness = 1e9, .gap = kGap}}));
  InitialConditions ic;
  ic.velocity = {{1.0}, {-0.5}};
  TimeHistoryOptions options{.dt = 1e-4};
  options.newton_max_iterations = 1;
  Simulator sim(model, NoExcitation{}, options, ic);
  const SimulationStatus status = sim.run_to(0.02);
  EXPECT_EQ(status.reason, StopReason::no_convergence);
  EXPECT_NE(status.message.find("did not converge within 1 iterations in the step from t = 0.0066"), std::string::npos)
      << status.message;
  EXPECT_NE(status.message.find("the force of the Hertz contact between frames 1 and 2 at floor 1 changed most"), std::string::npos) << status.message;
}

/// Gives element 0 a NaN force at every iterate, as a law evaluated outside its range does.
class NotFiniteForces final : public SmoothForces {
 public:
  void evaluate(const KinematicState& /*x*/, std::span<ForceTangent> by_element) override {
    by_element[0] = ForceTangent{.force = std::numeric_limits<double>::quiet_NaN()};
  }
};

TEST_F(NewtonSteps, ANotFiniteForceIsBlamedOnItsElement) {
  // Every comparison with NaN is false: the element whose force "changed most" was never found
  // and the failure message read the link before the first.
  LinearPhase& phase = *step_phase;
  NotFiniteForces forces;
  std::vector<ForceTangent> by_element(1);
  KinematicState end;
  end.resize(2);
  const NewtonOutcome outcome =
      newmark.step_newton(phase, x, 1e-4, 0.0, forces, by_element, NewtonOptions{.max_iterations = 3}, end);
  EXPECT_FALSE(outcome.converged);
  EXPECT_EQ(outcome.worst_element, 0);
  EXPECT_TRUE(outcome.worst_not_finite);
}

TEST(SmoothContactLaws, TheExactIntegratorRefusesThemNamingTheElement) {
  const Model model = make_model({make_uniform_frame(1, kLeftMass, 1e2, 0.0), make_uniform_frame(1, kRightMass, 1e2, 0.0)},
                                 GapLaw(Jankowski{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = 0.5}}));
  try {
    Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = 1e-3, .integrator = Integrator::exact});
    ADD_FAILURE() << "the exact integrator took a smooth law";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("Jankowski's contact between frames 1 and 2 at floor 1 is not piecewise linear: use integrator = \"newmark\""),
              std::string::npos)
        << e.what();
  }
}

TEST(SmoothContactLaws, AreChosenByNameWithTheirParametersChecked) {
  const std::string text =
      "[[frames]]\nstoreys = 1\nmass = 2.0\nstiffness = 100.0\ndamping = 0.0\n"
      "[[frames]]\nstoreys = 1\nmass = 3.0\nstiffness = 100.0\ndamping = 0.0\n"
      "[gap_elements]\nlaw = \"hertzdamp\"\nstiffness = 1e9\ngap = 0.01\nrestitution = 0.4\n"
      "damping_model = \"ye_li_zhu\"\n"
      "[analysis]\nkind = \"time_history\"\nduration = 0.1\ndt = 0.001\n[excitation]\nkind = \"none\"\n";
  const io::RunInput in = io::read_input_string(text, "smooth.toml", ".");
  const auto& law = std::get<Hertzdamp>(in.model.gaps[0].law);
  EXPECT_EQ(law.parameters, (HertzdampForce::Parameters{.stiffness = 1e9, .gap = 0.01, .exponent = 1.5,
                                                         .restitution = 0.4,
                                                         .damping_model = HertzdampDamping::ye_li_zhu}));
  EXPECT_DOUBLE_EQ(HertzdampForce::damping_factor(law.parameters), 8 * 0.6 / (5 * 0.4));
  const auto error_of = [&](const std::string& from, const std::string& to) {
    std::string bad = text;
    bad.replace(bad.find(from), from.size(), to);
    try {
      (void)io::read_input_string(bad, "smooth.toml", ".");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("restitution = 0.4", "restitution = 0.0").find("gap_elements.restitution"), std::string::npos);
  EXPECT_NE(error_of("restitution = 0.4", "restitution = 0.0").find("must be > 0 with damping_model = \"ye_li_zhu\""),
            std::string::npos);
  EXPECT_NE(error_of("\"ye_li_zhu\"", "\"ye\"").find("gap_elements.damping_model: \"ye\" is not one of"),
            std::string::npos);
  // Jankowski's ξ needs e > 0, and it has no damping model.
  const std::string jankowski = error_of("law = \"hertzdamp\"", "law = \"jankowski\"");
  EXPECT_NE(jankowski.find("gap_elements.damping_model"), std::string::npos) << jankowski;
  EXPECT_NE(jankowski.find("unknown key"), std::string::npos) << jankowski;
  const std::string zero = error_of("law = \"hertzdamp\"\nstiffness = 1e9\ngap = 0.01\nrestitution = 0.4\n"
                                    "damping_model = \"ye_li_zhu\"\n",
                                    "law = \"jankowski\"\nstiffness = 1e9\ngap = 0.01\nrestitution = 0.0\n");
  EXPECT_NE(zero.find("gap_elements.restitution: must be in (0, 1] (got 0)"), std::string::npos) << zero;
}

TEST(SmoothContactLaws, AHertzdampContactPresentFromTheStartUsesTheLeastClosingSpeed) {
  // No contact event gave it v₀: the force must still be finite, F = k_h sⁿ (1 + ξ̄ ṡ/v_min).
  const Model model = make_model({make_uniform_frame(1, kLeftMass, 1e2, 0.0), make_uniform_frame(1, kRightMass, 1e2, 0.0)},
                                 GapLaw(Hertzdamp{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = 0.5}}));
  InitialConditions ic;
  ic.displacement = {{kGap + 1e-4}, {0.0}};
  ic.velocity = {{0.01}, {0.0}};
  Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = 2e-6}, ic);
  const double xi = 0.75 * (1 - 0.25);
  EXPECT_NEAR(sim.gap_force(0), 1e9 * 1e-6 * (1 + xi * 0.01 / 1e-3), 1e-6);
  sim.advance_to(0.01);
  EXPECT_TRUE(std::isfinite(sim.gap_force(0)));
  EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-7);
}

TEST(SmoothContactLaws, JankowskisDashpotIsBoundToTheFloorsReducedMass) {
  const Model model = make_model({make_uniform_frame(1, kLeftMass, 1e2, 0.0), make_uniform_frame(1, kRightMass, 1e2, 0.0)},
                                 GapLaw(Jankowski{.parameters = {.stiffness = 1e9, .gap = kGap, .restitution = 0.5}}));
  const std::vector<Link> links = make_links(model, DofLayout(model));
  const auto& law = std::get<Jankowski>(links.back().law);
  EXPECT_DOUBLE_EQ(law.reduced_mass, kReduced);
  // At s = 1e-4 m closing at 1 m/s: F = β s^{3/2} + 2ξ√(β√s m̄) ṡ, and its tangent.
  const LinkKinematics k{.ua = kGap + 1e-4, .ub = 0.0, .va = 1.0, .vb = 0.0};
  const ForceTangent f = law.force_tangent(k, static_cast<LinkMode>(SmoothContact::Mode::contact), {});
  const double xi = JankowskiForce::damping_ratio(0.5);
  const double c = 2 * xi * std::sqrt(1e9 * std::sqrt(1e-4) * kReduced);
  EXPECT_NEAR(f.force, 1e9 * 1e-6 + c, 1e-9 * f.force);
  EXPECT_NEAR(f.damping, c, 1e-9 * c);
  EXPECT_NEAR(f.stiffness, 1.5e9 * 1e-2 + 0.25 * c / 1e-4, 1e-9 * f.stiffness);
  // On restitution the dashpot is off: F = β s^{3/2}.
  const LinkKinematics back{.ua = kGap + 1e-4, .ub = 0.0, .va = -1.0, .vb = 0.0};
  EXPECT_NEAR(law.force(back, static_cast<LinkMode>(SmoothContact::Mode::contact), {}), 1e9 * 1e-6, 1e-9);
  // ξ of Jankowski (2005) at e = 0.5: 9√5·0.75/(2·0.5·(0.5(9π − 16) + 16)).
  EXPECT_NEAR(xi, 9 * std::sqrt(5.0) * 0.75 / (0.5 * (9 * std::numbers::pi - 16) + 16), 1e-15);
}

}  // namespace
}  // namespace poundsim
