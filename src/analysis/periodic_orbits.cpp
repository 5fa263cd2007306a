#include "poundsim/analysis/periodic_orbits.hpp"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <initializer_list>
#include <optional>
#include <cmath>
#include <limits>
#include <numbers>
#include <variant>
#include <stdexcept>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "poundsim/analysis/parallel.hpp"
#include "poundsim/error.hpp"

namespace poundsim {

std::string_view to_string(BifurcationKind kind) {
  switch (kind) {
    case BifurcationKind::none: return "";
    case BifurcationKind::fold: return "fold";
    case BifurcationKind::period_doubling: return "period-doubling";
    case BifurcationKind::neimark_sacker: return "Neimark-Sacker";
    case BifurcationKind::grazing: return "grazing";
    case BifurcationKind::end: return "end";
  }
  return "?";
}

void ShootingOptions::validate() const {
  if (const auto violation = first_violation(*this)) throw std::invalid_argument(*violation);
}

std::string periodic_orbits_refusal(const Model& model, const TimeHistoryOptions& options) {
  if (options.separation == SeparationCriterion::force) {
    return "periodic orbits need separation = \"displacement\": under the force criterion a separated "
           "element's free end relaxes with a memory that the floors' state does not hold";
  }
  const DofLayout layout(model);
  std::string why;
  for (const Link& link : make_links(model, layout)) {
    std::visit(
        [&](const auto& law) {
          using L = std::decay_t<decltype(law)>;
          if constexpr (!ContactLaw<L> && !std::is_same_v<typename L::State, NoState>) {
            if (why.empty()) {
              why = fmt::format("periodic orbits need elastic storeys: {} keeps a state between events (its "
                                "plastic drift) that the floors' state does not hold",
                                describe(link, layout));
            }
          }
        },
        link.law);
  }
  return why;
}

void ContinuationOptions::validate() const {
  if (const auto violation = first_violation(*this)) throw std::invalid_argument(*violation);
  if (min_step > initial_step) throw std::invalid_argument("min_step must not exceed initial_step");
  if (initial_step > max_step) throw std::invalid_argument("initial_step must not exceed max_step");
}

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

/// The state x of a run is [u; u̇]; the laws' States are not in it: refuse the laws that keep one.
void refuse_remembering_laws(const Model& model, const TimeHistoryOptions& options) {
  if (std::string why = periodic_orbits_refusal(model, options); !why.empty()) throw std::invalid_argument(why);
}

/// Scaling of the state: w = D x, D = diag(1/L, 1/(ω̄L)).
struct Scaling {
  double length, omega;
  [[nodiscard]] Eigen::VectorXd to_scaled(const Eigen::VectorXd& x) const {
    const Eigen::Index n = x.size() / 2;
    Eigen::VectorXd w(x.size());
    w.head(n) = x.head(n) / length;
    w.tail(n) = x.tail(n) / (omega * length);
    return w;
  }
  [[nodiscard]] Eigen::VectorXd to_state(const Eigen::VectorXd& w) const {
    const Eigen::Index n = w.size() / 2;
    Eigen::VectorXd x(w.size());
    x.head(n) = w.head(n) * length;
    x.tail(n) = w.tail(n) * (omega * length);
    return x;
  }
  /// D J D⁻¹.
  [[nodiscard]] Eigen::MatrixXd jacobian(const Eigen::MatrixXd& j) const {
    const Eigen::Index n = j.rows() / 2;
    Eigen::MatrixXd out = j;
    out.block(0, n, n, n) *= omega;
    out.block(n, 0, n, n) /= omega;
    return out;
  }
};

Eigen::VectorXcd sorted_multipliers(const Eigen::MatrixXd& monodromy) {
  Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(monodromy, false).eigenvalues();
  std::vector<std::complex<double>> values(mu.data(), mu.data() + mu.size());
  std::stable_sort(values.begin(), values.end(), [](auto a, auto b) {
    if (std::abs(a) != std::abs(b)) return std::abs(a) > std::abs(b);
    if (a.real() != b.real()) return a.real() > b.real();
    return a.imag() > b.imag();
  });
  for (std::size_t i = 0; i < values.size(); ++i) mu(static_cast<Eigen::Index>(i)) = values[i];
  return mu;
}

/// Fills what the run from x tells about the orbit through x.
void describe_run(const StroboscopicMap& map, const Eigen::VectorXd& x, const Eigen::MatrixXd& monodromy,
                  PeriodicOrbit& orbit) {
  const Eigen::Index n = map.dofs();
  orbit.omega = map.omega();
  orbit.u = x.head(n);
  orbit.v = x.tail(n);
  orbit.monodromy = monodromy;
  orbit.multipliers = sorted_multipliers(monodromy);
  orbit.stable = orbit.largest_multiplier() < 1.0;
  const Simulator& sim = map.simulator();
  orbit.events = sim.statistics().events;
  orbit.impacts = 0;
  for (const GapResponse& g : sim.statistics().gaps) orbit.impacts += g.impacts;
  orbit.transversality = sim.least_transversality();
}

/// The orbit's peaks: its period run once more, recording them (the Newton iterations skip them).
void record_amplitudes(StroboscopicMap& map, PeriodicOrbit& orbit) {
  Eigen::VectorXd x(2 * map.dofs());
  x << orbit.u, orbit.v;
  map.evaluate(x, orbit.periodicity, nullptr, StroboscopicMap::Responses::record);
  orbit.amplitudes = run_amplitudes(map.simulator());
}

}  // namespace

StroboscopicMap::StroboscopicMap(const Model& model, double amplitude, double omega, TimeHistoryOptions options,
                                 int samples_per_period)
    : model_(model), amplitude_(amplitude), omega_(omega), options_(options), samples_(samples_per_period) {
  validate(model_);
  refuse_remembering_laws(model_, options_);
  options_.integrator = Integrator::exact;
  options_.dt = kTwoPi / omega_ / samples_;
  dofs_ = DofLayout(model_).size();
  sim_ = std::make_unique<Simulator>(model_, HarmonicExcitation{amplitude_, omega_}, options_);
  sim_->track_sensitivity();
  sim_->meter_energy(false);
}

StroboscopicMap::~StroboscopicMap() = default;

void StroboscopicMap::set_omega(double omega) {
  if (omega == omega_) return;
  omega_ = omega;
  options_.dt = kTwoPi / omega_ / samples_;
  // A run that failed has no state to restart from: start it at rest first.
  sim_->reset_state(Eigen::VectorXd::Zero(dofs_), Eigen::VectorXd::Zero(dofs_));
  sim_->restart(HarmonicExcitation{amplitude_, omega_}, options_.dt);
}

Eigen::VectorXd StroboscopicMap::evaluate(const Eigen::VectorXd& x, int k, Eigen::MatrixXd* jacobian,
                                          Responses responses, Eigen::VectorXd* frequency_derivative) {
  if (frequency_derivative != nullptr && jacobian == nullptr) {
    throw std::invalid_argument("StroboscopicMap::evaluate: ∂P/∂ω̄ comes with the monodromy");
  }
  sim_->track_sensitivity(jacobian != nullptr);
  if (jacobian != nullptr) sim_->track_frequency_sensitivity(frequency_derivative != nullptr);
  sim_->record_responses(responses == Responses::record);
  // A run cannot start with a pair pressed past its stop, yet an orbit whose section finds a pair
  // on its stop (touching at rest, δ = 0, or pressed together) is reached by Newton's iterates
  // from both sides. The map is taken at the state put back on the stop (each floor of the pair
  // moved half the excess): continuous, the identity where no pair is past its stop, and its
  // derivative I − ½ n nᵀ composed into the monodromy where one is.
  start_ = x;
  bool projected = false;
  if (jacobian != nullptr) projection_.setIdentity(2 * dofs_, 2 * dofs_);
  for (const Link& link : sim_->system().contact_links()) {
    if (!link.joins_floors() || link.b < 0) continue;
    std::visit(
        [&](const auto& law) {
          using L = std::decay_t<decltype(law)>;
          if constexpr (ContactLaw<L>) {
            if (!law.traits.has_stop) return;
            const double past = start_(link.a) - start_(link.b) - law.locked_length();
            if (!(past > 0)) return;
            start_(link.a) -= 0.5 * past;
            start_(link.b) += 0.5 * past;
            // The halves may leave an ulp of the excess.
            while (start_(link.a) - start_(link.b) - law.locked_length() > 0) {
              start_(link.b) = std::nextafter(start_(link.b), std::numeric_limits<double>::infinity());
            }
            projected = true;
            if (jacobian != nullptr) {
              Eigen::RowVectorXd difference = projection_.row(link.a) - projection_.row(link.b);
              projection_.row(link.a) -= 0.5 * difference;
              projection_.row(link.b) += 0.5 * difference;
            }
          }
        },
        link.law);
  }
  sim_->reset_state(start_.head(dofs_), start_.tail(dofs_));
  const double period = k * kTwoPi / omega_;
  sim_->advance_to(period);
  Eigen::VectorXd out(2 * dofs_);
  out << sim_->state().u, sim_->state().v;
  if (jacobian != nullptr) {
    if (projected) {
      *jacobian = sim_->sensitivity() * projection_;
    } else {
      *jacobian = sim_->sensitivity();
    }
  }
  if (frequency_derivative != nullptr) {
    // P^k(x; ω̄) = x(kT; ω̄) with T = 2π/ω̄: dP/dω̄ = ∂x/∂ω̄ + ẋ(kT)·d(kT)/dω̄, d(kT)/dω̄ = −kT/ω̄.
    const double shortening = period / omega_;
    *frequency_derivative = sim_->frequency_sensitivity();
    frequency_derivative->head(dofs_) -= shortening * sim_->state().v;
    frequency_derivative->tail(dofs_) -= shortening * sim_->state().a;
  }
  return out;
}

Eigen::VectorXd linear_steady_state(const Model& model, double amplitude, double omega) {
  const DofLayout layout(model);
  const Eigen::Index n = layout.size();
  Eigen::VectorXd x(2 * n);
  for (int f = 0; f < model.frame_count(); ++f) {
    const Eigen::VectorXcd u = harmonic_amplitudes(model.frames[static_cast<std::size_t>(f)], amplitude, omega);
    for (int i = 0; i < layout.storeys(f); ++i) {
      // u(t) = Im(U e^{iω̄t}): u(0) = Im U, u̇(0) = ω̄ Re U.
      x(layout.dof(f, i)) = u(i).imag();
      x(n + layout.dof(f, i)) = omega * u(i).real();
    }
  }
  return x;
}

Eigen::VectorXd settled_state(StroboscopicMap& map, const Eigen::VectorXd& x0, int periods) {
  Eigen::VectorXd x = x0;
  for (int i = 0; i < periods; ++i) x = map.evaluate(x, 1);
  return x;
}

