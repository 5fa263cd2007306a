#pragma once
/// @file
/// Guards of an exact segment as closed-form functions of time, and the search for the first one
/// that becomes positive — with a proof that none was missed in between.
///
/// Every guard (see simulator.hpp) is affine in the state x = [q; q̇] of the phase: g = R_j x + κ_j,
/// except the free end of a relaxing element, a known exponential. On an exact segment
/// (exact_phase.hpp) each guard is therefore, with s = t − t₀,
///
///     g_j(s) = K_j + L_j s + Im(H_j e^{iω̄(t₀+s)}) + Re Σ_k γ_jk e^{λ_k s} − m_j e^{−ν_j s}
///
/// (plus Q_j s² + P_j s³ on a phase with a rigid-body mode, exact_phase.hpp; a slow mode's term
/// as Re γ_jk + Re γ_jk(e^{λ_k s} − 1), its constant in K_j, ExactPhase::slow_modes)
///
/// whose values, rates and derivative bounds are exact and cheap. first_crossing() searches an
/// interval by subdivision: on [a, b] the cubic Hermite model p of a guard from its values and
/// rates at both ends differs from the guard by at most max|g⁗|·(b−a)⁴/384, so
/// max p + that bound ≤ 0 proves the guard stays non-positive; a positive end with a derivative
/// bounded away from zero proves a single crossing, refined by safeguarded Newton steps to the
/// requested resolution (near machine precision). No grazing contact escapes the proof.

#include <array>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "poundsim/integrate/exact_phase.hpp"

namespace poundsim {

/// A phase's guards as affine functions of its state (R, guards × states) in the forms every
/// segment's expansion takes, made once per phase: a segment starts at every event.
struct GuardRows {
  GuardRows() = default;
  GuardRows(Eigen::MatrixXd rows, const ExactPhase& phase);
  Eigen::MatrixXd real;      ///< R
  Eigen::MatrixXcd complex;  ///< R as complex numbers (a segment's harmonic part is R h)
  Eigen::MatrixXcd modal;    ///< R V on a modal phase (a segment's γ is R V diag(c)); empty otherwise
  Eigen::MatrixXd modal_size;  ///< |R V| entry by entry (a segment's |γ_jk| is |R V|_jk |c_k|)
  static constexpr int kBoundOrders = 5;  ///< derivative_bound's orders 0 … 4
  Eigen::MatrixXd rate_powers;            ///< |λ_k|^p, column p (modal phase)
};

class GuardExpansion {
 public:
  /// `at_start` the guard values at s = 0 (which fix κ); the free ends of relaxing elements
  /// contribute −m_j e^{−ν_j s} (m_j = 0 for others). Guards equal to −∞ at the start are
  /// inactive.
  void build(const ExactTrajectory& trajectory, const GuardRows& guard_rows, std::span<const double> at_start,
             std::span<const double> memory_amplitude, std::span<const double> memory_rate);

  [[nodiscard]] int size() const { return static_cast<int>(constant_.size()); }
  [[nodiscard]] bool active(int j) const { return active_[static_cast<std::size_t>(j)]; }
  /// g_j(s) and dg_j/ds. At s = 0 the value is the start value (less the round-off margin every
  /// guard is shifted down by), not the sum. The last two points asked of each guard are
  /// remembered, since the search of consecutive intervals starts where the previous one ended.
  [[nodiscard]] std::pair<double, double> value_and_rate(int j, double s) const;
  /// An upper bound of |dᵐg_j/dsᵐ| over [a, b], 1 ≤ m ≤ 4.
  [[nodiscard]] double derivative_bound(int j, int order, double a, double b) const;

 private:
  const ExactTrajectory* trajectory_ = nullptr;
  std::vector<bool> active_;
  Eigen::VectorXd constant_, slope_, memory_, memory_rate_, start_;
  Eigen::VectorXd start_state_;  // the trajectory at s = 0 (build's work vector)
  /// R p₂ and R p₃ of a singular phase's polynomial (empty otherwise).
  Eigen::VectorXd quadratic_, cubic_;
  Eigen::VectorXcd harmonic_;
  // γ = R V diag(c) (modal path) summed by pairs: γ_k + conj(γ_{k+1}) for a pair (k, k+1), γ_k for a real mode, over the phase's kept modes:
  // Re(γ_k e^{λs}) + Re(γ_{k+1} e^{λ̄s}) = Re((γ_k + γ̄_{k+1}) e^{λs}) exactly, half the terms
  // (columns beyond the kept count unused).
  Eigen::MatrixXcd kept_modal_;
  // |γ_jk|, |λ_k|, |H_j| of the segment: the derivative bounds ask for them at every interval.
  Eigen::MatrixXd modal_size_;
  Eigen::VectorXd harmonic_size_;
  static constexpr int kBoundOrders = GuardRows::kBoundOrders;
  const Eigen::MatrixXd* rate_powers_ = nullptr;  // the phase's |λ_k|^p (GuardRows)
  Eigen::VectorXd coefficient_size_;              // |c_k|
  Eigen::MatrixXd rows_;              // R (matrix-exponential path)
  Eigen::VectorXd row_norm_;
  Eigen::VectorXd balanced_row_norm_;  // ‖r_j D‖, D the phase's balancing (derivative bounds)
  double balanced_start_norm_ = 0.0;   // ‖D⁻¹ h₀‖
  struct Remembered {
    double s = std::numeric_limits<double>::quiet_NaN(), value = 0.0, rate = 0.0;
  };
  mutable std::vector<std::array<Remembered, 2>> remembered_;
  // e^{Re λ_k s} at the end of [a, b] where it is largest, for the derivative bounds: every guard's
  // search starts on the same interval and asks the bounds of orders 2 and 4 there.
  mutable double growth_a_ = std::numeric_limits<double>::quiet_NaN();
  mutable double growth_b_ = std::numeric_limits<double>::quiet_NaN();
  mutable Eigen::VectorXd growth_;
  void update_growth(double a, double b) const;
  // The phase's slow modes (ExactPhase::slow_modes) summed as γ(e^{λs} − 1), their constants in
  // constant_; their round-off margin grows with s (in slope_).
  bool slow_ = false;
  void add_slow_constant(const ExactTrajectory& trajectory, const Eigen::MatrixXd& rows);
  /// Σ|γ_jk| of the other modes, and Σ|γ_jk λ_k| of the slow ones.
  [[nodiscard]] std::pair<double, double> slow_sizes(Eigen::Index j) const;
  [[nodiscard]] std::pair<double, double> slow_modal_sum(int j, double s) const;
  [[nodiscard]] std::pair<double, double> compute(int j, double s) const;
};

/// The first upward crossing of any active guard in (a, b]: guard j, and a bracket [lo, hi] of
/// width ≤ resolution with g_j(lo) ≤ 0 < g_j(hi).
struct Crossing {
  int guard = -1;
  double lo = 0.0, hi = 0.0;
};

/// Every active guard must be ≤ 0 at a. Returns nothing when no guard crosses in (a, b].
/// resolution ≥ (b − a)·2⁻⁶⁰ (the simulator's 16 ulps of the time are far coarser): the search keeps
/// a fixed stack of that depth, and throws SimulationError if asked to go deeper. Allocation-free.
std::optional<Crossing> first_crossing(const GuardExpansion& guards, double a, double b,
                                       double resolution);

}  // namespace poundsim
