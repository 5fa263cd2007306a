#pragma once
// The cubic Hermite interpolant of a guard over [0, τ] from its values and rates at both ends,
// p(θ) = c0 + c1 θ + c2 θ² + c3 θ³ with θ = t/τ. Guards are smooth along a Newmark step, so this
// cheap model predicts where they cross zero or peak inside the step.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace poundsim::detail {

class HermiteCubic {
 public:
  /// g0, g1: values at θ = 0 and 1; d0, d1: rates dg/dt at both ends; tau: the interval length.
  HermiteCubic(double g0, double d0, double g1, double d1, double tau)
      : c0_(g0),
        c1_(tau * d0),
        c2_(-3 * g0 - 2 * tau * d0 + 3 * g1 - tau * d1),
        c3_(2 * g0 + tau * d0 - 2 * g1 + tau * d1) {}

  [[nodiscard]] double operator()(double t) const { return ((c3_ * t + c2_) * t + c1_) * t + c0_; }
  [[nodiscard]] double slope(double t) const { return (3 * c3_ * t + 2 * c2_) * t + c1_; }

  /// The least of slope(θ) over [0, 1]: at an end, or at the vertex of the quadratic when it is
  /// convex (c3 > 0) and the vertex lies inside.
  [[nodiscard]] double least_slope() const {
    double least = std::min(slope(0.0), slope(1.0));
    if (c3_ > 0) {
      const double vertex = -c2_ / (3 * c3_);
      if (vertex > 0 && vertex < 1) least = std::min(least, slope(vertex));
    }
    return least;
  }

  /// Where p crosses zero in (0, 1) when p(0) ≤ 0 < p(1) and the guard it models is proven
  /// rising there: a secant start and a few Newton steps kept in the bracket — a first point for
  /// Newton on the guard itself, which needs it no closer than the model's own error.
  [[nodiscard]] double rising_root() const {
    const double p0 = c0_, p1 = (*this)(1.0);
    return monotone_root(0.0, 1.0, p0 < p1 ? p0 / (p0 - p1) : 0.5, 4);
  }

  /// Interior critical points in (0, 1), ascending; unused entries are NaN.
  [[nodiscard]] std::array<double, 2> critical_points() const {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::array<double, 2> out{nan, nan};
    const double a = 3 * c3_, b = 2 * c2_, c = c1_;
    const double scale = std::abs(a) + std::abs(b) + std::abs(c);
    if (scale == 0) return out;
    int n = 0;
    const auto keep = [&](double x) {
      if (x > 0 && x < 1) out[static_cast<std::size_t>(n++)] = x;
    };
    if (std::abs(a) <= 1e-14 * scale) {
      if (b != 0) keep(-c / b);
    } else {
      const double disc = b * b - 4 * a * c;
      if (disc >= 0) {
        const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
        if (q != 0) {
          keep(q / a);
          keep(c / q);
        } else {
          keep(0.0);
        }
      }
    }
    if (n == 2 && out[0] > out[1]) std::swap(out[0], out[1]);
    return out;
  }

  /// The first θ in (0, 1] where p crosses from ≤ 0 to > 0, to about 1e-15; NaN if none.
  [[nodiscard]] double first_upward_root() const {
    const auto cp = critical_points();
    double a = 0.0;
    for (int k = 0; k <= 2; ++k) {
      const double b = k < 2 && !std::isnan(cp[static_cast<std::size_t>(k)]) ? cp[static_cast<std::size_t>(k)] : 1.0;
      if (b <= a) continue;
      if ((*this)(a) <= 0 && (*this)(b) > 0) return monotone_root(a, b, 0.5 * (a + b), 100);
      a = b;
      if (b == 1.0) break;
    }
    return std::numeric_limits<double>::quiet_NaN();
  }

 private:
  /// Root of p on [a, b] where p(a) ≤ 0 < p(b) and p is monotone: Newton from x inside a
  /// bisection bracket, at most `iterations` steps.
  [[nodiscard]] double monotone_root(double a, double b, double x, int iterations) const {
    for (int i = 0; i < iterations && b - a > 1e-16; ++i) {
      const double y = (*this)(x);
      if (y > 0) {
        b = x;
      } else {
        a = x;
      }
      const double d = slope(x);
      const double newton = d != 0 ? x - y / d : 0.5 * (a + b);
      const double next = newton > a && newton < b ? newton : 0.5 * (a + b);
      if (std::abs(next - x) <= 1e-16) return next;
      x = next;
    }
    return x;
  }

  double c0_, c1_, c2_, c3_;
};

}  // namespace poundsim::detail
