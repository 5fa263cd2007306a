#include "poundsim/analysis/verification.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "poundsim/model/dimensionless.hpp"
#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/integrate/exact_phase.hpp"
#include "poundsim/units.hpp"

namespace poundsim {

namespace {

struct Trace {
  std::vector<Eigen::VectorXd> samples;
  std::vector<Event> events;
  Eigen::VectorXd peaks;
  double residual = 0.0;
  double run_time = 0.0;
};

Trace run(const VerificationCase& c, const TimeHistoryOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Simulator sim(c.model, c.excitation, options);
  Trace trace;
  sim.set_event_handler([&](const Event& e) { trace.events.push_back(e); });
  const auto n = static_cast<long>(std::llround(c.duration / c.sample_dt));
  for (long k = 1; k <= n; ++k) {
    sim.advance_to(static_cast<double>(k) * c.sample_dt);
    trace.samples.push_back(sim.state().u);
  }
  trace.peaks.resize(sim.layout().size());
  for (int i = 0; i < sim.layout().size(); ++i) {
    trace.peaks(i) = sim.statistics().floors[static_cast<std::size_t>(i)].displacement.value;
  }
  trace.residual = sim.energy_meter().max_relative_residual();
  trace.run_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return trace;
}

ComparisonRow compare(const Trace& t, const Trace& reference, const std::string& integrator,
                      double dt, double tolerance) {
  ComparisonRow row{integrator, dt, tolerance};
  double scale = 0, error = 0;
  for (std::size_t k = 0; k < reference.samples.size(); ++k) {
    scale = std::max(scale, reference.samples[k].cwiseAbs().maxCoeff());
    error = std::max(error, (t.samples[k] - reference.samples[k]).cwiseAbs().maxCoeff());
  }
  row.history_error = error / scale;
  row.peak_error = (t.peaks - reference.peaks).cwiseAbs().maxCoeff() / reference.peaks.maxCoeff();
  bool same = t.events.size() == reference.events.size();
  double worst = 0;
  for (std::size_t k = 0; same && k < t.events.size(); ++k) {
    same = t.events[k].gap == reference.events[k].gap && t.events[k].kind == reference.events[k].kind;
    worst = std::max(worst, std::abs(t.events[k].time - reference.events[k].time));
  }
  row.event_time_error = same ? worst : std::numeric_limits<double>::quiet_NaN();
  row.events = static_cast<long>(t.events.size());
  row.energy_residual = t.residual;
  row.run_time = t.run_time;
  return row;
}

TimeHistoryOptions options_for(Integrator integrator, double dt, double tolerance) {
  TimeHistoryOptions o{.dt = dt, .event_tolerance = tolerance, .integrator = integrator};
  o.lock_time = std::max(o.lock_time, 10 * tolerance);
  return o;
}

/// The exact run every row of a study is compared with.
Trace exact_reference(const VerificationCase& c, double reference_dt, double tolerance) {
  return run(c, options_for(Integrator::exact, reference_dt, tolerance));
}

std::vector<ComparisonRow> convergence_rows(const VerificationCase& c, const Trace& reference,
                                            double reference_dt, Integrator integrator,
                                            const std::vector<double>& dts, double tolerance) {
  std::vector<ComparisonRow> rows{compare(reference, reference, "exact", reference_dt, 0.0)};
  for (const double dt : dts) {
    const Trace t = run(c, options_for(integrator, dt, tolerance));
    ComparisonRow row = compare(t, reference, std::string(to_string(integrator)), dt, tolerance);
    if (rows.size() > 1 && rows.back().history_error > 0 && row.history_error > 0) {
      row.order = std::log2(rows.back().history_error / row.history_error) / std::log2(rows.back().dt / dt);
    }
    rows.push_back(row);
  }
  return rows;
}

std::vector<ComparisonRow> tolerance_rows(const VerificationCase& c, const Trace& reference,
                                          double dt, const std::vector<double>& tolerances) {
  std::vector<ComparisonRow> rows;
  for (const double tol : tolerances) {
    rows.push_back(compare(run(c, options_for(Integrator::newmark, dt, tol)), reference, "newmark", dt, tol));
  }
  return rows;
}

/// Event tolerance of the exact reference of the tolerance study.
constexpr double kReferenceTolerance = 1e-10;

}  // namespace

VerificationCase paper_case(const std::string& figure, double ratio) {
  DimensionlessParameters p;
  std::array<int, 2> storeys{1, 1};
  if (figure == "2c") {
    p = {.lambda2 = 200, .alpha = 0.25, .beta = 1, .gamma = 0.5, .xi = 0.05, .delta = 0.25,
         .eta = 0.125, .mu = 1, .epsilon = 0.5, .restitution = 0.75};
  } else if (figure == "3b") {
    p = {.lambda2 = 400, .alpha = 0.25, .beta = 1, .gamma = 0.5, .xi = 0.05, .delta = 0.5,
         .eta = 0.125, .mu = 2, .epsilon = 1, .restitution = 0.75};
    storeys = {3, 3};
  } else {
    throw std::invalid_argument("paper_case: figure must be \"2c\" or \"3b\"");
  }
  VerificationCase c;
  c.name = fmt::format("Fig. {} system, 0.2 g at ω̄/ω₁ = {}", figure, ratio);
  c.model = make_model(p, storeys);
  c.excitation =
      HarmonicExcitation{0.2 * standard_gravity, ratio * reference_frequency(c.model)};
  return c;
}

std::vector<ComparisonRow> convergence_study(const VerificationCase& c, Integrator integrator,
                                             const std::vector<double>& dts, double tolerance,
                                             double reference_dt) {
  return convergence_rows(c, exact_reference(c, reference_dt, tolerance), reference_dt, integrator,
                          dts, tolerance);
}

std::vector<ComparisonRow> tolerance_study(const VerificationCase& c, double dt,
                                           const std::vector<double>& tolerances,
                                           double reference_dt) {
  return tolerance_rows(c, exact_reference(c, reference_dt, kReferenceTolerance), dt, tolerances);
}

SteadyStateCheck steady_state_check() {
  // The Fig. 3 frame 1 (three storeys) with a dashpot in its top storey only (complex modes),
  // alone, under 0.2 g at 1.3 ω₁; Fourier coefficient over one period after the transient.
  using Complex = std::complex<double>;
  Frame f = make_uniform_frame(3, 1.0, 400.0, 0.0);
  f.damping = {0.0, 0.0, 8.0};
  const Model model = make_model({f}, GapProperties{});
  const double a = 0.2 * standard_gravity, omega = 1.3 * fundamental_frequency(f);
  const Eigen::VectorXcd u = harmonic_amplitudes(f, a, omega);
  Simulator sim(model, HarmonicExcitation{a, omega},
                TimeHistoryOptions{.dt = 1e-2, .integrator = Integrator::exact});
  const DofLayout layout(model);
  const ExactPhase phase(LinearPhase(model, layout, {}, 1e-2));
  const double slowest = -phase.eigenvalues().real().maxCoeff();
  const double period = 2 * std::numbers::pi / omega;
  const double start = std::ceil(30.0 / slowest / period);
  sim.advance_to(start * period);
  const int samples = 64;
  Eigen::VectorXcd coefficient = Eigen::VectorXcd::Zero(3);
  for (int j = 0; j < samples; ++j) {
    sim.advance_to((start + (j + 1.0) / samples) * period);
    const Complex basis = std::exp(Complex(0, -omega * sim.time()));
    for (int i = 0; i < 3; ++i) coefficient(i) += sim.state().u(i) * basis;
  }
  coefficient *= 2.0 * Complex(0, 1) / double(samples);
  SteadyStateCheck check{"three-storey frame, dashpot in the top storey only (complex modes), "
                         "0.2 g at 1.3 ω₁"};
  for (int i = 0; i < 3; ++i) {
    check.amplitude_error = std::max(check.amplitude_error,
                                     std::abs(std::abs(coefficient(i)) - std::abs(u(i))) / std::abs(u(i)));
    check.phase_error = std::max(check.phase_error, std::abs(std::arg(coefficient(i) / u(i))));
  }
  return check;
}

VerificationReport run_verification() {
  VerificationReport report;
  const std::vector<double> dts{4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4};
  const double reference_dt = 1e-3;
  // The convergence studies' tolerance (also their reference's) is the tolerance study's
  // reference tolerance, so one exact run of Fig. 2c serves both of its tables.
  const double tolerance = kReferenceTolerance;
  const VerificationCase fig2c = paper_case("2c", 0.8);
  const Trace fig2c_reference = exact_reference(fig2c, reference_dt, tolerance);
  report.tables.emplace_back(fig2c.name + ": Newmark against the exact integrator",
                             convergence_rows(fig2c, fig2c_reference, reference_dt,
                                              Integrator::newmark, dts, tolerance));
  const VerificationCase fig3b = paper_case("3b", 0.8);
  report.tables.emplace_back(
      fig3b.name + ": Newmark against the exact integrator",
      convergence_study(fig3b, Integrator::newmark, dts, tolerance, reference_dt));
  report.tables.emplace_back(fig2c.name + ": event tolerance of Newmark, dt = 5e-4 s",
                             tolerance_rows(fig2c, fig2c_reference, 5e-4, {1e-4, 1e-6, 1e-8, 1e-10}));
  report.steady_state = steady_state_check();
  return report;
}

namespace {
std::string number(double x, const char* format = "{:.2e}") {
  return std::isnan(x) ? std::string("—") : fmt::format(fmt::runtime(format), x);
}

/// The cells of one row, in the column order of both reports.
std::array<std::string, 10> cells(const ComparisonRow& r) {
  return {r.integrator,
          fmt::format("{:.2e}", r.dt),
          r.tolerance > 0 ? number(r.tolerance, "{:.0e}") : "—",
          number(r.history_error),
          r.order != 0 ? number(r.order, "{:.2f}") : "",
          number(r.peak_error),
          number(r.event_time_error),
          fmt::format("{}", r.events),
          fmt::format("{:.1e}", r.energy_residual),
          fmt::format("{:.3f}", r.run_time)};
}
}  // namespace

std::string to_text(const VerificationReport& report) {
  std::string out;
  for (const auto& [title, rows] : report.tables) {
    out += title + "\n";
    out += fmt::format("  {:<8} {:>9} {:>9} {:>12} {:>6} {:>11} {:>11} {:>7} {:>10} {:>9}\n", "method",
                       "dt [s]", "tol [s]", "history err", "order", "peak err", "event t err",
                       "events", "energy res", "time [s]");
    for (const ComparisonRow& r : rows) {
      const auto c = cells(r);
      out += fmt::format("  {:<8} {:>9} {:>9} {:>12} {:>6} {:>11} {:>11} {:>7} {:>10} {:>9}\n", c[0], c[1],
                         c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9]);
    }
    out += "\n";
  }
  out += fmt::format("Exact integrator against the closed-form steady state ({}):\n"
                     "  amplitude error {:.2e} (relative), phase error {:.2e} rad\n",
                     report.steady_state.description, report.steady_state.amplitude_error,
                     report.steady_state.phase_error);
  return out;
}

