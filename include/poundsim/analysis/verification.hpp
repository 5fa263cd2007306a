#pragma once
/// @file
/// The verification suite: Newmark against the exact integrator, and the exact integrator
/// against closed forms, measured on the paper's systems. `poundsim verify` prints it and writes
/// docs/verification.md from a real run.

#include <string>
#include <vector>

#include "poundsim/model/excitation.hpp"
#include "poundsim/model/model.hpp"
#include "poundsim/integrate/simulator.hpp"

namespace poundsim {

/// A model, an excitation and a duration to compare integrators on.
struct VerificationCase {
  std::string name;
  Model model;
  Excitation excitation;
  double duration = 20.0;   ///< [s]
  double sample_dt = 0.01;  ///< Histories are compared at multiples of this [s].
};

/// The paper's Fig. 2c (two single-storey frames) or Fig. 3b (two three-storey frames) system
/// under 0.2 g at ω̄/ω₁ = `ratio`.
VerificationCase paper_case(const std::string& figure, double ratio);

/// One run compared with the exact reference.
struct ComparisonRow {
  std::string integrator;       ///< "newmark" or "exact"
  double dt = 0.0;              ///< [s]
  double tolerance = 0.0;       ///< event tolerance [s] (Newmark)
  double history_error = 0.0;   ///< max |u − u_exact| over samples and floors, / max |u_exact|
  double peak_error = 0.0;      ///< max over floors of |peak |u| − exact peak|, / max exact peak
  double event_time_error = 0.0;  ///< max |t − t_exact| over events [s]; NaN if the sequences differ
  long events = 0;
  double energy_residual = 0.0; ///< max relative residual of the balance
  double run_time = 0.0;        ///< wall-clock [s]
  double order = 0.0;           ///< log2(history error at 2 dt / at dt); 0 for the first row
};

/// Runs `integrator` with each dt (and `tolerance`), and the exact reference with `reference_dt`
/// (its sampling interval), and compares. The first row is the reference itself.
std::vector<ComparisonRow> convergence_study(const VerificationCase& c, Integrator integrator,
                                             const std::vector<double>& dts, double tolerance,
                                             double reference_dt);

/// Newmark at one dt with each event tolerance against the exact reference.
std::vector<ComparisonRow> tolerance_study(const VerificationCase& c, double dt,
                                           const std::vector<double>& tolerances,
                                           double reference_dt);

/// Exact integrator against the closed-form steady state of a frame without contact.
struct SteadyStateCheck {
  std::string description;
  double amplitude_error = 0.0;  ///< max relative error of |U| over floors
  double phase_error = 0.0;      ///< max |arg(U_sim/U)| [rad]
};
SteadyStateCheck steady_state_check();

struct VerificationReport {
  std::vector<std::pair<std::string, std::vector<ComparisonRow>>> tables;
  SteadyStateCheck steady_state;
};

/// The whole suite as `poundsim verify` runs it (a few seconds).
VerificationReport run_verification();

/// Markdown for docs/verification.md (tables and how they were obtained).
std::string to_markdown(const VerificationReport& report);

/// Plain-text tables for a terminal.
std::string to_text(const VerificationReport& report);

}  // namespace poundsim