namespace {

double state_length(const Model& model, double amplitude) {
  const double omega1 = reference_frequency(model);
  return std::abs(amplitude) / (omega1 * omega1);
}

}  // namespace

// A branch followed as period k — a doubled branch that met its parent again, a seed detected
// at a multiple — may hold orbits that repeat sooner: their values and stability are right,
// their label is the least j.
int minimal_period(StroboscopicMap& map, const PeriodicOrbit& orbit, double tolerance) {
  const int k = orbit.periodicity;
  if (k < 2 || orbit.u.size() == 0) return k;
  Eigen::VectorXd x(orbit.u.size() + orbit.v.size());
  x << orbit.u, orbit.v;
  const Scaling s{state_length(map.model(), map.amplitude()), map.omega()};
  const Eigen::VectorXd w = s.to_scaled(x);
  const double bound = tolerance * std::max(1.0, w.cwiseAbs().maxCoeff());
  for (int j = 1; j < k; ++j) {
    if (k % j != 0) continue;
    Eigen::VectorXd image;
    try {
      image = map.evaluate(x, j);
    } catch (const std::exception&) {
      continue;  // a run that cannot be made says nothing against period k
    }
    if ((s.to_scaled(image) - w).cwiseAbs().maxCoeff() <= bound) return j;
  }
  return k;
}

ShootingResult shoot(StroboscopicMap& map, const Eigen::VectorXd& x0, int k, const ShootingOptions& options) {
  ShootingResult result;
  PeriodicOrbit& orbit = result.orbit;
  orbit.periodicity = k;
  const Scaling scaling{state_length(map.model(), map.amplitude()), map.omega()};
  Eigen::VectorXd x = x0, previous = x0;
  Eigen::MatrixXd monodromy;
  const Eigen::Index size = x.size();
  for (int iteration = 0;; ++iteration) {
    Eigen::VectorXd image;
    // An iterate that cannot start (an element pressed past its stop) or run is brought back
    // towards the last one that could.
    for (int backtrack = 0;; ++backtrack) {
      try {
        image = map.evaluate(x, k, &monodromy);
        break;
      } catch (const std::exception& e) {
        if (iteration == 0 || backtrack >= 20) {
          result.failure = fmt::format("the run from Newton's iterate {} failed: {}", iteration, e.what());
          return result;
        }
        x = previous + 0.5 * (x - previous);
      }
    }
    previous = x;
    const Eigen::VectorXd w = scaling.to_scaled(x);
    const Eigen::VectorXd residual = scaling.to_scaled(image) - w;
    orbit.iterations = iteration;
    orbit.residual = residual.cwiseAbs().maxCoeff();
    describe_run(map, x, monodromy, orbit);
    if (orbit.residual <= options.tolerance * std::max(1.0, w.cwiseAbs().maxCoeff())) {
      result.converged = true;
      record_amplitudes(map, orbit);
      return result;
    }
    if (iteration >= options.max_iterations) {
      result.failure = fmt::format("no convergence in {} Newton iterations (residual {:.3g})", iteration, orbit.residual);
      return result;
    }
    const Eigen::MatrixXd jacobian = scaling.jacobian(monodromy) - Eigen::MatrixXd::Identity(size, size);
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(jacobian);
    const Eigen::VectorXd step = lu.solve(-residual);
    if (!step.allFinite()) {
      result.failure = "the Newton matrix is singular (a multiplier at +1: a fold)";
      return result;
    }
    x = scaling.to_state(w + step);
  }
}

// ---- families ------------------------------------------------------------------------------

FrequencyFamily::FrequencyFamily(const Model& model, double amplitude, const TimeHistoryOptions& options,
                                 int samples_per_period)
    : omega1_(reference_frequency(model)),
      length_(state_length(model, amplitude)),
      map_(model, amplitude, omega1_, options, samples_per_period),
      difference_(model, amplitude, omega1_, options, samples_per_period) {}

StroboscopicMap& FrequencyFamily::at(double ratio) {
  if (!(ratio > 0)) throw std::invalid_argument(fmt::format("the frequency ratio {} is not positive", ratio));
  map_.set_omega(ratio * omega1_);
  return map_;
}

StroboscopicMap& FrequencyFamily::difference_at(double ratio) {
  if (!(ratio > 0)) throw std::invalid_argument(fmt::format("the frequency ratio {} is not positive", ratio));
  difference_.set_omega(ratio * omega1_);
  return difference_;
}

ParameterFamily::ParameterFamily(std::function<Model(double)> model_at, double amplitude, double ratio,
                                 const TimeHistoryOptions& options, int samples_per_period)
    : model_at_(std::move(model_at)), amplitude_(amplitude), ratio_(ratio), options_(options),
      samples_(samples_per_period) {}

StroboscopicMap& ParameterFamily::at(double p) {
  if (!map_ || map_p_ != p) {
    const Model model = model_at_(p);
    map_ = std::make_unique<StroboscopicMap>(model, amplitude_, ratio_ * reference_frequency(model), options_, samples_);
    map_p_ = p;
    if (length_ == 0.0) length_ = state_length(model, amplitude_);
  }
  return *map_;
}

StroboscopicMap& ParameterFamily::difference_at(double p) {
  if (!difference_ || difference_p_ != p) {
    const Model model = model_at_(p);
    difference_ = std::make_unique<StroboscopicMap>(model, amplitude_, ratio_ * reference_frequency(model), options_,
                                                    samples_);
    difference_p_ = p;
  }
  return *difference_;
}

// ---- continuation --------------------------------------------------------------------------

namespace {

/// The fixed tuning of continue_orbits: its step control, its restarts, and its tests for a
/// branch that stalls, closes on itself or comes back to the doubling it was born at. Not input
/// keys: the continuation's options (ContinuationOptions) set its scales, these the ratios to them.
struct ContinuationTuning {
  /// Two section states are the same point (of a doubling, or of a crossing) within this
  /// fraction of the state's size (at least 1).
  static constexpr double same_state = 1e-3;
  /// A doubling is the one already switched at (or met) within this many max_parameter_step in p.
  static constexpr double same_doubling_steps = 2;
  /// With the exact F_p Newton converges quadratically: a corrector whose residual does not fall
  /// below this factor of the last one (after its first correction) is stopped.
  static constexpr double contraction_exact_fp = 0.5;
  /// With a chord F_p (a model parameter) Newton is only linear: only a residual that grows stops it.
  static constexpr double contraction_chord_fp = 1.0;
  /// The step after the corrector failed: retried this much shorter.
  static constexpr double failed_step_factor = 0.5;
  /// Newton converged in at most this many iterations: the next step is longer by step_growth.
  static constexpr int fast_iterations = 3;
  static constexpr double step_growth = 1.5;
  /// Newton needed at least this many iterations: the next step is shorter by slow_step_factor.
  static constexpr int slow_iterations = 6;
  static constexpr double slow_step_factor = 0.5;
  /// A period-2k orbit whose max |P^k(w) − w| (scaled) is below this is a period-k orbit: the
  /// branch came back to the one it doubled from.
  static constexpr double met_difference = 1e-6;
  /// Across that crossing |D| before + |D| after is at most this many chords of the step.
  static constexpr double met_chord_factor = 3;
  /// A branch comes back to its first point (an isola) only after going farther from it than
  /// this many times the last step.
  static constexpr double isola_reach_steps = 4;
  /// A branch stalls when the point this many points back is within stall_parameter_fraction ×
  /// max_parameter_step in p and within stall_points × min_step × stall_state_margin in the state.
  static constexpr std::size_t stall_points = 50;
  static constexpr double stall_parameter_fraction = 0.01;
  static constexpr double stall_state_margin = 10;
  /// Restarts of one branch across points the corrector cannot pass.
  static constexpr int max_restarts = 20;
};

/// F(w, p) = D P^k(D⁻¹w; p) − w with its derivatives, for one branch.
class BranchProblem {
 public:
  BranchProblem(OrbitFamily& family, int k, const ContinuationOptions& options, ContinuationResult& counts)
      : family_(family), k_(k), options_(options), counts_(counts) {}

  [[nodiscard]] Scaling scaling(StroboscopicMap& map) const { return {family_.length_scale(), map.omega()}; }

  /// F, ∂F/∂w and ∂F/∂p at (w, p); the orbit described from the run. False when a run failed.
  /// In the forcing frequency ∂F/∂p comes with the run, exact; in a model parameter it is a
  /// forward difference, and `with_fp` false keeps fp as it is (a chord: one run fewer, but
  /// Newton then converges only linearly).
  bool evaluate(const Eigen::VectorXd& w, double p, Eigen::VectorXd& f, Eigen::MatrixXd& fw, Eigen::VectorXd& fp,
                PeriodicOrbit& orbit, std::string& failure, bool with_fp = true) {
    if (!std::isfinite(p) || !w.allFinite()) {
      failure = fmt::format("the corrector left the admissible states (parameter {})", p);
      return false;
    }
    try {
      StroboscopicMap& map = family_.at(p);
      const Scaling s = scaling(map);
      const Eigen::VectorXd x = s.to_state(w);
      Eigen::MatrixXd monodromy;
      const std::optional<double> frequency_rate = family_.frequency_rate();
      Eigen::VectorXd frequency_derivative;
      const Eigen::VectorXd image = map.evaluate(x, k_, &monodromy, StroboscopicMap::Responses::skip,
                                                 frequency_rate ? &frequency_derivative : nullptr);
      ++counts_.map_evaluations;
      f = s.to_scaled(image) - w;
      fw = s.jacobian(monodromy) - Eigen::MatrixXd::Identity(w.size(), w.size());
      orbit.parameter = p;
      orbit.periodicity = k_;
      describe_run(map, x, monodromy, orbit);
      counts_.events += orbit.events;
      if (frequency_rate) {
        // F = S(P(S⁻¹w; ω̄)) − w with S = diag(1/L, 1/(ω̄L)): dF/dω̄ = S(∂P/∂ω̄ + M ∂(S⁻¹w)/∂ω̄) + (dS/dω̄) P,
        // ∂(S⁻¹w)/∂ω̄ = [0; u̇/ω̄], (dS/dω̄) P = [0; −P_u̇/(ω̄²L)].
        const Eigen::Index n = map.dofs();
        const double omega = map.omega();
        Eigen::VectorXd moved = Eigen::VectorXd::Zero(2 * n);
        moved.tail(n) = x.tail(n) / omega;
        fp = s.to_scaled(frequency_derivative + monodromy * moved);
        fp.tail(n) -= image.tail(n) / (omega * omega * s.length);
        fp *= *frequency_rate;
        return true;
      }
      if (!with_fp) return true;
      const double dp = options_.difference_step * std::max(1.0, std::abs(p));
      StroboscopicMap& shifted = family_.difference_at(p + dp);
      const Scaling s2 = scaling(shifted);
      const Eigen::VectorXd image2 = shifted.evaluate(s2.to_state(w), k_);
      ++counts_.map_evaluations;
      fp = ((s2.to_scaled(image2) - w) - f) / dp;
      return true;
    } catch (const std::exception& e) {
      failure = e.what();
      return false;
    }
  }

