#pragma once
// Two free masses that collide once through a contact law: the closed-form cases of the contact
// laws' tests (kelvin_voigt_test.cpp, smooth_contact_test.cpp).

#include <gtest/gtest.h>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim::testing {

inline constexpr double kLeftMass = 2.0, kRightMass = 3.0, kReduced = 1.2;  // m̄ = 2·3/5 [kg]
inline constexpr double kClosing = 1.5;                                     // v₀ [m/s]
inline constexpr double kGap = 0.01;                                        // δ [m]

/// What one collision did: its events' times and rates, its peaks and the run's figures.
struct Collision {
  double contact = -1, separation = -1, closing = 0, parting = 0;
  double max_shortening = 0, max_force = 0;
  double relative_residual = 0;
  double mean_newton_iterations = 0;
  // What the monitor and the energy meter report of the element.
  double contact_time = 0, longest_contact = 0, mean_restitution = 0;
  int completed_contacts = 0;
  double gap_damping = 0, element_dissipation = -1;
  Eigen::VectorXd velocity;  ///< the floors' velocities at the end [m/s]
  double max_approach = 0;   ///< of the element's facing points [m]
};

/// The first gap element of `model` released from `ic`, run for `duration` [s].
inline Collision collide(const Model& model, const InitialConditions& ic, double dt, Integrator integrator,
                         double duration) {
  Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = dt, .integrator = integrator}, ic);
  Collision c;
  sim.set_event_handler([&](const Event& e) {
    if (e.kind == EventKind::contact) {
      c.contact = e.time;
      c.closing = e.rate_before;
    } else if (e.kind == EventKind::separation) {
      c.separation = e.time;
      c.parting = e.rate_after;
    }
  });
  sim.advance_to(duration);
  const ResponseStatistics& stats = sim.statistics();
  c.max_shortening = stats.gaps[0].shortening.value;
  c.max_force = stats.gaps[0].force.value;
  c.relative_residual = sim.energy_meter().max_relative_residual();
  const GapResponse& gap = stats.gaps[0];
  c.contact_time = gap.contact_time;
  c.longest_contact = gap.longest_contact.value;
  c.mean_restitution = gap.mean_restitution();
  c.completed_contacts = gap.completed_contacts;
  c.gap_damping = sim.energy().gap_damping;
  if (const auto per_element = sim.energy_meter().element_dissipation()) c.element_dissipation = (*per_element)[0];
  if (stats.newton_steps > 0) {
    c.mean_newton_iterations = static_cast<double>(stats.newton_iterations) / static_cast<double>(stats.newton_steps);
  }
  c.velocity = sim.state().v;
  c.max_approach = stats.neighbours[0].max_approach;
  return c;
}

/// Frames of 2 and 3 kg on storeys of 1e-6 N/m (free masses to far below the contacts' 1e5 and
/// more), at 1 and −0.5 m/s across the gap of `law`, run for `duration` [s].
template <class L>
Collision collide(const L& law, double dt, Integrator integrator = Integrator::newmark, double duration = 0.012) {
  const Model model = make_model(
      {make_uniform_frame(1, kLeftMass, 1e-6, 0.0), make_uniform_frame(1, kRightMass, 1e-6, 0.0)}, GapLaw(law));
  InitialConditions ic;
  ic.velocity = {{1.0}, {-0.5}};
  return collide(model, ic, dt, integrator, duration);
}

}  // namespace poundsim::testing
