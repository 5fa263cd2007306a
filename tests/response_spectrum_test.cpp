// Response spectra against closed forms and the exact integrator; design spectra; suite scaling.

#include "poundsim/analysis/response_spectrum.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/ground_motion.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

constexpr double kPi = std::numbers::pi;
const std::filesystem::path kRecords = std::filesystem::path(POUNDSIM_SOURCE_DIR) / "data" / "ground_motions";

/// Response from rest of ü + 2ζωu̇ + ω²u = −r t (a ramp of slope r from t = 0), and its rate.
struct Ramp {
  double omega, zeta;
  [[nodiscard]] double operator()(double t) const {
    if (t <= 0) return 0.0;
    const double wd = omega * std::sqrt(1 - zeta * zeta);
    const double alpha = -1.0 / (omega * omega), beta = 2 * zeta / (omega * omega * omega);
    const double e = -beta, f = (zeta * omega * e - alpha) / wd;
    return alpha * t + beta + std::exp(-zeta * omega * t) * (e * std::cos(wd * t) + f * std::sin(wd * t));
  }
};

/// max |f| over [0, end] on a grid of n points.
template <class F>
double dense_peak(const F& f, double end, int n) {
  double peak = 0.0;
  for (int i = 0; i <= n; ++i) peak = std::max(peak, std::abs(f(end * i / n)));
  return peak;
}

// A triangular pulse is exactly linear between its three samples, and zero after: its response is
// three ramps, u = r (R(t) − 2R(t − t₁) + R(t − 2t₁)), free vibration after 2t₁. The spectrum
// (with its free period after the record) must find the same peak; the cubic between sub-steps
// errs by at most (ωh)⁴/384.
TEST(ResponseSpectrum, ATriangularPulseHasTheClosedFormPeaks) {
  const double t1 = 0.3, peak_a = 4.0, r = peak_a / t1;
  RecordExcitation pulse{{0.0, t1, 2 * t1}, {0.0, peak_a, 0.0}, "pulse"};
  for (const double period : {0.1, 0.5, 1.3, 4.0}) {
    const double omega = 2 * kPi / period;
    const Ramp ramp{omega, 0.05};
    const auto u = [&](double t) { return r * (ramp(t) - 2 * ramp(t - t1) + ramp(t - 2 * t1)); };
    const double exact = dense_peak(u, 2 * t1 + period, 2'000'000);
    const double periods[] = {period};
    const ResponseSpectrum fine = response_spectrum(pulse, periods, {.damping = 0.05, .steps_per_period = 400});
    EXPECT_NEAR(fine.displacement[0], exact, 1e-8 * exact) << period;
    EXPECT_NEAR(fine.pseudo_acceleration[0], omega * omega * exact, 1e-8 * omega * omega * exact);
    const ResponseSpectrum standard = response_spectrum(pulse, periods);  // 50 sub-steps a period
    EXPECT_NEAR(standard.displacement[0], exact, 1e-6 * exact) << period;
  }
}

// A sine sampled finely: the steady amplitude and its transient from rest in closed form. The
// record is the sine's linear interpolant, which differs from it by (Ω dt)²/8 ≈ 3e-7 here.
TEST(ResponseSpectrum, ASineHasItsClosedFormResponseFromRest) {
  const double big_omega = 2 * kPi, amplitude = 1.5, dt = 1.0 / 4000, duration = 20.0;
  RecordExcitation sine;
  for (int i = 0; i * dt <= duration + 1e-12; ++i) {
    sine.time.push_back(i * dt);
    sine.acceleration.push_back(amplitude * std::sin(big_omega * i * dt));
  }
  for (const double period : {0.35, 0.9, 1.6}) {
    const double omega = 2 * kPi / period, zeta = 0.05, wd = omega * std::sqrt(1 - zeta * zeta);
    const double w2 = omega * omega - big_omega * big_omega, delta = w2 * w2 + 4 * zeta * zeta * omega * omega * big_omega * big_omega;
    const double c = -amplitude * w2 / delta, d = 2 * zeta * omega * big_omega * amplitude / delta;
    const double e = -d, f = (zeta * omega * e - big_omega * c) / wd;
    const auto u = [&](double t) {
      return c * std::sin(big_omega * t) + d * std::cos(big_omega * t) +
             std::exp(-zeta * omega * t) * (e * std::cos(wd * t) + f * std::sin(wd * t));
    };
    // The record ends at a whole number of cycles (a_g = 0 there): after it the response is free,
    // and the spectrum looks one period further; the closed form's peak comes well before.
    const double exact = dense_peak(u, duration, 4'000'000);
    const double periods[] = {period};
    const ResponseSpectrum s = response_spectrum(sine, periods, {.damping = zeta, .steps_per_period = 200});
    EXPECT_NEAR(s.displacement[0], exact, 2e-6 * exact) << period;
  }
}