 private:
  OrbitFamily& family_;
  int k_;
  const ContinuationOptions& options_;
  ContinuationResult& counts_;
};

/// The unit tangent of the branch: null vector of [F_w F_p], oriented along `previous`.
Eigen::VectorXd branch_tangent(const Eigen::MatrixXd& fw, const Eigen::VectorXd& fp, const Eigen::VectorXd& previous) {
  const Eigen::Index m = fw.rows();
  Eigen::MatrixXd a(m + 1, m + 1);
  a.topLeftCorner(m, m) = fw;
  a.topRightCorner(m, 1) = fp;
  a.bottomRows(1) = previous.transpose();
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m + 1);
  rhs(m) = 1.0;
  Eigen::VectorXd t = a.partialPivLu().solve(rhs);
  t.normalize();
  if (t.dot(previous) < 0) t = -t;
  return t;
}

int real_below_minus_one(const Eigen::VectorXcd& mu) {
  int count = 0;
  for (const auto& m : mu) {
    if (std::abs(m.imag()) <= 1e-9 * std::abs(m) && m.real() < -1.0) ++count;
  }
  return count;
}
int real_above_one(const Eigen::VectorXcd& mu) {
  int count = 0;
  for (const auto& m : mu) {
    if (std::abs(m.imag()) <= 1e-9 * std::abs(m) && m.real() > 1.0) ++count;
  }
  return count;
}
int complex_outside(const Eigen::VectorXcd& mu) {
  int count = 0;
  for (const auto& m : mu) {
    if (std::abs(m.imag()) > 1e-9 * std::abs(m) && std::abs(m) > 1.0) ++count;
  }
  return count;
}

/// A branch waiting to be followed: from `start` in the direction of `direction` in p (or along
/// `tangent` when given), or — `doubling` — the period-2k branch born at the period doubling
/// `start` of a period-k branch, switched to when its turn comes.
struct PendingBranch {
  PeriodicOrbit start;
  int parent;
  int direction;
  Eigen::VectorXd tangent;  ///< orientation of the first tangent in (w, p); empty: `direction`
  bool doubling = false;
  bool located = false;     ///< a doubling's `start` is the located doubling (else an orbit beside it)
  PeriodicOrbit unstable;   ///< a doubling's period-k orbit on its unstable side (the fallback's start)
};

/// The pseudo-arclength corrector: Newton's method on F(w, p) = 0 with tangent · (z − predicted) = 0
/// from `predicted` (a step of length `step` from a point at parameter `from`). True when it
/// converged no further than two max_parameter_step from `from` in the parameter (beyond, it
/// landed on another branch); `trial`, `orbit`, f, fw, fp are then the corrected point's.
bool corrected(BranchProblem& problem, const Eigen::VectorXd& predicted, const Eigen::VectorXd& tangent, double step,
               double from, double contraction, const ShootingOptions& shooting, const ContinuationOptions& options,
               ContinuationResult& result, Eigen::VectorXd& trial, PeriodicOrbit& orbit, Eigen::VectorXd& f,
               Eigen::MatrixXd& fw, Eigen::VectorXd& fp, int& iterations, std::string& failure) {
  const Eigen::Index m = predicted.size() - 1;
  trial = predicted;
  bool converged = false;
  iterations = 0;
  double last_residual = std::numeric_limits<double>::infinity();
  for (; iterations < options.newton_iterations; ++iterations) {
    ++result.newton_iterations;
    if (!problem.evaluate(trial.head(m), trial(m), f, fw, fp, orbit, failure, iterations == 0)) break;
    const double arclength = tangent.dot(trial - predicted);
    const double residual = f.cwiseAbs().maxCoeff();
    if (residual <= shooting.tolerance * std::max(1.0, trial.head(m).cwiseAbs().maxCoeff()) &&
        std::abs(arclength) <= 1e-6 * step) {
      // A corrector that ran far along the parameter landed on another branch: a smaller step.
      converged = std::abs(trial(m) - from) <= 2 * options.max_parameter_step;
      break;
    }
    // With the exact F_w and F_p Newton converges quadratically once near the branch; a
    // corrector that does not halve the residual after its first correction is cycling or
    // diverging (the map is not smooth between predictor and branch: a grazing, a lock), and
    // its remaining iterations were half of all the runs (Fig. 3a): halve the step instead.
    // A model parameter's F_p is a chord and Newton only linear: there, only a residual that
    // grows stops it.
    if (iterations >= 2 && residual > contraction * last_residual) break;
    last_residual = residual;
    Eigen::MatrixXd a(m + 1, m + 1);
    a.topLeftCorner(m, m) = fw;
    a.topRightCorner(m, 1) = fp;
    a.bottomRows(1) = tangent.transpose();
    Eigen::VectorXd rhs(m + 1);
    rhs << -f, -arclength;
    const Eigen::VectorXd delta = a.partialPivLu().solve(rhs);
    if (!delta.allFinite()) break;
    trial += delta;
  }
  return converged;
}

/// The scaled state of an orbit at its parameter.
Eigen::VectorXd scaled_state(OrbitFamily& family, const PeriodicOrbit& orbit) {
  Eigen::VectorXd x(2 * orbit.u.size());
  x << orbit.u, orbit.v;
  return Scaling{family.length_scale(), family.at(orbit.parameter).omega()}.to_scaled(x);
}

