#include "poundsim/analysis/response_spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Core>
#include <fmt/format.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "../integrate/hermite_cubic.hpp"

namespace poundsim {

void SpectrumOptions::validate() const { validate_fields(*this, "spectrum"); }

namespace {

/// The exact step of the oscillator: x(h) = Φ x(0) + Γ₀ a₀ + Γ₁ a₁, x = [u, u̇].
struct Recurrence {
  double h = -1.0;
  Eigen::Matrix2d phi = Eigen::Matrix2d::Zero();
  Eigen::Vector2d gamma0 = Eigen::Vector2d::Zero(), gamma1 = Eigen::Vector2d::Zero();

  void make(double omega, double zeta, double step) {
    // State [u, u̇, a_g, ȧ_g]: u̇' = −ω²u − 2ζωu̇ − a_g, a_g' = ȧ_g, ȧ_g' = 0.
    Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
    m(0, 1) = 1.0;
    m(1, 0) = -omega * omega;
    m(1, 1) = -2.0 * zeta * omega;
    m(1, 2) = -1.0;
    m(2, 3) = 1.0;
    const Eigen::Matrix4d e = (m * step).exp();
    phi = e.topLeftCorner<2, 2>();
    // a_g(s) = a₀ + (a₁ − a₀) s/h: the columns of a₀ and of the slope ȧ_g = (a₁ − a₀)/h.
    gamma1 = e.block<2, 1>(0, 3) / step;
    gamma0 = e.block<2, 1>(0, 2) - gamma1;
    h = step;
  }
};

/// Peaks of one oscillator over a record.
class Oscillator {
 public:
  Oscillator(double period, double zeta, int steps_per_period)
      : omega_(2 * std::numbers::pi / period), zeta_(zeta), longest_(period / steps_per_period),
        steps_per_period_(steps_per_period) {}

  /// From x over a step of length `length` on which a_g goes from a0 to a1.
  void advance(double length, double a0, double a1) {
    const double steps = std::ceil(length / longest_);
    if (!(steps <= 1e9)) {
      throw std::invalid_argument(fmt::format("a step of {} s of the record needs {:.3g} sub-steps at a period of {} s "
                                              "(at most 1e9): the period is too short",
                                              length, steps, longest_ * steps_per_period_));
    }
    const auto n = static_cast<long>(steps);
    const double h = length / static_cast<double>(n);
    // Steps of a record sampled at a fixed dt differ by round-off only: one recurrence serves.
    if (!(std::abs(h - recurrence_.h) <= 1e-12 * h)) recurrence_.make(omega_, zeta_, h);
    for (long i = 0; i < n; ++i) {
      const double s0 = static_cast<double>(i) / static_cast<double>(n), s1 = static_cast<double>(i + 1) / static_cast<double>(n);
      const double g0 = a0 + (a1 - a0) * s0, g1 = a0 + (a1 - a0) * s1;
      const Eigen::Vector2d next = recurrence_.phi * x_ + recurrence_.gamma0 * g0 + recurrence_.gamma1 * g1;
      observe(x_, g0, next, g1, recurrence_.h);
      x_ = next;
    }
  }

  [[nodiscard]] double peak_displacement() const { return peak_u_; }
  [[nodiscard]] double peak_absolute_acceleration() const { return peak_a_; }

 private:
  /// ü + a_g = −2ζωu̇ − ω²u, and its rate −2ζω ü − ω² u̇.
  [[nodiscard]] double absolute(const Eigen::Vector2d& x) const { return -2 * zeta_ * omega_ * x(1) - omega_ * omega_ * x(0); }
  [[nodiscard]] double absolute_rate(const Eigen::Vector2d& x, double ag) const {
    const double relative_acceleration = absolute(x) - ag;
    return -2 * zeta_ * omega_ * relative_acceleration - omega_ * omega_ * x(1);
  }

  void observe(const Eigen::Vector2d& a, double ga, const Eigen::Vector2d& b, double gb, double h) {
    peak_u_ = std::max(peak_u_, std::abs(b(0)));
    const double abs_a = absolute(a), abs_b = absolute(b);
    peak_a_ = std::max({peak_a_, std::abs(abs_a), std::abs(abs_b)});
    if (a(1) * b(1) < 0) {
      const detail::HermiteCubic cubic(a(0), a(1), b(0), b(1), h);
      for (const double theta : cubic.critical_points()) {
        if (theta > 0 && theta < 1) peak_u_ = std::max(peak_u_, std::abs(cubic(theta)));
      }
    }
    const double ra = absolute_rate(a, ga), rb = absolute_rate(b, gb);
    if (ra * rb < 0) {
      const detail::HermiteCubic cubic(abs_a, ra, abs_b, rb, h);
      for (const double theta : cubic.critical_points()) {
        if (theta > 0 && theta < 1) peak_a_ = std::max(peak_a_, std::abs(cubic(theta)));
      }
    }
  }

