#pragma once
/// @file
/// Elastic response spectra of ground-motion records, design spectra (Eurocode 8 or a table), and
/// the scale factors that bring a record or a suite of records to them.
///
/// The spectrum of a record at a period T = 2π/ω and damping ratio ζ is the peak response of the
/// linear oscillator
///
///     ü + 2ζω u̇ + ω² u = −a_g(t),   u(t₀) = u̇(t₀) = 0,
///
/// with a_g linear between samples (as everywhere in poundsim: excitation.hpp). Over a step of
/// length h on which a_g goes linearly from a₀ to a₁ the solution is exact:
///
///     [u, u̇](h) = Φ [u, u̇](0) + Γ₀ a₀ + Γ₁ a₁
///
/// — the recurrence of Nigam and Jennings (1969), "Calculation of response spectra from
/// strong-motion earthquake records", Bull. Seism. Soc. Am. 59(2), 909–922. Φ, Γ₀ and Γ₁ are
/// taken from the exponential of the augmented matrix [[A, b, 0], [0, 0, 1], [0, 0, 0]] of the
/// state [u, u̇, a_g, ȧ_g] (Van Loan 1978), which holds for every ζ ≥ 0 (critical and
/// over-damped included) and costs one 4×4 exponential per period and step length.
///
/// Peaks between samples: each step is cut into sub-steps no longer than T/steps_per_period,
/// still exact, and where u̇ (or the absolute acceleration's rate) changes sign inside a sub-step
/// the extremum of the cubic Hermite interpolant of the two ends is taken — its error is at most
/// (ωh)⁴/384 of the amplitude, 6.5e-7 at the default 50 sub-steps a period. After the last sample
/// (a_g = 0 from there on) the oscillator vibrates freely: its first extremum, the largest of a
/// decaying free vibration, lies within the period that follows, which is integrated too.
///
/// Checked against the closed-form response to a sine from rest and against the exact integrator
/// of a single-storey frame under a record (response_spectrum_test.cpp).

#include <array>
#include <cstdint>
#include <utility>
#include <span>
#include <string_view>
#include <variant>
#include <vector>

#include "poundsim/fields.hpp"
#include "poundsim/model/excitation.hpp"

namespace poundsim {

/// How a spectrum is computed.
struct SpectrumOptions {
  double damping = 0.05;      ///< ζ of the oscillators, in [0, 1] (5 %: the design spectra's).
  int steps_per_period = 50;  ///< Sub-steps per period T at least, 8 … 10000.