/// P^j(w) − w in the scaled state for the orbit (j periods run); none when the run fails.
std::optional<Eigen::VectorXd> return_difference(OrbitFamily& family, const PeriodicOrbit& orbit, int j,
                                                 ContinuationResult& result) {
  StroboscopicMap& map = family.at(orbit.parameter);
  const Scaling s{family.length_scale(), map.omega()};
  Eigen::VectorXd x(2 * orbit.u.size());
  x << orbit.u, orbit.v;
  try {
    const Eigen::VectorXd image = map.evaluate(x, j);
    ++result.map_evaluations;
    return Eigen::VectorXd(s.to_scaled(image) - s.to_scaled(x));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// The first orbit of the period-2k branch born at the period doubling `at` of a period-k
/// branch (its multiplier at −1, eigenvector φ in the scaled state), and the orientation of its
/// tangent, away from the period-k branch. As fixed points of P^{2k} the two branches cross at
/// `at`, the period-2k one along (φ, 0): its first orbit is corrected from (w + hφ, p) by the
/// pseudo-arclength corrector with that tangent, in w and p together — so whichever side of the
/// doubling the branch lies on (super- or subcritical) — for h a hundredth of the state's size
/// (then smaller or larger). An orbit the corrector lands on that repeats every k periods is the
/// period-k branch again, not kept. None when no such orbit converges.
struct SwitchedBranch {
  PeriodicOrbit start;
  Eigen::VectorXd tangent;
};
std::optional<SwitchedBranch> switched_branch(OrbitFamily& family, const PeriodicOrbit& at,
                                              const ShootingOptions& shooting, const ContinuationOptions& options,
                                              ContinuationResult& result) {
  const int k = at.periodicity;
  if (at.monodromy.size() == 0) return std::nullopt;
  StroboscopicMap& map = family.at(at.parameter);
  const Scaling s{family.length_scale(), map.omega()};
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(s.jacobian(at.monodromy));
  Eigen::Index best = 0;
  for (Eigen::Index i = 1; i < eig.eigenvalues().size(); ++i) {
    if (std::abs(eig.eigenvalues()(i) + 1.0) < std::abs(eig.eigenvalues()(best) + 1.0)) best = i;
  }
  Eigen::VectorXd phi = eig.eigenvectors().col(best).real();
  if (!(phi.norm() > 0) || !phi.allFinite()) return std::nullopt;
  phi.normalize();
  Eigen::VectorXd x(2 * at.u.size());
  x << at.u, at.v;
  const Eigen::VectorXd w0 = s.to_scaled(x);
  const Eigen::Index m = w0.size();
  const double size = std::max(1.0, w0.cwiseAbs().maxCoeff());
  BranchProblem problem(family, 2 * k, options, result);
  const double contraction = family.frequency_rate() ? ContinuationTuning::contraction_exact_fp
                                                     : ContinuationTuning::contraction_chord_fp;
  Eigen::VectorXd tangent = Eigen::VectorXd::Zero(m + 1);
  tangent.head(m) = phi;
  for (const double h : {1e-2, 1e-3, 1e-1}) {
    if (result.map_evaluations >= options.max_evaluations || result.events >= options.max_events) break;
    Eigen::VectorXd predicted(m + 1);
    predicted << w0 + h * size * phi, at.parameter;
    Eigen::VectorXd trial, f, fp;
    Eigen::MatrixXd fw;
    PeriodicOrbit orbit;
    int iterations = 0;
    std::string failure;
    if (!corrected(problem, predicted, tangent, h * size, at.parameter, contraction, shooting, options, result, trial,
                   orbit, f, fw, fp, iterations, failure)) {
      continue;
    }
    // Not the period-k orbit again: P^k moves it by about 2h along φ.
    orbit.parameter = trial(m);
    const std::optional<Eigen::VectorXd> half = return_difference(family, orbit, k, result);
    if (!half || half->norm() < 0.5 * h * size) continue;
    orbit.iterations = iterations;
    orbit.residual = f.cwiseAbs().maxCoeff();
    const Eigen::VectorXd next = branch_tangent(fw, fp, tangent);
    if (!next.allFinite()) continue;
    return SwitchedBranch{std::move(orbit), next};
  }
  return std::nullopt;
}

/// A period-2k orbit near the period-k orbit `at`, along the eigenvector of its multiplier
/// nearest −1; nothing when Newton finds none distinct from the period-k orbit.
std::optional<PeriodicOrbit> doubled_orbit(OrbitFamily& family, const PeriodicOrbit& at, const ShootingOptions& shooting,
                                           ContinuationResult& counts) {
  StroboscopicMap& map = family.at(at.parameter);
  const Scaling s{family.length_scale(), map.omega()};
  const Eigen::MatrixXd jw = s.jacobian(at.monodromy);
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(jw);
  Eigen::Index best = 0;
  for (Eigen::Index i = 1; i < eig.eigenvalues().size(); ++i) {
    if (std::abs(eig.eigenvalues()(i) + 1.0) < std::abs(eig.eigenvalues()(best) + 1.0)) best = i;
  }
  Eigen::VectorXd direction = eig.eigenvectors().col(best).real();
  if (direction.norm() == 0) return std::nullopt;
  direction.normalize();
  Eigen::VectorXd x;
  x.resize(at.u.size() * 2);
  x << at.u, at.v;
  const Eigen::VectorXd w = s.to_scaled(x);
  for (const double size : {1e-2, 1e-1, 3e-1}) {
    for (const double sign : {1.0, -1.0}) {
      ShootingResult r = shoot(map, s.to_state(w + sign * size * direction), 2 * at.periodicity, shooting);
      counts.map_evaluations += r.orbit.iterations + 1;
      counts.newton_iterations += r.orbit.iterations;
      if (!r.converged) continue;
      Eigen::VectorXd xr(x.size());
      xr << r.orbit.u, r.orbit.v;
      const Eigen::VectorXd half = map.evaluate(xr, at.periodicity);
      ++counts.map_evaluations;
      if ((s.to_scaled(half) - s.to_scaled(xr)).cwiseAbs().maxCoeff() < 1e-6) continue;  // the period-k orbit again
      r.orbit.parameter = at.parameter;
      // The run above left the map with the half orbit: describe the whole one again.
      Eigen::MatrixXd monodromy;
      map.evaluate(xr, 2 * at.periodicity, &monodromy);
      ++counts.map_evaluations;
      describe_run(map, xr, monodromy, r.orbit);
      return r.orbit;
    }
  }
  return std::nullopt;
}

/// The test function of a bifurcation that changes the multipliers: 1 + μ for the real
/// multiplier nearest −1 (period doubling), |μ| − 1 for the complex one nearest the unit circle
/// (Neimark–Sacker).
double bifurcation_test(const PeriodicOrbit& orbit, BifurcationKind kind) {
  double best = std::numeric_limits<double>::infinity();
  double value = best;
  for (const auto& mu : orbit.multipliers) {
    const bool real = std::abs(mu.imag()) <= 1e-9 * std::abs(mu);
    if (kind == BifurcationKind::period_doubling && real && std::abs(mu.real() + 1) < best) {
      best = std::abs(mu.real() + 1);
      value = mu.real() + 1;
    }
    if (kind == BifurcationKind::neimark_sacker && !real && std::abs(std::abs(mu) - 1) < best) {
      best = std::abs(std::abs(mu) - 1);
      value = std::abs(mu) - 1;
    }
  }
  return value;
}

/// The orbit where the test function of `kind` vanishes between a and b (regula falsi, Illinois,
/// on orbits shot at fixed p from the interpolated state); nothing when it cannot be bracketed.
std::optional<PeriodicOrbit> refined_bifurcation(OrbitFamily& family, PeriodicOrbit a, PeriodicOrbit b,
                                                 BifurcationKind kind, const ShootingOptions& shooting,
                                                 ContinuationResult& counts) {
  double fa = bifurcation_test(a, kind), fb = bifurcation_test(b, kind);
  if (!std::isfinite(fa) || !std::isfinite(fb) || !(fa * fb < 0)) return std::nullopt;
  const auto state = [](const PeriodicOrbit& o) {
    Eigen::VectorXd x(2 * o.u.size());
    x << o.u, o.v;
    return x;
  };
  std::optional<PeriodicOrbit> best;
  int side = 0;
  for (int i = 0; i < 40 && std::abs(b.parameter - a.parameter) > 1e-11 * std::max(1.0, std::abs(a.parameter)); ++i) {
    const double t = fa / (fa - fb);
    const double p = a.parameter + t * (b.parameter - a.parameter);
    ShootingResult r;
    try {
      r = shoot(family.at(p), state(a) + t * (state(b) - state(a)), a.periodicity, shooting);
    } catch (const std::exception&) {
      break;  // a run that cannot start: keep the best located so far
    }
    counts.map_evaluations += r.orbit.iterations + 1;
    counts.newton_iterations += r.orbit.iterations;
    if (!r.converged) break;
    r.orbit.parameter = p;
    const double fc = bifurcation_test(r.orbit, kind);
    best = r.orbit;
    if (fc == 0) break;
    if (fc * fa < 0) {
      b = r.orbit;
      fb = fc;
      if (side == -1) fa /= 2;
      side = -1;
    } else {
      a = r.orbit;
      fa = fc;
      if (side == 1) fb /= 2;
      side = 1;
    }
  }
  if (best) best->bifurcation = kind;
  return best;
}

/// The period-k orbit at p shot from x, its parameter set, its runs charged to `result`; none when
/// Newton does not converge or a run fails.
std::optional<PeriodicOrbit> shot_at(OrbitFamily& family, double p, const Eigen::VectorXd& x, int k,
                                     const ShootingOptions& shooting, ContinuationResult& result) {
  ShootingResult shot;
  try {
    shot = shoot(family.at(p), x, k, shooting);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  result.map_evaluations += shot.orbit.iterations + 2;  // Newton's runs and the recorded period
  result.newton_iterations += shot.orbit.iterations;
  if (!shot.converged) return std::nullopt;
  shot.orbit.parameter = p;
  return std::move(shot.orbit);
}


/// The branch beyond a point where the corrector failed at the smallest step: the orbit one
/// parameter step (max_parameter_step, onward along the tangent) past `last`, shot from its
/// state, kept when it lies near it (scaled distance ≤ 0.1 × the state's size: the same branch,
/// not a coexisting one) — with its scaled state and the branch's tangent there.
bool restart_across(OrbitFamily& family, BranchProblem& problem, const PeriodicOrbit& last,
                    const Eigen::VectorXd& tangent, const ShootingOptions& shooting, const ContinuationOptions& options,
                    ContinuationResult& result, PeriodicOrbit& beyond, Eigen::VectorXd& w, Eigen::VectorXd& next_tangent) {
  const Eigen::Index m = tangent.size() - 1;
  if (tangent(m) == 0) return false;  // no onward direction in p
  const double p = last.parameter + std::copysign(options.max_parameter_step, tangent(m));
  Eigen::VectorXd x(2 * last.u.size());
  x << last.u, last.v;
  const std::optional<PeriodicOrbit> shot = shot_at(family, p, x, last.periodicity, shooting, result);
  if (!shot) return false;
  const Scaling s{family.length_scale(), family.at(p).omega()};
  Eigen::VectorXd landed(x.size());
  landed << shot->u, shot->v;
  const Eigen::VectorXd w_last = s.to_scaled(x);
  w = s.to_scaled(landed);
  if ((w - w_last).cwiseAbs().maxCoeff() > 0.1 * std::max(1.0, w_last.cwiseAbs().maxCoeff())) return false;
  Eigen::VectorXd f, fp;
  Eigen::MatrixXd fw;
  std::string failure;
  if (!problem.evaluate(w, p, f, fw, fp, beyond, failure)) return false;
  beyond.iterations = shot->iterations;
  beyond.residual = f.cwiseAbs().maxCoeff();
  beyond.amplitudes = shot->amplitudes;
  next_tangent = branch_tangent(fw, fp, tangent);
  return next_tangent.allFinite();
}

/// The orbit at p = edge of a branch whose last step went from `inside` to `outside` past it:
/// shot at the edge from the state interpolated between the two (none when Newton fails there).
std::optional<PeriodicOrbit> orbit_at_edge(OrbitFamily& family, const PeriodicOrbit& inside,
                                           const PeriodicOrbit& outside, double edge,
                                           const ShootingOptions& shooting, ContinuationResult& result) {
  if (inside.parameter == edge) return std::nullopt;  // the branch already has its edge point
  const double t = (edge - inside.parameter) / (outside.parameter - inside.parameter);
  Eigen::VectorXd x(2 * inside.u.size());
  x << inside.u + t * (outside.u - inside.u), inside.v + t * (outside.v - inside.v);
  std::optional<PeriodicOrbit> shot = shot_at(family, edge, x, inside.periodicity, shooting, result);
  if (!shot) return std::nullopt;  // the branch ends at its last point inside
  // Newton may land on a coexisting orbit: keep only one as near as the branch's step.
  Eigen::VectorXd step(x.size()), landed(x.size());
  step << outside.u - inside.u, outside.v - inside.v;
  landed << shot->u, shot->v;
  if ((landed - x).cwiseAbs().maxCoeff() > 2 * step.cwiseAbs().maxCoeff()) return std::nullopt;
  return shot;
}

/// The doubling a period-2k branch was switched at: not switched at again.
struct Doubling {
  double parameter;
  Eigen::VectorXd w;
  int periodicity;  ///< k of the period-k branch
};

/// Where a period-2k branch crossed the period-k one (came back to a doubling): a doubling there
/// is not switched at again.
struct Meeting {
  double parameter;   ///< the period-2k branch's last point before the crossing
  Eigen::VectorXd w;  ///< the crossing, estimated from the points either side
  double radius;      ///< the estimate's uncertainty
  int periodicity;    ///< 2k
};

/// What the branches of one continue_orbits call share: its inputs, the counts and branches it
/// returns, the branches still to follow, and the doublings switched at and crossings met.
struct Tracing {
  OrbitFamily& family;
  const ShootingOptions& shooting;
  const ContinuationOptions& options;
  double p_min;
  double p_max;
  ContinuationResult result;
  std::vector<PendingBranch> pending;
  std::vector<Doubling> switched;
  std::vector<Meeting> meetings;

  /// True when the runs or their events reached the budget: nothing more is followed.
  [[nodiscard]] bool budget_spent() const {
    return result.map_evaluations >= options.max_evaluations || result.events >= options.max_events;
  }
};

/// The k scaled states on the section of a period-k orbit (its state and the k − 1 it runs
/// through): a branch followed as period k may hold any of them, so the same doubling reached
/// along two branches may be at two of its states.
std::vector<Eigen::VectorXd> phases(Tracing& t, const PeriodicOrbit& orbit) {
  std::vector<Eigen::VectorXd> out{scaled_state(t.family, orbit)};
  StroboscopicMap& map = t.family.at(orbit.parameter);
  const Scaling s{t.family.length_scale(), map.omega()};
  Eigen::VectorXd x(2 * orbit.u.size());
  x << orbit.u, orbit.v;
  for (int j = 1; j < orbit.periodicity; ++j) {
    try {
      x = map.evaluate(x, 1);
    } catch (const std::exception&) {
      break;
    }
    ++t.result.map_evaluations;
    out.push_back(s.to_scaled(x));
  }
  return out;
}

/// True when the doubling `at` (its section states `states`) was already switched at, or a
/// period-2k branch came back to it: its period-2k branch is followed once only.
bool already_followed(const Tracing& t, const PeriodicOrbit& at, const std::vector<Eigen::VectorXd>& states) {
  using T = ContinuationTuning;
  const double size = std::max(1.0, states.front().cwiseAbs().maxCoeff());
  const double window = T::same_doubling_steps * t.options.max_parameter_step;
  for (const Eigen::VectorXd& w : states) {
    for (const Doubling& d : t.switched) {
      if (d.periodicity == at.periodicity && std::abs(d.parameter - at.parameter) <= window &&
          (d.w - w).cwiseAbs().maxCoeff() <= T::same_state * size) {
        return true;
      }
    }
    for (const Meeting& meeting : t.meetings) {
      if (meeting.periodicity == 2 * at.periodicity &&
          (meeting.w - w).norm() <= meeting.radius + T::same_state * size &&
          std::abs(at.parameter - meeting.parameter) <= window) {
        return true;
      }
    }
  }
  return false;
}

/// Turns the doubling job into the period-2k branch born at its doubling (located, else the
/// orbit beside it) and queues the same branch the other way; false when a branch already did or
/// came back there, the budget is spent, or no period-2k orbit could be started.
bool switched_to_doubled(Tracing& t, PendingBranch& job) {
  if (t.budget_spent()) return false;
  const std::vector<Eigen::VectorXd> states = phases(t, job.start);
  if (already_followed(t, job.start, states)) return false;
  t.switched.push_back({job.start.parameter, states.front(), job.start.periodicity});
  std::optional<SwitchedBranch> born;
  if (job.located) born = switched_branch(t.family, job.start, t.shooting, t.options, t.result);
  if (born) {
    job.start = std::move(born->start);
    job.tangent = std::move(born->tangent);
    // Back towards the doubling too: where the map is smooth the branch crosses the period-k
    // one at once and ends; where it is not (a grazing at the doubling), it may go on.
    t.pending.insert(t.pending.begin(),
                     PendingBranch{job.start, job.parent, job.direction, -job.tangent, false, false, {}});
  } else {
    // The corrector found no period-2k orbit near the doubling: shoot one at the unstable
    // side's parameter instead, and follow it both ways.
    std::optional<PeriodicOrbit> doubled;
    try {
      doubled = doubled_orbit(t.family, job.unstable, t.shooting, t.result);
    } catch (const std::exception&) {
      doubled.reset();
    }
    if (!doubled) return false;  // no period-2k orbit could be started: the branch is not followed
    job.start = *doubled;
    job.direction = 1;
    t.pending.insert(t.pending.begin(), PendingBranch{*doubled, job.parent, -1, {}, false, false, {}});
  }
  job.doubling = false;
  return true;
}

/// One branch followed by pseudo-arclength continuation from a pending job: its points so far
/// and the predictor-corrector's state (the last point, the tangent there, the step size).
class BranchWalk {
 public:
  BranchWalk(Tracing& t, const PendingBranch& job)
      : t_(t), k_(job.start.periodicity), problem_(t.family, k_, t.options, t.result) {
    branch_.id = static_cast<int>(t.result.branches.size());
    branch_.periodicity = k_;
    branch_.parent = job.parent;
  }

  /// The branch followed from the job until it ends, or has the most points a branch may have.
  Branch walked(const PendingBranch& job) {
    if (started(job)) {
      while (static_cast<int>(branch_.points.size()) < t_.options.max_points) {
        if (!advanced()) break;
      }
      if (branch_.ended.empty()) branch_.ended = "reached the most points of a branch";
    }
    return std::move(branch_);
  }

 private:
  bool started(const PendingBranch& job);
  bool advanced();
  bool went_on(const PeriodicOrbit& before, PeriodicOrbit& orbit, const Eigen::VectorXd& trial,
               const Eigen::VectorXd& next_tangent, int iterations);
  bool after_failed_corrector();
  bool restarted();
  void end_at_edge();
  void classify(const PeriodicOrbit& before, PeriodicOrbit& orbit, const Eigen::VectorXd& next_tangent) const;
  bool met_doubled_from(const PeriodicOrbit& before, PeriodicOrbit& orbit, const Eigen::VectorXd& trial);
  std::optional<PeriodicOrbit> located(const PeriodicOrbit& before, PeriodicOrbit& orbit);
  bool closed(const Eigen::VectorXd& trial, const Eigen::VectorXd& next_tangent);
  void adapt_step(bool grazed, int iterations);
  [[nodiscard]] bool stalled(const PeriodicOrbit& orbit) const;
  void queue_doubling(const PeriodicOrbit& before, const PeriodicOrbit& orbit,
                      const std::optional<PeriodicOrbit>& at);

  Tracing& t_;
  Branch branch_;
  int k_;  ///< the branch's periodicity
  BranchProblem problem_;
  // F, F_w, F_p at the last evaluation, and why the last run failed: kept from step to step,
  // as a corrector that fails without a run failing reports the last run that did.
  Eigen::VectorXd f_, fp_;
  Eigen::MatrixXd fw_;
  std::string failure_;
  Eigen::Index m_ = 0;    ///< the scaled state's size
  Eigen::VectorXd w_;     ///< the last point's scaled state
  double p_ = 0;          ///< the last point's parameter
  Eigen::VectorXd tangent_;  ///< the unit tangent in (w, p) at the last point
  double step_ = 0;       ///< the next step's arclength
  int restarts_ = 0;
  Eigen::VectorXd first_;          ///< the first point in (w, p): an isola comes back to it
  Eigen::VectorXd first_tangent_;  ///< the tangent there
  double contraction_ = 1;         ///< the corrector's factor (ContinuationTuning)
  double farthest_ = 0;            ///< the farthest the branch went from its first point
};

/// Takes the job's orbit as the first point, with the tangent from F_w, F_p there (oriented by
/// the job); false when its run fails or the tangent is not defined: the branch ends there.
bool BranchWalk::started(const PendingBranch& job) {
  PeriodicOrbit current = job.start;
  {
    StroboscopicMap& map = t_.family.at(current.parameter);
    const Scaling s = problem_.scaling(map);
    Eigen::VectorXd x(2 * current.u.size());
    x << current.u, current.v;
    w_ = s.to_scaled(x);
  }
  if (!problem_.evaluate(w_, current.parameter, f_, fw_, fp_, current, failure_)) {
    branch_.ended = "the starting orbit's run failed: " + failure_;
    return false;
  }
  m_ = w_.size();
  Eigen::VectorXd seed = Eigen::VectorXd::Zero(m_ + 1);
  seed(m_) = job.direction;
  if (job.tangent.size() == m_ + 1) seed = job.tangent;
  tangent_ = branch_tangent(fw_, fp_, seed);
  branch_.points.push_back(current);
  if (!tangent_.allFinite()) {
    branch_.ended = "the branch's tangent is not defined at its start (a singular Jacobian)";
    return false;
  }
  step_ = t_.options.initial_step;
  p_ = current.parameter;
  restarts_ = 0;
  first_.resize(m_ + 1);
  first_ << w_, p_;
  first_tangent_ = tangent_;
  contraction_ = t_.family.frequency_rate() ? ContinuationTuning::contraction_exact_fp
                                            : ContinuationTuning::contraction_chord_fp;
  farthest_ = 0;
  return true;
}

/// One step along the branch: predicted along the tangent, corrected, classified against the
/// point before; false when the branch ends here (budget, range, corrector, tangent, crossing).
bool BranchWalk::advanced() {
  const ContinuationOptions& options = t_.options;
  if (t_.budget_spent()) {
    branch_.ended = "the budget of map runs or of their events is spent";
    t_.pending.clear();
    return false;
  }
  if (p_ < t_.p_min || p_ > t_.p_max) {
    end_at_edge();
    return false;
  }
  if (std::abs(tangent_(m_)) * step_ > options.max_parameter_step) {
    step_ = options.max_parameter_step / std::abs(tangent_(m_));
  }
  Eigen::VectorXd z(m_ + 1);
  z << w_, p_;
  const Eigen::VectorXd predicted = z + step_ * tangent_;
  Eigen::VectorXd trial;
  PeriodicOrbit orbit;
  int iterations = 0;
  const bool converged = corrected(problem_, predicted, tangent_, step_, p_, contraction_, t_.shooting, options,
                                   t_.result, trial, orbit, f_, fw_, fp_, iterations, failure_);
  if (!converged) return after_failed_corrector();
  orbit.iterations = iterations;
  orbit.residual = f_.cwiseAbs().maxCoeff();
  const Eigen::VectorXd next_tangent = branch_tangent(fw_, fp_, tangent_);
  if (!next_tangent.allFinite()) {
    branch_.points.push_back(orbit);
    branch_.points.back().bifurcation = BifurcationKind::end;
    branch_.ended = "the branch's tangent is not defined (a singular Jacobian)";
    return false;
  }
  const PeriodicOrbit before = branch_.points.back();  // a copy: the pushes below may move the points
  classify(before, orbit, next_tangent);
  if (met_doubled_from(before, orbit, trial)) return false;
  return went_on(before, orbit, trial, next_tangent, iterations);
}

/// Keeps the corrected orbit (and the bifurcation located before it), moves the branch's state
/// to it and adapts the step; false when the branch closed on itself or stalled for good.
bool BranchWalk::went_on(const PeriodicOrbit& before, PeriodicOrbit& orbit, const Eigen::VectorXd& trial,
                         const Eigen::VectorXd& next_tangent, int iterations) {
  const bool grazed = orbit.bifurcation == BifurcationKind::grazing;
  const BifurcationKind found = orbit.bifurcation;
  const std::optional<PeriodicOrbit> at = located(before, orbit);
  branch_.points.push_back(orbit);
  if (closed(trial, next_tangent)) return false;
  w_ = trial.head(m_);
  p_ = trial(m_);
  // Across a grazing the map's derivative jumps: the old tangent is no guide, take the new one
  // and start again with small steps.
  tangent_ = next_tangent;
  adapt_step(grazed, iterations);
  if (stalled(orbit)) {
    // A singularity the corrector cannot pass: restart beyond it, or end the branch.
    if (restarted()) return true;
    branch_.points.back().bifurcation = BifurcationKind::end;
    branch_.ended = "stalled: the corrector cannot pass a singularity of the map";
    return false;
  }
  if (found == BifurcationKind::period_doubling && 2 * k_ <= t_.options.max_periodicity) {
    queue_doubling(before, orbit, at);
  }
  return true;
}

/// After the corrector failed: a smaller step, or — below the smallest — a restart beyond the
/// point, else the branch ends there. False when it ends.
bool BranchWalk::after_failed_corrector() {
  step_ *= ContinuationTuning::failed_step_factor;
  if (step_ < t_.options.min_step) {
    // The corrector cannot pass a point where the map is not smooth (a grazing, a lock):
    // restart beyond it, shooting one parameter step further from the last orbit.
    if (restarted()) return true;
    branch_.ended = failure_.empty() ? "Newton failed below the smallest step" : "a run failed: " + failure_;
    branch_.points.back().bifurcation = BifurcationKind::end;
    return false;
  }
  return true;
}

/// Goes on beyond a point the corrector cannot pass (a grazing, a lock), from an orbit shot one
/// parameter step further, with the initial step; false when restarts are used up or none lands.
bool BranchWalk::restarted() {
  if (restarts_ >= ContinuationTuning::max_restarts) return false;
  ++restarts_;
  PeriodicOrbit beyond;
  Eigen::VectorXd w_beyond, t_beyond;
  if (!restart_across(t_.family, problem_, branch_.points.back(), tangent_, t_.shooting, t_.options, t_.result,
                      beyond, w_beyond, t_beyond)) {
    return false;
  }
  beyond.bifurcation = BifurcationKind::grazing;
  branch_.points.push_back(beyond);
  ++t_.result.restarts;
  w_ = w_beyond;
  p_ = beyond.parameter;
  tangent_ = t_beyond;
  step_ = t_.options.initial_step;
  return true;
}

/// Ends a branch that left the parameter range on the range's edge: the orbit there, shot from
/// between its last two points, goes before the last (which lies outside).
void BranchWalk::end_at_edge() {
  branch_.ended = "left the parameter range";
  if (branch_.points.size() < 2) return;
  if (auto edge = orbit_at_edge(t_.family, branch_.points[branch_.points.size() - 2], branch_.points.back(),
                                p_ < t_.p_min ? t_.p_min : t_.p_max, t_.shooting, t_.result)) {
    branch_.points.insert(branch_.points.end() - 1, std::move(*edge));
  }
}

/// Flags what changed between `before` and the corrected `orbit`: the tangent's turn in p or a
/// multiplier through +1 (a fold), through −1, a complex pair through the circle, the events.
void BranchWalk::classify(const PeriodicOrbit& before, PeriodicOrbit& orbit,
                          const Eigen::VectorXd& next_tangent) const {
  if (next_tangent(m_) * tangent_(m_) < 0) {
    orbit.bifurcation = BifurcationKind::fold;
  } else if (real_below_minus_one(before.multipliers) != real_below_minus_one(orbit.multipliers)) {
    orbit.bifurcation = BifurcationKind::period_doubling;
  } else if (complex_outside(before.multipliers) != complex_outside(orbit.multipliers)) {
    orbit.bifurcation = BifurcationKind::neimark_sacker;
  } else if (before.events != orbit.events || before.impacts != orbit.impacts) {
    orbit.bifurcation = BifurcationKind::grazing;
  } else if (real_above_one(before.multipliers) != real_above_one(orbit.multipliers)) {
    orbit.bifurcation = BifurcationKind::fold;
  }
}

/// True (and the branch ended, the crossing recorded) when this period-2k branch came back to
/// a period doubling of the period-k branch it was born from.
bool BranchWalk::met_doubled_from(const PeriodicOrbit& before, PeriodicOrbit& orbit, const Eigen::VectorXd& trial) {
  using T = ContinuationTuning;
  const bool turned = orbit.bifurcation == BifurcationKind::fold;
  if (k_ % 2 != 0 || !(turned || (branch_.parent >= 0 && orbit.bifurcation != BifurcationKind::none))) return false;
  // There (as fixed points of P^{2k} the two branches cross) it would go on as the same orbits
  // shifted by k periods — its mirror image, turning back in p like a fold — or as the period-k
  // orbits run twice: it ends. Near the crossing w ≈ w* + aφ, φ the doubling's eigenvector, and
  // D = P^k(w) − w ≈ −2aφ: the branch crossed between two points where D points opposite ways
  // and is no longer than the step between them (a fold of the branch itself keeps D's
  // direction and its size); w* ≈ w + D/2 from either side.
  const Eigen::VectorXd w_after = trial.head(m_);
  const std::optional<Eigen::VectorXd> after = return_difference(t_.family, orbit, k_ / 2, t_.result);
  bool met = after && after->cwiseAbs().maxCoeff() < T::met_difference;
  Eigen::VectorXd crossing = w_after;
  double radius = after ? after->norm() : 0.0;
  if (after && !met && turned) {
    const std::optional<Eigen::VectorXd> ahead = return_difference(t_.family, before, k_ / 2, t_.result);
    if (ahead) {
      const double chord = (w_after - w_).norm();
      met = ahead->dot(*after) < 0 && ahead->norm() + after->norm() <= T::met_chord_factor * chord;
      crossing = 0.5 * ((w_ + 0.5 * *ahead) + (w_after + 0.5 * *after));
      radius = std::max(ahead->norm(), after->norm());
    }
  }
  if (!met) return false;
  orbit.bifurcation = BifurcationKind::period_doubling;
  t_.meetings.push_back({before.parameter, crossing, radius, k_});
  branch_.points.push_back(orbit);
  branch_.ended = "met the branch it doubled from";
  return true;
}

/// A period doubling or Neimark–Sacker flagged at `orbit` (only the first point past it),
/// located between `before` and it and kept on the branch (orbit's flag then cleared).
std::optional<PeriodicOrbit> BranchWalk::located(const PeriodicOrbit& before, PeriodicOrbit& orbit) {
  if (orbit.bifurcation != BifurcationKind::period_doubling && orbit.bifurcation != BifurcationKind::neimark_sacker) {
    return std::nullopt;
  }
  std::optional<PeriodicOrbit> at =
      refined_bifurcation(t_.family, before, orbit, orbit.bifurcation, t_.shooting, t_.result);
  if (at) {
    branch_.points.push_back(*at);
    orbit.bifurcation = BifurcationKind::none;
  }
  return at;
}

/// True (and the branch ended) when the last step's chord passed the first point going the way
/// the branch started, having gone further from it than a few steps: an isola, that would go
/// round again. The chord, not its end: steps grow as Newton converges fast, and one that passes
/// the first point need not land within a step of it; a branch that folds back and passes its
/// first point the other way is not closing.
bool BranchWalk::closed(const Eigen::VectorXd& trial, const Eigen::VectorXd& next_tangent) {
  Eigen::VectorXd last(m_ + 1);
  last << w_, p_;
  const Eigen::VectorXd chord = trial - last;
  const double this_step = chord.norm();
  const double along = this_step > 0 ? std::clamp((first_ - last).dot(chord) / chord.squaredNorm(), 0.0, 1.0) : 0.0;
  const double from_start = (trial - first_).norm();
  const double chord_from_start = (last + along * chord - first_).norm();
  farthest_ = std::max(farthest_, from_start);
  if (farthest_ > ContinuationTuning::isola_reach_steps * this_step && chord_from_start <= this_step &&
      next_tangent.dot(first_tangent_) > 0) {
    branch_.ended = "closed on itself (an isola or a loop)";
    return true;
  }
  return false;
}

/// The next step's size: back to small steps across a grazing, larger when Newton converged in
/// few iterations, smaller when it needed many.
void BranchWalk::adapt_step(bool grazed, int iterations) {
  using T = ContinuationTuning;
  const ContinuationOptions& options = t_.options;
  if (grazed) {
    step_ = std::max(options.min_step, std::min(step_, options.initial_step));
  } else if (iterations <= T::fast_iterations) {
    step_ = std::min(options.max_step, step_ * T::step_growth);
  } else if (iterations >= T::slow_iterations) {
    step_ *= T::slow_step_factor;
  }
}

/// True when the branch creeps: over its last stall_points points it moved (almost) neither in
/// the parameter nor in the state, stepping at about the smallest size — it sits on a
/// singularity the corrector cannot pass.
bool BranchWalk::stalled(const PeriodicOrbit& orbit) const {
  using T = ContinuationTuning;
  if (branch_.points.size() <= T::stall_points) return false;
  const PeriodicOrbit& back = branch_.points[branch_.points.size() - T::stall_points - 1];
  Eigen::VectorXd xb(2 * back.u.size()), xo(2 * orbit.u.size());
  xb << back.u, back.v;
  xo << orbit.u, orbit.v;
  const Scaling s{t_.family.length_scale(), orbit.omega};
  return std::abs(back.parameter - orbit.parameter) < T::stall_parameter_fraction * t_.options.max_parameter_step &&
         (s.to_scaled(xb) - s.to_scaled(xo)).norm() <
             static_cast<double>(T::stall_points) * t_.options.min_step * T::stall_state_margin;
}

/// Queues the period-2k branch born at the doubling just passed, switched to when its turn
/// comes: from the located doubling `at`, or where it could not be located, shot beside it from
/// the period-k orbit on its unstable side (the fallback).
void BranchWalk::queue_doubling(const PeriodicOrbit& before, const PeriodicOrbit& orbit,
                                const std::optional<PeriodicOrbit>& at) {
  const PeriodicOrbit& unstable =
      real_below_minus_one(orbit.multipliers) > real_below_minus_one(before.multipliers) ? orbit : before;
  t_.pending.push_back({at ? *at : unstable, branch_.id, 1, {}, true, at.has_value(), unstable});
}

/// Records the peaks of every continued orbit that has none (a shot orbit's were recorded at
/// its convergence): one run each, after the branches, so only the orbits kept are run.
void record_missing_amplitudes(OrbitFamily& family, ContinuationResult& result) {
  for (Branch& branch : result.branches) {
    for (PeriodicOrbit& orbit : branch.points) {
      if (!orbit.amplitudes.base_shear.empty()) continue;
      record_amplitudes(family.at(orbit.parameter), orbit);
      ++result.map_evaluations;
    }
  }
}

}  // namespace

ContinuationResult continue_orbits(OrbitFamily& family, const PeriodicOrbit& start, double p_min, double p_max,
                                   int direction, const ShootingOptions& shooting, const ContinuationOptions& options) {
  shooting.validate();
  options.validate();
  Tracing t{family, shooting, options, p_min, p_max, {}, {{start, -1, direction >= 0 ? 1 : -1, {}, false, false, {}}},
            {}, {}};
  while (!t.pending.empty()) {
    PendingBranch job = t.pending.front();
    t.pending.erase(t.pending.begin());
    if (job.doubling && !switched_to_doubled(t, job)) continue;
    t.result.branches.push_back(BranchWalk(t, job).walked(job));
  }
  record_missing_amplitudes(family, t.result);
  return std::move(t.result);
}

// ---- frequency responses by continuation ----------------------------------------------------

namespace {

/// The smallest k ≤ max_k whose sections repeat to `tolerance` (relative) after `settle` periods
/// from x; 0 when none. x is left at the last section.
int detected_periodicity(StroboscopicMap& map, Eigen::VectorXd& x, int settle, int max_k, double tolerance) {
  x = settled_state(map, x, settle);
  std::vector<Eigen::VectorXd> sections{x};
  double scale = x.cwiseAbs().maxCoeff();
  for (int j = 0; j < 2 * max_k; ++j) {
    x = map.evaluate(x, 1);
    sections.push_back(x);
    scale = std::max(scale, x.cwiseAbs().maxCoeff());
  }
  const auto size = static_cast<int>(sections.size());
  for (int k = 1; k <= max_k; ++k) {
    double worst = 0;
    for (int j = size - 1; j >= size - k; --j) {
      worst = std::max(worst, (sections[static_cast<std::size_t>(j)] - sections[static_cast<std::size_t>(j - k)]).cwiseAbs().maxCoeff());
    }
    if (worst <= tolerance * scale) return k;
  }
  return 0;
}

/// The orbit the response from rest settles on: simulated steady.max_periods/10 + 10 periods,
/// its periodicity read from its sections, then shot. None when Newton does not converge or a run
/// fails (the caller simulates, or says so). `budget` is charged the runs, `event_budget` their
/// events (as many per period as the orbit's).
std::optional<PeriodicOrbit> orbit_from_rest(StroboscopicMap& map, const SteadyStateOptions& steady, int max_k,
                                             const ShootingOptions& shooting, long& budget, long& event_budget) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * map.dofs());
  const int settle = steady.max_periods / 10 + 10;
  budget -= settle + 2 * max_k;
  try {
    const int k = detected_periodicity(map, x, settle, max_k, 1e-4);
    ShootingResult shot = shoot(map, x, k > 0 ? k : 1, shooting);
    budget -= shot.orbit.iterations + 1;
    event_budget -= shot.orbit.events * (settle + 2 * max_k + shot.orbit.iterations + 1) / shot.orbit.periodicity;
    if (shot.converged) return std::move(shot.orbit);
  } catch (const std::exception&) {
    // the run from rest failed: the caller's simulation (or message) says why
  }
  return std::nullopt;
}

/// The periodic orbit the response from rest settles on within about `longest` periods: its
/// sections read as orbit_from_rest's after steady.max_periods/10 + 10 periods, then again every
/// 10 + 2 max_k periods until they repeat, and shot. None when they do not repeat by then,
/// Newton does not converge or a run fails.
std::optional<PeriodicOrbit> periodic_orbit_from_rest(StroboscopicMap& map, const SteadyStateOptions& steady, int max_k,
                                                      int longest, const ShootingOptions& shooting, long& budget,
                                                      long& event_budget) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * map.dofs());
  try {
    int k = 0;
    for (int run = 0; k == 0 && run < longest;) {
      const int settle = run == 0 ? steady.max_periods / 10 + 10 : 10;
      k = detected_periodicity(map, x, settle, max_k, 1e-4);
      run += settle + 2 * max_k;
      budget -= settle + 2 * max_k;
      event_budget -= map.simulator().statistics().events * (settle + 2 * max_k);
    }
    if (k == 0) return std::nullopt;
    ShootingResult shot = shoot(map, x, k, shooting);
    budget -= shot.orbit.iterations + 1;
    event_budget -= shot.orbit.events * (shot.orbit.iterations + 1) / k;
    if (shot.converged) return std::move(shot.orbit);
  } catch (const std::exception&) {
    // the run from rest failed: nothing to follow from there
  }
  return std::nullopt;
}

