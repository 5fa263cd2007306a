#include "poundsim/model/laws/bouc_wen.hpp"

#include <algorithm>
#include <cmath>

namespace poundsim {

BoucWenStorey::Trial BoucWenStorey::trial(double d, const State& state) const {
  const double uy = yield_drift();
  const double step = (d - state.drift) / uy;  // Δd/u_y
  if (step == 0.0) {
    // The slope of the loading branch the state is on (its direction unknown: the tangent of a
    // step about to start is Φ for the sign Newton's first increment will take; take loading).
    const double z = state.z, az = std::abs(z);
    return {.z = z, .slope = (a - std::pow(az, n) * (beta + gamma)) / uy};
  }
  const double direction = step > 0 ? 1.0 : -1.0;
  // Φ(z) and Φ′(z) for this step's direction.
  const auto phi = [&](double z, double& derivative) {
    const double az = std::abs(z);
    const double s = direction * z >= 0 ? 1.0 : -1.0;  // sgn(Δd z)
    const double shape = beta * s + gamma;
    const double power = std::pow(az, n);
    derivative = az > 0 ? -n * power / az * (z > 0 ? 1.0 : -1.0) * shape : 0.0;
    return a - power * shape;
  };
  // g(z) = z − z₀ − step Φ(z) = 0 by Newton from the explicit (forward-Euler) guess, each
  // iterate kept within the bracket that g's sign changes have established.
  double derivative = 0.0;
  double z = state.z + step * phi(state.z, derivative);
  double lo = -HUGE_VAL, hi = HUGE_VAL;
  for (int i = 0; i < 100; ++i) {
    const double g = z - state.z - step * phi(z, derivative);
    const double dg = 1.0 - step * derivative;
    if (g > 0) {
      hi = std::min(hi, z);
    } else {
      lo = std::max(lo, z);
    }
    double next = dg > 0 ? z - g / dg : z;
    if (!(next > lo && next < hi) || dg <= 0) {
      // Outside the bracket (or a non-monotone g): bisect once it exists, else step out.
      if (std::isfinite(lo) && std::isfinite(hi)) {
        next = 0.5 * (lo + hi);
      } else {
        next = g > 0 ? z - std::max(1.0, std::abs(z)) : z + std::max(1.0, std::abs(z));
      }
    }
    const bool converged = std::abs(next - z) <= 1e-15 * std::max(1.0, std::abs(z));
    z = next;
    if (converged) break;
  }
  double d_phi = 0.0;
  const double value = phi(z, d_phi);
  // dz/dd from g(z(d), d) = 0: (1 − step Φ′) dz = (Φ/u_y) dd.
  return {.z = z, .slope = value / uy / (1.0 - step * d_phi)};
}

}  // namespace poundsim