// The spectrum of a real record against the exact integrator of a single-storey frame with the
// same period and damping (its peaks refined to 1e-12 s), run past the record's end by a period.
TEST(ResponseSpectrum, ARecordsSpectrumIsTheExactIntegratorsPeaks) {
  io::RecordOptions options;
  const io::GroundMotionRecord record = io::read_ground_motion(kRecords / "elCentro.AT2", options);
  for (const double period : {0.2, 0.75, 2.0}) {
    const double m = 1.0e4, omega = 2 * kPi / period, zeta = 0.05;
    const Model model = make_model({make_uniform_frame(1, m, m * omega * omega, 2 * zeta * m * omega)}, GapProperties{});
    Simulator sim(model, record.excitation, TimeHistoryOptions{.dt = 0.01, .integrator = Integrator::exact});
    sim.advance_to(record.excitation.time.back() + period);
    const double peak_u = sim.statistics().floors[0].displacement.value;
    const double peak_abs = sim.statistics().floors[0].absolute_acceleration.value;
    const double periods[] = {period};
    const ResponseSpectrum s = response_spectrum(record.excitation, periods, {.damping = zeta, .steps_per_period = 400});
    EXPECT_NEAR(s.displacement[0], std::abs(peak_u), 1e-8 * std::abs(peak_u)) << period;
    // The monitor samples the absolute acceleration at its dt and events (no refinement): within
    // the spectrum's refined peak, and close to it.
    EXPECT_LE(std::abs(peak_abs), s.absolute_acceleration[0] * (1 + 1e-9));
    EXPECT_NEAR(std::abs(peak_abs), s.absolute_acceleration[0], 0.02 * s.absolute_acceleration[0]) << period;
  }
}

TEST(ResponseSpectrum, BadPeriodsAndOptionsAreRefused) {
  const RecordExcitation pulse{{0.0, 0.1}, {1.0, 0.0}, "p"};
  const double zero[] = {0.0};
  EXPECT_THROW((void)response_spectrum(pulse, zero), std::invalid_argument);
  const double nan[] = {std::nan("")};
  EXPECT_THROW((void)response_spectrum(pulse, nan), std::invalid_argument);
  const double fine[] = {1.0};
  EXPECT_THROW((void)response_spectrum(pulse, fine, {.damping = 1.5}), std::invalid_argument);
  EXPECT_THROW((void)response_spectrum(pulse, fine, {.steps_per_period = 2}), std::invalid_argument);
  // So short a period that one step of the record would need more sub-steps than a count holds.
  const double tiny[] = {1e-20};
  EXPECT_THROW((void)response_spectrum(pulse, tiny), std::invalid_argument);
  EXPECT_EQ(peak_ground_acceleration(RecordExcitation{{0.0, 1.0, 2.0}, {0.5, -2.5, 1.0}, "p"}), 2.5);
}

// EN 1998-1 §3.2.2.2 at its corners and on each branch (type 1, ground C: S = 1.15, T_B = 0.2,
// T_C = 0.6, T_D = 2; type 2, ground D: S = 1.8, T_B = 0.1, T_C = 0.3, T_D = 1.2).
TEST(DesignSpectrum, EurocodeEightHasItsBranchesAndCorners) {
  const double g = 9.81, ag = 0.25 * g;
  const DesignSpectrum c1 = Eurocode8Spectrum{.type = Eurocode8Type::type1, .ground = GroundType::C, .ag = ag};
  const double plateau = 2.5 * ag * 1.15;
  EXPECT_DOUBLE_EQ(spectral_acceleration(c1, 0.0), ag * 1.15);
  EXPECT_DOUBLE_EQ(spectral_acceleration(c1, 0.1), ag * 1.15 * (1 + 0.5 * 1.5));
  EXPECT_DOUBLE_EQ(spectral_acceleration(c1, 0.2), plateau);
  EXPECT_DOUBLE_EQ(spectral_acceleration(c1, 0.45), plateau);
  EXPECT_DOUBLE_EQ(spectral_acceleration(c1, 1.2), plateau * 0.6 / 1.2);
  EXPECT_DOUBLE_EQ(spectral_acceleration(c1, 3.0), plateau * 0.6 * 2.0 / 9.0);
  EXPECT_THROW((void)spectral_acceleration(c1, 4.5), std::invalid_argument);
  const DesignSpectrum d2 = Eurocode8Spectrum{.type = Eurocode8Type::type2, .ground = GroundType::D, .ag = ag, .damping = 0.10};
  const double eta = std::sqrt(10.0 / 15.0);
  EXPECT_DOUBLE_EQ(spectral_acceleration(d2, 0.3), 2.5 * ag * 1.8 * eta);
  EXPECT_DOUBLE_EQ(spectral_acceleration(d2, 2.4), 2.5 * ag * 1.8 * eta * 0.3 * 1.2 / (2.4 * 2.4));
  // η never below 0.55, whatever the damping.
  const DesignSpectrum heavy = Eurocode8Spectrum{.type = Eurocode8Type::type1, .ground = GroundType::A, .ag = ag, .damping = 1.0};
  EXPECT_DOUBLE_EQ(spectral_acceleration(heavy, 0.3), 2.5 * ag * 0.55);
  EXPECT_THROW(validate(DesignSpectrum{Eurocode8Spectrum{.ag = 0.0}}), std::invalid_argument);
}