FrfPoint frf_point(StroboscopicMap& map, double amplitude, const PeriodicOrbit& orbit, int branch, int parent,
                   double period_tolerance) {
  const Model& model = map.model();
  FrfPoint p;
  p.ratio = orbit.parameter;
  p.omega = orbit.omega;
  p.interacting = orbit.amplitudes;
  p.free = free_response(model, amplitude, orbit.omega);
  p.periodicity = minimal_period(map, orbit, period_tolerance);
  p.transient_periods = 0;
  p.events = orbit.events;
  p.impacts = orbit.impacts;
  p.continued = true;
  p.branch_id = branch;
  p.parent_branch = parent;
  p.stable = orbit.stable;
  p.multipliers.assign(orbit.multipliers.data(), orbit.multipliers.data() + orbit.multipliers.size());
  p.bifurcation = orbit.bifurcation;
  p.section_u.assign(orbit.u.data(), orbit.u.data() + orbit.u.size());
  p.section_v.assign(orbit.v.data(), orbit.v.data() + orbit.v.size());
  return p;
}

}  // namespace

namespace {

/// Whether the response at ratio r was simulated (no orbit converged there).
bool simulated_at(const std::vector<FrfPoint>& points, double r) {
  return std::any_of(points.begin(), points.end(), [&](const FrfPoint& p) { return !p.continued && p.ratio == r; });
}

/// Whether visit(a, b, t) holds for a continued orbit at ratio r: a continued point there (b = a,
/// t = 0), or two consecutive points a, b of a branch either side of r, t of the way from a to b.
template <class Visit>
bool any_continued_at(const std::vector<FrfPoint>& points, double r, const Visit& visit) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const FrfPoint& a = points[i];
    if (!a.continued) continue;
    if (a.ratio == r && visit(a, a, 0.0)) return true;
    if (i + 1 == points.size()) continue;
    const FrfPoint& b = points[i + 1];
    if (!b.continued || b.branch_id != a.branch_id || !((a.ratio - r) * (b.ratio - r) < 0)) continue;
    if (visit(a, b, (r - a.ratio) / (b.ratio - a.ratio))) return true;
  }
  return false;
}