std::string to_markdown(const VerificationReport& report) {
  std::string out =
      "# Verification\n\n"
      "This page is written by `poundsim verify --write docs/verification.md` from a real run; the\n"
      "numbers below are measured, not typed. Regenerate it after any change to the integrators.\n\n"
      "The **exact integrator** (`integrator = \"exact\"`, [numerics.md](numerics.md)) solves each\n"
      "phase in closed form and finds events as proven first roots of exact guard functions, to\n"
      "near machine precision. It is the reference here. Each row compares one run with it:\n\n"
      "- *history err*: the largest difference of any floor displacement, sampled every 0.01 s over\n"
      "  20 s, relative to the largest displacement;\n"
      "- *order*: log₂ of the ratio of history errors at dt and dt/2 — Newmark's is 2;\n"
      "- *peak err*: the largest difference of the peak |u| of any floor, relative;\n"
      "- *event t err*: the largest difference of an event time [s], when both runs see the same\n"
      "  sequence of events (— otherwise);\n"
      "- *energy res*: the largest relative residual of the energy balance over the run;\n"
      "- *time*: wall-clock time of the run on the machine that wrote this page.\n\n";
  for (const auto& [title, rows] : report.tables) {
    out += "## " + title + "\n\n";
    out += "| integrator | dt [s] | event tolerance [s] | history err | order | peak err | event t err [s] | events | energy res | time [s] |\n";
    out += "|---|---|---|---|---|---|---|---|---|---|\n";
    for (const ComparisonRow& r : rows) {
      out += fmt::format("| {} |\n", fmt::join(cells(r), " | "));
    }
    out += "\n";
  }
  out += "## Exact integrator against a closed form\n\n";
  out += fmt::format(
      "Steady state of a {}: the Fourier coefficient of each floor's displacement over one period,\n"
      "after the transient has decayed below 1e-13, against U from (K − ω̄²M + iω̄C) U = −M 1 A.\n\n"
      "| largest relative amplitude error | largest phase error [rad] |\n|---|---|\n| {:.2e} | {:.2e} |\n\n",
      report.steady_state.description, report.steady_state.amplitude_error,
      report.steady_state.phase_error);
  out +=
      "## Reading the tables\n\n"
      "Newmark's histories converge to the exact ones at second order through contacts, impacts and\n"
      "separations, because every event is located on Newmark's own trajectory. Its event times\n"
      "converge at second order with dt as long as the event tolerance is smaller than Newmark's\n"
      "error; the tolerance table shows the floor that a loose tolerance sets. Both integrators close\n"
      "the energy balance to round-off: Newmark's average-acceleration scheme satisfies the\n"
      "trapezoidal balance exactly, and the exact integrator integrates the powers on its exact\n"
      "trajectory.\n";
  return out;
}

}  // namespace poundsim
