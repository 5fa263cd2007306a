#pragma once
// Small models shared by the tests.

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "poundsim/model/dimensionless.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/model.hpp"
#include "poundsim/integrate/simulator.hpp"

namespace poundsim::testing {

/// Two single-storey frames: floor mass [kg], storey stiffness [N/m] and dashpot [N·s/m] of
/// each, joined by one gap element.
inline Model two_oscillators(double m1, double k1, double c1, double m2, double k2, double c2,
                             GapProperties gap) {
  return make_model({make_uniform_frame(1, m1, k1, c1, "1"), make_uniform_frame(1, m2, k2, c2, "2")},
                    gap);
}

/// The paper's dimensionless systems (captions of Figs. 2–4).
inline DimensionlessParameters fig2(char panel) {
  DimensionlessParameters p{.lambda2 = 200, .alpha = 0.25, .beta = 1, .gamma = 0.5, .xi = 0.05,
                            .delta = 0.25};
  if (panel == 'a') p.restitution = 1.0;
  if (panel == 'b') p.restitution = 0.75;
  if (panel == 'c') {
    p.restitution = 0.75;
    p.eta = 0.125;
    p.mu = 1;
    p.epsilon = 0.5;
  }
  return p;
}

inline DimensionlessParameters fig4(char panel) {
  DimensionlessParameters p{.lambda2 = 200, .alpha = 2, .beta = 1, .gamma = 1, .xi = 0.05,
                            .delta = 0, .restitution = 1.0};
  if (panel == 'b') {
    p.eta = 0.5;
    p.mu = 1;
    p.epsilon = 0.5;
  }
  return p;
}

/// The `[model]` table of an input file for the two frames of `storeys` floors (TOML array text,
/// e.g. "[1, 3]") with the dimensionless parameters `p`, one key per line as the docs write it.
inline std::string model_toml(const std::string& storeys, const DimensionlessParameters& p) {
  using io::toml_float;
  return fmt::format(
      "[model]\nstoreys = {}\n[model.dimensionless]\nlambda2 = {}\nalpha = {}\nbeta = {}\ngamma = {}\n"
      "xi = {}\ndelta = {}\neta = {}\nmu = {}\nepsilon = {}\nrestitution = {}\n",
      storeys, toml_float(p.lambda2), toml_float(p.alpha), toml_float(p.beta), toml_float(p.gamma),
      toml_float(p.xi), toml_float(p.delta), toml_float(p.eta), toml_float(p.mu), toml_float(p.epsilon),
      toml_float(p.restitution));
}

inline HarmonicExcitation harmonic(const Model& m, double amplitude_g, double ratio) {
  return {amplitude_g * 9.81, ratio * fundamental_frequency(m.frames.front())};
}

/// Total momentum Σ m u̇ of all floors [N·s].
inline double momentum(const Simulator& sim) {
  double p = 0;
  for (int i = 0; i < sim.layout().size(); ++i) {
    const Frame& f = sim.model().frames[sim.layout().frame_of(i)];
    p += f.mass[sim.layout().floor_of(i)] * sim.state().v(i);
  }
  return p;
}

}  // namespace poundsim::testing