/// Whether a stable orbit lies at ratio r among the points: a simulated point there, a continued
/// one there, or two consecutive points of a branch either side of r one of which is stable (a
/// branch's stability changes only at a bifurcation, located as a point of its own).
bool has_stable_orbit(const std::vector<FrfPoint>& points, double r) {
  return simulated_at(points, r) ||
         any_continued_at(points, r, [](const FrfPoint& a, const FrfPoint& b, double) { return a.stable || b.stable; });
}

/// Whether `orbit`, shot at ratio r, lies on a stable side of a continued branch: a point at r,
/// or two consecutive points of a branch either side of r, of the orbit's minimal period (the
/// longer of the two labels: a point at a doubling is labelled with the period it doubled), and
/// whose peaks (interpolated linearly between the two) are the orbit's to
/// 1 % of each frame's (kPeaks): coexisting orbits differ far more, and linear interpolation over
/// a parameter step of 0.01 errs far less.
bool on_stable_branch(const std::vector<FrfPoint>& points, double r, const PeriodicOrbit& orbit) {
  constexpr double kPeaks = 1e-2;
  const auto same = [&](const FrameAmplitudes& a, const FrameAmplitudes& b, double t) {
    for (std::size_t f = 0; f < orbit.amplitudes.base_shear.size(); ++f) {
      const double shear = a.base_shear[f] + t * (b.base_shear[f] - a.base_shear[f]);
      const double top = a.top_displacement[f] + t * (b.top_displacement[f] - a.top_displacement[f]);
      if (std::abs(shear - orbit.amplitudes.base_shear[f]) > kPeaks * orbit.amplitudes.base_shear[f]) return false;
      if (std::abs(top - orbit.amplitudes.top_displacement[f]) > kPeaks * orbit.amplitudes.top_displacement[f]) return false;
    }
    return true;
  };
  return any_continued_at(points, r, [&](const FrfPoint& a, const FrfPoint& b, double t) {
    return (a.stable || b.stable) && std::max(a.periodicity, b.periodicity) == orbit.periodicity &&
           same(a.interacting, b.interacting, t);
  });
}