TEST(DesignSpectrum, ATableIsLinearBetweenItsRowsAndRefusesOthers) {
  const DesignSpectrum table = TabulatedSpectrum{{0.1, 0.5, 2.0}, {3.0, 7.0, 1.0}};
  validate(table);
  EXPECT_DOUBLE_EQ(spectral_acceleration(table, 0.3), 5.0);
  EXPECT_DOUBLE_EQ(spectral_acceleration(table, 2.0), 1.0);
  EXPECT_THROW((void)spectral_acceleration(table, 2.5), std::invalid_argument);
  EXPECT_THROW(validate(DesignSpectrum{TabulatedSpectrum{{0.1, 0.1}, {1.0, 2.0}}}), std::invalid_argument);
  EXPECT_THROW(validate(DesignSpectrum{TabulatedSpectrum{{0.1, 0.2}, {1.0, -2.0}}}), std::invalid_argument);
  EXPECT_THROW(validate(DesignSpectrum{TabulatedSpectrum{{0.1}, {1.0}}}), std::invalid_argument);
}

// Spectra are linear in the record's scale; the factors do what they promise over the range.
TEST(SuiteScaling, TheFactorsMeetTheirTargetOverTheRange) {
  io::RecordOptions options;
  std::vector<ResponseSpectrum> spectra;
  const std::vector<double> periods = log_spaced_periods(0.1, 2.0, 30);
  for (const char* name : {"elCentro.AT2", "RSN758_LOMAP_EMY260.AT2", "RSN1084_NORTHR_SCS142.AT2"}) {
    spectra.push_back(response_spectrum(io::read_ground_motion(kRecords / name, options).excitation, periods));
  }
  const DesignSpectrum ec8 = Eurocode8Spectrum{.type = Eurocode8Type::type1, .ground = GroundType::C, .ag = 0.3 * 9.81};
  std::vector<double> target;
  for (const double t : periods) target.push_back(spectral_acceleration(ec8, t));
  const std::vector<double> mean = mean_pseudo_acceleration(spectra);

  const double f = suite_scale_factor(spectra, target, SuiteMatch::least_squares, 1.0);
  double log_misfit = 0.0;
  for (std::size_t i = 0; i < periods.size(); ++i) log_misfit += std::log(f * mean[i] / target[i]);
  EXPECT_NEAR(log_misfit, 0.0, 1e-12);

  const double g = suite_scale_factor(spectra, target, SuiteMatch::not_below, 0.9);
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < periods.size(); ++i) least = std::min(least, g * mean[i] / target[i]);
  EXPECT_NEAR(least, 0.9, 1e-14);

  // Scaling the record scales its spectrum: a record scaled by g has g times the spectrum.
  io::RecordOptions scaled = options;
  scaled.scale = 1.7;
  const ResponseSpectrum twice = response_spectrum(io::read_ground_motion(kRecords / "elCentro.AT2", scaled).excitation, periods);
  for (std::size_t i = 0; i < periods.size(); ++i) {
    EXPECT_NEAR(twice.pseudo_acceleration[i], 1.7 * spectra[0].pseudo_acceleration[i], 1e-12 * twice.pseudo_acceleration[i]);
  }
  EXPECT_THROW((void)suite_scale_factor(spectra, std::vector<double>(3, 1.0), SuiteMatch::least_squares, 1.0), std::invalid_argument);
  EXPECT_THROW((void)log_spaced_periods(0.0, 1.0, 5), std::invalid_argument);
  EXPECT_DOUBLE_EQ(periods.front(), 0.1);
  EXPECT_DOUBLE_EQ(periods.back(), 2.0);
}

}  // namespace
}  // namespace poundsim