  static constexpr auto fields() {
    using O = SpectrumOptions;
    return std::tuple{
        NumberField{"damping", &O::damping, "", unit_interval, "damping ratio ζ of the spectrum's oscillators"},
        IntegerField{"steps_per_period", &O::steps_per_period, 8, 10000,
                     "exact sub-steps per oscillator period at least (peaks between them from the cubic)"},
    };
  }
  /// Throws std::invalid_argument naming the field that is out of range (its declared range).
  void validate() const;
};

/// Peaks of the oscillators, one per period.
struct ResponseSpectrum {
  std::vector<double> period;                 ///< T [s], > 0
  std::vector<double> displacement;           ///< S_d = max |u| [m]
  std::vector<double> pseudo_acceleration;    ///< S_a = ω² S_d [m/s²] (what design spectra give)
  std::vector<double> absolute_acceleration;  ///< max |ü + a_g| [m/s²]
};

/// The periods an input may ask a spectrum at [s]: below a millisecond the sub-steps over a record
/// run to billions.
inline constexpr double kShortestSpectrumPeriod = 1e-3;
inline constexpr double kLongestSpectrumPeriod = 100.0;

/// The spectrum of `record` at `periods` (each finite and > 0). Throws std::invalid_argument for
/// a bad period or options, and for a period so short that a step of the record would need more
/// than 1e9 sub-steps.
[[nodiscard]] ResponseSpectrum response_spectrum(const RecordExcitation& record, std::span<const double> periods,
                                                 const SpectrumOptions& options = {});

/// max |a_g| of the samples [m/s²] (a_g is linear between them, so this is its peak).
[[nodiscard]] double peak_ground_acceleration(const RecordExcitation& record);

/// EN 1998-1:2004 §3.2.2.2: the horizontal elastic spectrum, type 1 (Ms > 5.5) or 2, on ground
/// type A … E with the recommended S, T_B, T_C, T_D of its Tables 3.2 and 3.3:
///
///     0 ≤ T ≤ T_B:   S_e = a_g S (1 + T/T_B (2.5η − 1))
///     T_B ≤ T ≤ T_C: S_e = 2.5 a_g S η
///     T_C ≤ T ≤ T_D: S_e = 2.5 a_g S η T_C/T
///     T_D ≤ T ≤ 4 s: S_e = 2.5 a_g S η T_C T_D/T²
///
/// with η = √(10/(5 + 100ζ)) ≥ 0.55 (η = 1 at 5 %).
enum class Eurocode8Type : std::uint8_t { type1, type2 };
enum class GroundType : std::uint8_t { A, B, C, D, E };
inline constexpr std::array<std::pair<std::string_view, Eurocode8Type>, 2> eurocode8_type_names{{
    {"ec8_type1", Eurocode8Type::type1},
    {"ec8_type2", Eurocode8Type::type2},
}};
inline constexpr std::array<std::pair<std::string_view, GroundType>, 5> ground_type_names{{
    {"A", GroundType::A}, {"B", GroundType::B}, {"C", GroundType::C}, {"D", GroundType::D}, {"E", GroundType::E},
}};

struct Eurocode8Spectrum {
  Eurocode8Type type = Eurocode8Type::type1;
  GroundType ground = GroundType::A;
  double ag = 0.0;         ///< Design ground acceleration on type A ground a_g [m/s²], > 0.
  double damping = 0.05;   ///< ζ, for η.
};

/// S, T_B, T_C, T_D [s] of a spectrum (Tables 3.2 and 3.3 of EN 1998-1).
struct Eurocode8Corners {
  double soil = 1.0, tb = 0.0, tc = 0.0, td = 0.0;
};
[[nodiscard]] Eurocode8Corners corners(Eurocode8Type type, GroundType ground);

/// A spectrum given as a table: S_a [m/s²] at increasing periods [s], linear between them.
struct TabulatedSpectrum {
  std::vector<double> period;
  std::vector<double> acceleration;
};

using DesignSpectrum = std::variant<Eurocode8Spectrum, TabulatedSpectrum>;

/// The name of a tabulated design spectrum where an input chooses one (the EC8 ones are
/// eurocode8_type_names').
inline constexpr std::string_view tabulated_design_name = "table";
/// "ec8_type1", "ec8_type2" or "table".
[[nodiscard]] std::string_view design_name(const DesignSpectrum& spectrum);

/// S_a(T) [m/s²]. Throws std::invalid_argument outside the spectrum's periods ([0, 4] s for
/// Eurocode 8, the table's first to last period).
[[nodiscard]] double spectral_acceleration(const DesignSpectrum& spectrum, double period);
/// Throws std::invalid_argument for a spectrum that breaks its rules (a_g ≤ 0, a table whose
/// periods do not increase, a negative or non-finite value, fewer than two rows).
void validate(const DesignSpectrum& spectrum);

/// How one factor for a whole suite is chosen over a period range.
enum class SuiteMatch : std::uint8_t {
  least_squares,  ///< the mean spectrum's log misfit to the target is least: f = exp(mean ln(target/mean))
  not_below,      ///< the least f with mean ≥ fraction × target at every period (EC8 §3.2.3.1.2(4): 90 %)
};
inline constexpr std::array<std::pair<std::string_view, SuiteMatch>, 2> suite_match_names{{
    {"least_squares", SuiteMatch::least_squares},
    {"not_below", SuiteMatch::not_below},
}};

/// The factor f applied to every record of a suite whose unscaled spectra (same periods in each)
/// have the mean m(T): f m(T) against `target` (same periods). `fraction` in (0, 1] for
/// not_below. Throws std::invalid_argument when a mean is zero or sizes differ.
[[nodiscard]] double suite_scale_factor(std::span<const ResponseSpectrum> spectra, std::span<const double> target,
                                        SuiteMatch match, double fraction);

/// The mean of the spectra's S_a at each period.
[[nodiscard]] std::vector<double> mean_pseudo_acceleration(std::span<const ResponseSpectrum> spectra);

/// `count` periods spaced evenly in log T over [lo, hi] (count ≥ 2, 0 < lo < hi).
[[nodiscard]] std::vector<double> log_spaced_periods(double lo, double hi, int count);

}  // namespace poundsim
