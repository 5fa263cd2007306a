#pragma once
/// @file
/// Free-field ground acceleration a_g(t) [m/s²], the same at the base of every frame (no
/// soil-structure interaction). The load on the floors is −M·1·a_g(t).
///
/// Example:
/// @code
///   Excitation h = HarmonicExcitation{.amplitude = 0.2 * standard_gravity, .omega = 11.3};
///   double a = ground_acceleration(h, 0.1);  // A sin(ω̄ t)
/// @endcode

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace poundsim {

/// No ground motion (free vibration from initial conditions).
struct NoExcitation {
  [[nodiscard]] bool operator==(const NoExcitation&) const = default;
};

/// a_g(t) = A sin(ω̄ t).
struct HarmonicExcitation {
  double amplitude = 0.0;  ///< A [m/s²].
  double omega = 0.0;      ///< ω̄ [rad/s], > 0.
  [[nodiscard]] bool operator==(const HarmonicExcitation&) const = default;
};

/// A sampled accelerogram, linear between samples and zero before the first and after the last.
/// Invariants: times strictly increasing, time[0] ≥ 0, same length as acceleration, ≥ 2 samples.
struct RecordExcitation {
  std::vector<double> time;          ///< [s]
  std::vector<double> acceleration;  ///< [m/s²], already scaled.
  std::string source;                ///< Where the record came from (file name), for reports.
  [[nodiscard]] bool operator==(const RecordExcitation&) const = default;
};

using Excitation = std::variant<NoExcitation, HarmonicExcitation, RecordExcitation>;

/// a_g(t) [m/s²].
[[nodiscard]] double ground_acceleration(const Excitation& excitation, double t);

/// The ground acceleration on the interval [start, end) around a time, in the closed form the
/// exact integrator needs: a polynomial value + slope·(t − start) (no excitation, a record between
/// two samples, or before or after the record), or A sin(ω t).
struct ForcingPiece {
  enum class Kind : std::uint8_t { linear, harmonic };
  Kind kind = Kind::linear;
  double start = 0.0;      ///< [s]
  double end = 0.0;        ///< [s], +∞ when the form holds for ever
  double value = 0.0;      ///< linear: a_g(start) [m/s²]
  double slope = 0.0;      ///< linear: da_g/dt [m/s³]
  double amplitude = 0.0;  ///< harmonic: A [m/s²]
  double omega = 0.0;      ///< harmonic: ω̄ [rad/s]

  [[nodiscard]] double at(double t) const;
};

/// The piece that holds on [t, piece.end), with piece.start ≤ t.
[[nodiscard]] ForcingPiece forcing_piece(const Excitation& excitation, double t);

/// Throws std::invalid_argument when the excitation breaks its invariants.
void validate(const Excitation& excitation);

}  // namespace poundsim
