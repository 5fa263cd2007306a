#pragma once
/// @file
/// Physical constants. All quantities in poundsim are SI (m, kg, s, N) unless a name says
/// otherwise (e.g. `amplitude_g`).

namespace poundsim {

/// Acceleration of gravity used to turn "g" into m/s² and in the paper's dimensionless gap and
/// shortening (δ̄ = δλ²/g, ε̄ = ελ²/g). Pasquino et al. use g = 9.81 m/s², so do we.
inline constexpr double standard_gravity = 9.81;

}  // namespace poundsim