  double omega_, zeta_, longest_;
  int steps_per_period_;
  Recurrence recurrence_;
  Eigen::Vector2d x_ = Eigen::Vector2d::Zero();
  double peak_u_ = 0.0, peak_a_ = 0.0;
};

}  // namespace

ResponseSpectrum response_spectrum(const RecordExcitation& record, std::span<const double> periods,
                                   const SpectrumOptions& options) {
  options.validate();
  validate(Excitation{record});
  ResponseSpectrum out;
  for (const double period : periods) {
    if (!(period > 0) || !std::isfinite(period)) {
      throw std::invalid_argument(fmt::format("a spectrum's periods must be finite and > 0 (got {})", period));
    }
    Oscillator oscillator(period, options.damping, options.steps_per_period);
    const std::vector<double>& t = record.time;
    const std::vector<double>& a = record.acceleration;
    // At rest until the first sample (a_g = 0 before it), linear between samples, and free for a
    // period after the last (a_g = 0 after it).
    for (std::size_t i = 0; i + 1 < t.size(); ++i) oscillator.advance(t[i + 1] - t[i], a[i], a[i + 1]);
    oscillator.advance(period, 0.0, 0.0);
    const double omega = 2 * std::numbers::pi / period;
    out.period.push_back(period);
    out.displacement.push_back(oscillator.peak_displacement());
    out.pseudo_acceleration.push_back(omega * omega * oscillator.peak_displacement());
    out.absolute_acceleration.push_back(oscillator.peak_absolute_acceleration());
  }
  return out;
}

double peak_ground_acceleration(const RecordExcitation& record) {
  double peak = 0.0;
  for (const double a : record.acceleration) peak = std::max(peak, std::abs(a));
  return peak;
}

Eurocode8Corners corners(Eurocode8Type type, GroundType ground) {
  // EN 1998-1:2004, Table 3.2 (type 1) and Table 3.3 (type 2), recommended values.
  static constexpr std::array<Eurocode8Corners, 5> type1{{
      {1.00, 0.15, 0.4, 2.0}, {1.20, 0.15, 0.5, 2.0}, {1.15, 0.20, 0.6, 2.0}, {1.35, 0.20, 0.8, 2.0}, {1.40, 0.15, 0.5, 2.0},
  }};
  static constexpr std::array<Eurocode8Corners, 5> type2{{
      {1.00, 0.05, 0.25, 1.2}, {1.35, 0.05, 0.25, 1.2}, {1.50, 0.10, 0.25, 1.2}, {1.80, 0.10, 0.30, 1.2}, {1.60, 0.05, 0.25, 1.2},
  }};
  const auto g = static_cast<std::size_t>(ground);
  return type == Eurocode8Type::type1 ? type1[g] : type2[g];
}

void validate(const DesignSpectrum& spectrum) {
  if (const auto* ec8 = std::get_if<Eurocode8Spectrum>(&spectrum)) {
    if (!(ec8->ag > 0) || !std::isfinite(ec8->ag)) {
      throw std::invalid_argument(fmt::format("a Eurocode 8 spectrum's a_g must be finite and > 0 (got {})", ec8->ag));
    }
    if (!(ec8->damping >= 0 && ec8->damping <= 1)) {
      throw std::invalid_argument(fmt::format("a Eurocode 8 spectrum's damping must lie in [0, 1] (got {})", ec8->damping));
    }
    return;
  }
  const auto& table = std::get<TabulatedSpectrum>(spectrum);
  if (table.period.size() != table.acceleration.size() || table.period.size() < 2) {
    throw std::invalid_argument(fmt::format("a spectrum table needs two or more rows of (period, S_a) (got {} periods, {} values)",
                                            table.period.size(), table.acceleration.size()));
  }
  for (std::size_t i = 0; i < table.period.size(); ++i) {
    if (!(table.period[i] >= 0) || !std::isfinite(table.period[i])) {
      throw std::invalid_argument(fmt::format("row {}: the period must be finite and ≥ 0 (got {})", i + 1, table.period[i]));
    }
    if (i > 0 && !(table.period[i] > table.period[i - 1])) {
      throw std::invalid_argument(fmt::format("row {}: the periods must increase ({} after {})", i + 1, table.period[i], table.period[i - 1]));
    }
    if (!(table.acceleration[i] >= 0) || !std::isfinite(table.acceleration[i])) {
      throw std::invalid_argument(fmt::format("row {}: S_a must be finite and ≥ 0 (got {})", i + 1, table.acceleration[i]));
    }
  }
}

std::string_view design_name(const DesignSpectrum& spectrum) {
  if (const auto* ec8 = std::get_if<Eurocode8Spectrum>(&spectrum)) return name_in(eurocode8_type_names, ec8->type);
  return tabulated_design_name;
}

double spectral_acceleration(const DesignSpectrum& spectrum, double period) {
  if (const auto* ec8 = std::get_if<Eurocode8Spectrum>(&spectrum)) {
    if (!(period >= 0 && period <= 4.0)) {
      throw std::invalid_argument(fmt::format("the Eurocode 8 spectrum is defined for periods in [0, 4] s (asked at {} s)", period));
    }
    const Eurocode8Corners c = corners(ec8->type, ec8->ground);
    const double eta = std::max(0.55, std::sqrt(10.0 / (5.0 + 100.0 * ec8->damping)));
    const double plateau = 2.5 * ec8->ag * c.soil * eta;
    if (period <= c.tb) return ec8->ag * c.soil * (1.0 + period / c.tb * (2.5 * eta - 1.0));
    if (period <= c.tc) return plateau;
    if (period <= c.td) return plateau * c.tc / period;
    return plateau * c.tc * c.td / (period * period);
  }
  const auto& table = std::get<TabulatedSpectrum>(spectrum);
  if (!(period >= table.period.front() && period <= table.period.back())) {
    throw std::invalid_argument(fmt::format("the spectrum table covers periods [{}, {}] s (asked at {} s)",
                                            table.period.front(), table.period.back(), period));
  }
  const auto upper = std::upper_bound(table.period.begin(), table.period.end(), period);
  if (upper == table.period.end()) return table.acceleration.back();
  const auto i = static_cast<std::size_t>(upper - table.period.begin());
  const double w = (period - table.period[i - 1]) / (table.period[i] - table.period[i - 1]);
  return table.acceleration[i - 1] + w * (table.acceleration[i] - table.acceleration[i - 1]);
}

std::vector<double> mean_pseudo_acceleration(std::span<const ResponseSpectrum> spectra) {
  if (spectra.empty()) throw std::invalid_argument("the mean of no spectra");
  std::vector<double> mean(spectra.front().pseudo_acceleration.size(), 0.0);
  for (const ResponseSpectrum& s : spectra) {
    if (s.pseudo_acceleration.size() != mean.size()) throw std::invalid_argument("spectra at different periods");
    for (std::size_t i = 0; i < mean.size(); ++i) mean[i] += s.pseudo_acceleration[i];
  }
  for (double& m : mean) m /= static_cast<double>(spectra.size());
  return mean;
}

double suite_scale_factor(std::span<const ResponseSpectrum> spectra, std::span<const double> target, SuiteMatch match,
                          double fraction) {
  const std::vector<double> mean = mean_pseudo_acceleration(spectra);
  if (mean.size() != target.size() || mean.empty()) {
    throw std::invalid_argument(fmt::format("{} target values for spectra at {} periods", target.size(), mean.size()));
  }
  if (!(fraction > 0 && fraction <= 1)) throw std::invalid_argument(fmt::format("fraction must lie in (0, 1] (got {})", fraction));
  double log_sum = 0.0, least = 0.0;
  for (std::size_t i = 0; i < mean.size(); ++i) {
    if (!(mean[i] > 0) || !(target[i] > 0)) {
      throw std::invalid_argument(fmt::format("the suite's mean S_a ({}) or the target ({}) is not > 0 at period {} of the range",
                                              mean[i], target[i], i + 1));
    }
    log_sum += std::log(target[i] / mean[i]);
    least = std::max(least, fraction * target[i] / mean[i]);
  }
  return match == SuiteMatch::least_squares ? std::exp(log_sum / static_cast<double>(mean.size())) : least;
}

std::vector<double> log_spaced_periods(double lo, double hi, int count) {
  if (!(lo > 0 && hi > lo && std::isfinite(hi)) || count < 2) {
    throw std::invalid_argument(fmt::format("periods from {} to {} s in {} points: need 0 < lo < hi and ≥ 2 points", lo, hi, count));
  }
  std::vector<double> out(static_cast<std::size_t>(count));
  const double step = std::log(hi / lo) / (count - 1);
  for (int i = 0; i < count; ++i) out[static_cast<std::size_t>(i)] = lo * std::exp(step * i);
  out.back() = hi;
  return out;
}

}  // namespace poundsim