/// One piece of a frequency response by continuation: the ratios [first, last) of the sorted
/// list, continued within [lo, hi] on a budget of its own. Branch ids count from 0 in the piece.
struct Segment {
  std::vector<double> ratios;
  double lo = 0.0, hi = 0.0;
};

/// Appends to `out` the points of `traced`'s branches inside the piece, their branch ids offset
/// by `next_branch`, which then counts them.
void append_branches(const ContinuationResult& traced, const Segment& segment, FrequencyFamily& family,
                     const FrequencyResponseOptions& options, int& next_branch, std::vector<FrfPoint>& out) {
  for (const Branch& b : traced.branches) {
    for (const PeriodicOrbit& orbit : b.points) {
      if (orbit.parameter < segment.lo || orbit.parameter > segment.hi) continue;
      out.push_back(frf_point(family.at(orbit.parameter), options.amplitude, orbit, next_branch + b.id,
                              b.parent >= 0 ? next_branch + b.parent : -1, options.continuation.period_tolerance));
    }
  }
  next_branch += static_cast<int>(traced.branches.size());
}

/// One piece of a frequency response by continuation, in two passes: the ratios continued
/// upward from seeds (continue_upward), then the responses from rest no branch reached
/// (seed_from_rest). Branch ids count from 0 in the piece.
class PieceContinuation {
 public:
  PieceContinuation(const Model& model, const FrequencyResponseOptions& options, const Segment& segment,
                    const std::function<void(int)>& ratios_done)
      : model_(model), options_(options), segment_(segment), ratios_done_(ratios_done),
        th_(exact_options(options.time_history)),
        family_(model, options.amplitude, th_, options.steady.steps_per_period), co_(options.continuation),
        max_k_(std::min(options.steady.max_periodicity, co_.max_periodicity)),
        budget_(static_cast<long>(co_.evaluations_per_ratio) * static_cast<long>(segment.ratios.size())),
        event_budget_(static_cast<long>(co_.events_per_ratio) * static_cast<long>(segment.ratios.size())) {}

  std::vector<FrfPoint> run() {
    for (const double r : segment_.ratios) {
      if (r > covered_) continue_upward(r);
    }
    for (const double r : segment_.ratios) seed_from_rest(r);
    return std::move(out_);
  }

 private:
  /// A periodic response simulated where the budget was spent: shot in the second pass, on a
  /// ratio's budget of its own.
  struct Pending {
    double ratio;
    Eigen::VectorXd state;
    int periodicity;
  };

  static TimeHistoryOptions exact_options(TimeHistoryOptions th) {
    th.integrator = Integrator::exact;
    return th;
  }

  void report() {
    const auto done = static_cast<int>(
        std::count_if(segment_.ratios.begin(), segment_.ratios.end(), [&](double r) { return r <= covered_; }));
    ratios_done_(done - reported_);
    reported_ = done;
  }

  /// The orbit shot from state x as period k, charged to (runs, events); none when Newton does
  /// not converge or the run cannot start.
  std::optional<PeriodicOrbit> shot_from(StroboscopicMap& map, const Eigen::VectorXd& x, int k, double r, long& runs,
                                         long& events) const {
    try {
      ShootingResult shot = shoot(map, x, k, options_.shooting);
      runs -= shot.orbit.iterations + 2;
      events -= shot.orbit.events * (shot.orbit.iterations + 2) / shot.orbit.periodicity;
      if (!shot.converged) return std::nullopt;
      shot.orbit.parameter = r;
      return std::move(shot.orbit);
    } catch (const std::exception&) {
      return std::nullopt;  // a run that cannot start: the simulated point stays
    }
  }

  /// Follows `seed` within the piece in `directions`, on (runs, events); appends its branches.
  void follow(const PeriodicOrbit& seed, std::initializer_list<int> directions, long& runs, long& events) {
    for (const int direction : directions) {
      // Upward at least the seed itself, whatever is left.
      if (direction < 0 && (runs <= 0 || events <= 0)) break;
      co_.max_evaluations = runs;
      co_.max_events = events;
      const ContinuationResult traced =
          continue_orbits(family_, seed, segment_.lo, segment_.hi, direction, options_.shooting, co_);
      runs -= traced.map_evaluations;
      events -= traced.events;
      if (direction > 0) {
        for (const PeriodicOrbit& orbit : traced.branches.front().points) covered_ = std::max(covered_, orbit.parameter);
      }
      append_branches(traced, segment_, family_, options_, next_branch_, out_);
    }
  }

