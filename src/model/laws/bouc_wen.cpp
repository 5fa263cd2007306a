#include "poundsim/model/laws/bouc_wen.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace poundsim {

namespace {
/// |z|ⁿ: by multiplication for the integer exponents of common use (std::pow costs several
/// times more, and every Newton iteration of every step asks it).
double power_of(double az, double n) {
  if (n == std::floor(n) && n <= 16) {
    double p = 1.0;
    for (int i = 0; i < static_cast<int>(n); ++i) p *= az;
    return p;
  }
  return std::pow(az, n);
}
}  // namespace

BoucWenStorey::Trial BoucWenStorey::trial(double d, const State& state) const {
  const double uy = yield_drift();
  const double step = (d - state.drift) / uy;  // Δd/u_y
  if (step == 0.0) {
    // The slope of the loading branch the state is on (its direction unknown: the tangent of a
    // step about to start is Φ for the sign Newton's first increment will take; take loading).
    const double z = state.z, az = std::abs(z);
    return {.z = z, .slope = (a - power_of(az, n) * (beta + gamma)) / uy};
  }
  const double direction = step > 0 ? 1.0 : -1.0;
  // Φ(z) and Φ′(z) for this step's direction.
  const auto phi = [&](double z, double& derivative) {
    const double az = std::abs(z);
    const double s = direction * z >= 0 ? 1.0 : -1.0;  // sgn(Δd z)
    const double shape = beta * s + gamma;
    const double power = power_of(az, n);
    derivative = az > 0 ? -n * power / az * (z > 0 ? 1.0 : -1.0) * shape : 0.0;
    return a - power * shape;
  };
  // The trapezoidal rule in the drift, g(z) = z − z₀ − (step/2)(Φ(z₀) + Φ(z)) = 0, by Newton
  // from the explicit (forward-Euler) guess, each iterate kept within the bracket that g's sign
  // changes have established.
  double derivative = 0.0;
  const double phi0 = phi(state.z, derivative);
  const double half = 0.5 * step;
  double z = state.z + step * phi0;
  double lo = -HUGE_VAL, hi = HUGE_VAL;
  for (int i = 0; i < 60; ++i) {
    const double g = z - state.z - half * (phi0 + phi(z, derivative));
    if (g == 0.0) break;
    const double dg = 1.0 - half * derivative;
    if (g > 0) {
      hi = std::min(hi, z);
    } else {
      lo = std::max(lo, z);
    }
    double next = z - g / dg;
    if (!(dg > 0) || !(next >= lo && next <= hi)) {
      // Outside the bracket (or a non-monotone g): bisect once it exists, else step out.
      if (std::isfinite(lo) && std::isfinite(hi)) {
        next = 0.5 * (lo + hi);
      } else {
        next = g > 0 ? z - std::max(1.0, std::abs(z)) : z + std::max(1.0, std::abs(z));
      }
    }
    const bool converged = std::abs(next - z) <= 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(z));
    z = next;
    if (converged) break;
  }
  double d_phi = 0.0;
  const double value = phi(z, d_phi);
  // dz/dd from g(z(d), d) = 0 (Φ(z₀) is fixed for the step's direction):
  // (1 − (step/2) Φ′) dz = ((Φ(z₀) + Φ(z))/(2 u_y)) dd.
  return {.z = z, .slope = 0.5 * (phi0 + value) / uy / (1.0 - half * d_phi)};
}

}  // namespace poundsim
