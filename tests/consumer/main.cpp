// Uses the installed library as another project would: reads a model from TOML text (io), runs
// it with the exact integrator (core) and checks the answer against the closed form.
//
// A single-storey frame, m = 2 kg, k = 800 N/m (ω = 20 rad/s), undamped, released from
// u₀ = 0.01 m: u(t) = u₀ cos ωt. Exits 0 when the run matches it to 1e-9 m.
#include <cmath>
#include <cstdio>
#include <numbers>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/input.hpp"

int main() {
  const char* text = R"(
title = "consumer"
[[frames]]
storeys = 1
mass = 2.0
stiffness = 800.0
damping = 0.0
[initial]
displacement = [[0.01]]
[excitation]
kind = "none"
[analysis]
kind = "time_history"
integrator = "exact"
duration = 1.0
dt = 0.01
)";
  const poundsim::io::RunInput input = poundsim::io::read_input_string(text, "consumer.toml", ".");
  poundsim::Simulator sim(input.model, input.excitation,
                          poundsim::TimeHistoryOptions{.dt = 0.01,
                                                       .integrator = poundsim::Integrator::exact},
                          input.initial);
  const double t = 0.25 * std::numbers::pi;  // a quarter of a turn past two periods
  sim.advance_to(t);
  const double u = sim.state().u[0];
  const double expected = 0.01 * std::cos(20.0 * t);
  std::printf("u(%.6f) = %.12e, closed form %.12e\n", t, u, expected);
  return std::abs(u - expected) < 1e-9 ? 0 : 1;
}