  /// Seeds at r (the orbit the response from rest settles on, or the simulated response shot
  /// where Newton fails from the short run) and continues upward; where no orbit converges or
  /// the budget is spent, the simulated point stands for r.
  void continue_upward(double r) {
    StroboscopicMap& map = family_.at(r);
    std::optional<PeriodicOrbit> seed;
    if (budget_ > 0 && event_budget_ > 0) {
      seed = orbit_from_rest(map, options_.steady, max_k_, options_.shooting, budget_, event_budget_);
      if (seed) {
        seed->parameter = r;
        if (seed->stable) seeded_.push_back(r);
      }
    }
    if (!seed) {
      // No periodic orbit from here (quasi-periodic, chaotic, or beyond Newton): simulate. Where
      // the simulation settles on a periodic response, shoot it from there (a longer transient
      // than the seed's) and continue it after all — now if the budget allows, else later.
      FromRest simulated = simulated_from_rest(map, r);
      if (simulated.state) {
        if (budget_ > 0 && event_budget_ > 0) {
          seed = shot_from(map, *simulated.state, simulated.point.periodicity, r, budget_, event_budget_);
        } else {
          pending_.push_back({r, std::move(*simulated.state), simulated.point.periodicity});
        }
      }
      if (!seed) {
        out_.push_back(std::move(simulated.point));
        covered_ = r;
        report();
        return;
      }
    }
    covered_ = std::max(covered_, r);
    follow(*seed, {+1}, budget_, event_budget_);
    report();
  }

  /// The response from rest at r may settle on a stable orbit no branch followed here reached
  /// (born at a grazing or a fold, not at a period doubling of a branch followed): at a ratio
  /// where every continued orbit is unstable, or at any ratio with seeds_from_rest = every, or
  /// where the first pass simulated a periodic response on a spent budget. Seed it there and
  /// follow that orbit both ways, on a share of the budget of its own: one ratio's, or what the
  /// piece has left if more.
  void seed_from_rest(double r) {
    // A seed's short run from rest may settle near an orbit the full run leaves again: with
    // seeds_from_rest = every its ratio is simulated too.
    const bool every = co_.seeds_from_rest == RestSeeds::every;
    if (!every && std::find(seeded_.begin(), seeded_.end(), r) != seeded_.end()) return;
    const auto pending = std::find_if(pending_.begin(), pending_.end(), [&](const Pending& p) { return p.ratio == r; });
    const bool simulated = simulated_at(out_, r);
    const bool none_stable = !has_stable_orbit(out_, r);
    if (simulated ? pending == pending_.end() : !none_stable && !every) return;
    long runs = std::max(budget_, static_cast<long>(co_.evaluations_per_ratio));
    long events = std::max(event_budget_, static_cast<long>(co_.events_per_ratio));
    const long runs_given = runs, events_given = events;
    StroboscopicMap& map = family_.at(r);
    std::optional<PeriodicOrbit> seed;
    std::optional<FrfPoint> from_rest;
    if (pending != pending_.end()) {
      seed = shot_from(map, pending->state, pending->periodicity, r, runs, events);
    } else if (every) {
      FromRest run = simulated_from_rest(map, r);
      if (run.state) seed = shot_from(map, *run.state, run.point.periodicity, r, runs, events);
      from_rest = std::move(run.point);
    } else {
      seed = periodic_orbit_from_rest(map, options_.steady, max_k_, options_.steady.max_periods / 4, options_.shooting,
                                      runs, events);
      if (seed) seed->parameter = r;
    }
    if (seed && seed->stable) {
      if (simulated) std::erase_if(out_, [&](const FrfPoint& p) { return !p.continued && p.ratio == r; });
      if (simulated || none_stable || !on_stable_branch(out_, r, *seed)) follow(*seed, {+1, -1}, runs, events);
    } else if (from_rest) {
      // Not periodic, or not an orbit Newton converges to: the response from rest itself.
      out_.push_back(std::move(*from_rest));
    }
    budget_ -= runs_given - runs;
    event_budget_ -= events_given - events;
  }

  /// The response from rest at r as the brute force simulates it, and its last state on the
  /// Poincaré section when it is periodic (where an orbit is shot from).
  struct FromRest {
    FrfPoint point;
    std::optional<Eigen::VectorXd> state;
  };
  FromRest simulated_from_rest(const StroboscopicMap& map, double r) const {
    std::unique_ptr<Simulator> sim;
    FromRest out{steady_state_point(model_, options_.amplitude, r, options_.steady, th_, sim), std::nullopt};
    if (out.point.periodicity > 0 && sim) {
      Eigen::VectorXd x(2 * map.dofs());
      x << sim->state().u, sim->state().v;
      out.state = std::move(x);
    }
    return out;
  }

  const Model& model_;
  const FrequencyResponseOptions& options_;
  const Segment& segment_;
  const std::function<void(int)>& ratios_done_;
  TimeHistoryOptions th_;
  FrequencyFamily family_;
  ContinuationOptions co_;
  int max_k_;
  long budget_, event_budget_;
  std::vector<FrfPoint> out_;
  std::vector<double> seeded_;  // the ratios whose stable response from rest a branch starts from
  std::vector<Pending> pending_;
  int next_branch_ = 0;
  double covered_ = -std::numeric_limits<double>::infinity();
  int reported_ = 0;
};

std::vector<FrfPoint> continued_segment(const Model& model, const FrequencyResponseOptions& options,
                                        const Segment& segment, const std::function<void(int)>& ratios_done) {
  return PieceContinuation(model, options, segment, ratios_done).run();
}

}  // namespace

std::vector<FrfPoint> frequency_response_by_continuation(const Model& model, const FrequencyResponseOptions& options) {
  options.shooting.validate();
  options.continuation.validate();
  std::vector<double> ratios = options.ratios;
  std::sort(ratios.begin(), ratios.end());
  ContinuationOptions co = options.continuation;
  if (ratios.size() > 1) {
    co.max_parameter_step = std::min(co.max_parameter_step, (ratios.back() - ratios.front()) / static_cast<double>(ratios.size() - 1));
  }
  FrequencyResponseOptions piece = options;
  piece.continuation = co;

  // The pieces are fixed by the ratios alone (never by the threads), so the result is the same
  // on any number of threads; each spends only its own budget, so a tangle of short branches in
  // one part of the range cannot starve the rest.
  const auto per = static_cast<std::size_t>(co.ratios_per_segment);
  std::vector<Segment> segments;
  for (std::size_t first = 0; first < ratios.size(); first += per) {
    const std::size_t last = std::min(ratios.size(), first + per);
    Segment s;
    s.ratios.assign(ratios.begin() + static_cast<std::ptrdiff_t>(first), ratios.begin() + static_cast<std::ptrdiff_t>(last));
    s.lo = ratios[first];
    s.hi = last < ratios.size() ? ratios[last] : ratios.back();  // shares its top with the next piece
    segments.push_back(std::move(s));
  }
  std::vector<std::vector<FrfPoint>> results(segments.size());
  std::atomic<int> done{0};
  const int total = static_cast<int>(ratios.size());
  parallel_for(static_cast<int>(segments.size()), options.threads, [&](int i) {
    const auto index = static_cast<std::size_t>(i);
    results[index] = continued_segment(model, piece, segments[index], [&](int more) {
      const int count = done += more;
      if (options.progress && more > 0) options.progress(count, total);
    });
  });
  std::vector<FrfPoint> out;
  int offset = 0;
  for (auto& r : results) {
    int most = -1;
    for (FrfPoint& p : r) {
      if (p.branch_id >= 0) {
        most = std::max(most, p.branch_id);
        p.branch_id += offset;
        if (p.parent_branch >= 0) p.parent_branch += offset;
      }
      out.push_back(std::move(p));
    }
    offset += most + 1;
  }
  return out;
}

std::vector<ParameterPoint> parameter_response_by_continuation(const std::function<Model(double)>& model_at,
                                                               double p_min, double p_max, double p_start,
                                                               const FrequencyResponseOptions& options) {
  options.shooting.validate();
  options.continuation.validate();
  if (options.ratios.size() != 1) {
    throw std::invalid_argument(fmt::format("a continuation in a model parameter is at one forcing frequency, not {}",
                                            options.ratios.size()));
  }
  if (!(p_min < p_max) || !(p_start >= p_min && p_start <= p_max)) {
    throw std::invalid_argument(fmt::format("the start {} must lie in [min, max] = [{}, {}], min < max", p_start, p_min, p_max));
  }
  const double ratio = options.ratios.front();
  TimeHistoryOptions th = options.time_history;
  th.integrator = Integrator::exact;
  ParameterFamily family(model_at, options.amplitude, ratio, th, options.steady.steps_per_period);
  const int max_k = std::min(options.steady.max_periodicity, options.continuation.max_periodicity);
  long budget = options.continuation.max_evaluations, event_budget = options.continuation.max_events;
  std::optional<PeriodicOrbit> seed =
      orbit_from_rest(family.at(p_start), options.steady, max_k, options.shooting, budget, event_budget);
  if (!seed) {
    throw SimulationError(fmt::format("no periodic orbit to start from at {}: the response from rest does not settle on "
                                      "one that Newton's method converges to (start elsewhere)", p_start));
  }
  seed->parameter = p_start;
  ContinuationOptions co = options.continuation;
  // The parameter has its own units (a gap in metres, a ratio, a mass): no step longer than a
  // hundredth of its range, so a branch is resolved alike whatever the key.
  co.max_parameter_step = std::min(co.max_parameter_step, (p_max - p_min) / 100);
  std::vector<ParameterPoint> out;
  int offset = 0;
  for (const int direction : {+1, -1}) {
    if ((direction > 0 && p_start >= p_max) || (direction < 0 && p_start <= p_min)) continue;
    co.max_evaluations = budget;
    co.max_events = event_budget;
    const ContinuationResult traced = continue_orbits(family, *seed, p_min, p_max, direction, options.shooting, co);
    budget -= traced.map_evaluations;
    event_budget -= traced.events;
    for (const Branch& b : traced.branches) {
      for (const PeriodicOrbit& orbit : b.points) {
        if (orbit.parameter < p_min || orbit.parameter > p_max) continue;
        FrfPoint point = frf_point(family.at(orbit.parameter), options.amplitude, orbit, offset + b.id,
                                   b.parent >= 0 ? offset + b.parent : -1, options.continuation.period_tolerance);
        point.ratio = ratio;
        out.push_back({orbit.parameter, std::move(point)});
      }
    }
    offset += static_cast<int>(traced.branches.size());
  }
  return out;
}


}  // namespace poundsim
