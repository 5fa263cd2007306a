#pragma once
/// @file
/// Periodic responses to a harmonic base acceleration a_g = A sin(ω̄t), found by shooting and
/// followed by pseudo-arclength continuation, with their Floquet stability (see
/// docs/periodic-orbits.md).
///
/// The stroboscopic (Poincaré) map P takes the floors' state x = [u; u̇] at t = 0 to the state
/// one forcing period T = 2π/ω̄ later; a period-k orbit is a fixed point of P^k. The exact
/// integrator runs the k periods and carries the map's Jacobian, the monodromy matrix, exactly:
/// the phase propagators between events composed with each event's saltation matrix
/// (src/integrate/tangent_flow.hpp). Newton's method on P^k(x) − x therefore converges
/// quadratically; the eigenvalues of the monodromy matrix at the fixed point are the orbit's
/// Floquet multipliers, stable when all lie inside the unit circle.
///
/// Continuation follows a branch of orbits through a parameter p — the forcing frequency ratio
/// ω̄/ω₁ or any model parameter — by pseudo-arclength (Keller 1977): predictor along the
/// branch's tangent, Newton corrector on F(x, p) = P^k(x; p) − x = 0 with the arclength
/// constraint, so that folds are passed. ∂F/∂x is exact; so is ∂F/∂p in the forcing frequency
/// (the state's sensitivity to ω̄ carried through the run beside the monodromy), while in a model
/// parameter it is a forward difference of the map (one extra run per step, a chord). Along a branch the multipliers mark folds (+1), period doublings (−1: at
/// each one located the period-2k branch born there is switched to and followed), Neimark–Sacker
/// points (a complex pair leaves the unit circle) and grazing (the orbit's events change: an
/// element starts or stops touching, where the map is not smooth; the branch is restarted across
/// it).
///
/// The state is scaled for Newton and the arclength: w = [u; u̇/ω̄]/L, L = A/ω₁² (the static
/// displacement of frame 1's first mode under the amplitude).
///
/// Limits: laws whose State persists between events (yielding storeys, the force criterion's
/// relaxing free end) are not part of x and are refused; an orbit that is locked at t = 0 cannot
/// start a run (its lock is a history, not a displacement) and Newton fails there; the map is
/// not smooth where an orbit grazes, locks or fires the rest-velocity rule, and Newton may then
/// converge linearly or not at all (the point is reported as not converged).

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/analysis/orbit_options.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// Why the periodic orbits of `model` under `options` cannot be shot (empty when they can): laws
/// that keep a state between events, the force separation criterion (see the file comment).
[[nodiscard]] std::string periodic_orbits_refusal(const Model& model, const TimeHistoryOptions& options);

/// One periodic orbit.
struct PeriodicOrbit {
  double parameter = 0.0;   ///< p: ω̄/ω₁ for a frequency response, else the model parameter
  double omega = 0.0;       ///< ω̄ [rad/s]
  int periodicity = 1;      ///< k: the orbit repeats every k forcing periods
  Eigen::VectorXd u, v;     ///< floors' displacements [m] and velocities [m/s] at t = 0 (mod kT)
  Eigen::MatrixXd monodromy;     ///< ∂x(kT)/∂x(0), x = [u; u̇]
  Eigen::VectorXcd multipliers;  ///< eigenvalues of the monodromy, by decreasing modulus
  bool stable = false;      ///< every multiplier inside the unit circle
  int iterations = 0;       ///< Newton iterations taken
  double residual = 0.0;    ///< max |P^k(w) − w| at the end (scaled)
  long events = 0;          ///< events per orbit (k periods)
  long impacts = 0;         ///< impacts per orbit
  /// min |∇h·ẋ|/(|∇h||ẋ|) over the orbit's events: near 0 it grazes a guard.
  double transversality = 1.0;
  FrameAmplitudes amplitudes;  ///< peaks over the orbit
  BifurcationKind bifurcation = BifurcationKind::none;  ///< between this point and the one before

  [[nodiscard]] double largest_multiplier() const {
    return multipliers.size() > 0 ? std::abs(multipliers(0)) : 0.0;
  }
};

/// The stroboscopic map of a model under a harmonic base acceleration: runs of the exact
/// integrator from a state at t = 0, with the monodromy.
class StroboscopicMap {
 public:
  /// `options`: the event rules (its integrator is set to exact, its dt per frequency). Throws
  /// std::invalid_argument for models the map cannot hold (see the file comment).
  StroboscopicMap(const Model& model, double amplitude, double omega, TimeHistoryOptions options,
                  int samples_per_period);
  ~StroboscopicMap();
  StroboscopicMap(const StroboscopicMap&) = delete;
  StroboscopicMap& operator=(const StroboscopicMap&) = delete;

  void set_omega(double omega);
  [[nodiscard]] double omega() const { return omega_; }
  [[nodiscard]] double amplitude() const { return amplitude_; }
  [[nodiscard]] const Model& model() const { return model_; }
  [[nodiscard]] int dofs() const { return dofs_; }

  /// What a run keeps besides the state: its peaks (Responses::record) or only its events
  /// (Responses::skip, a fifth to a quarter of a recorded period's cost:
  /// Simulator::record_responses). No run of the map keeps an energy balance: an orbit reports
  /// its peaks alone, and the closed-form power integrals were a quarter of a recorded period.
  enum class Responses { skip, record };

  /// Runs k periods from x = [u; v] (2N); the state reached and, when `jacobian` is given, the
  /// monodromy ∂x(kT)/∂x(0). A pair of floors past its stop in x is put back on it first (each
  /// moved half the excess; the monodromy includes that projection). Throws SimulationError or
  /// std::invalid_argument (a state that cannot start) as the simulator does.
  ///
  /// `frequency_derivative`, when given (with `jacobian`), receives ∂P^k/∂ω̄ at fixed x: the
  /// state's sensitivity to ω̄ carried through the run (tangent_flow.hpp) less ẋ(kT)·kT/ω̄, as the
  /// period shortens when ω̄ grows.
  Eigen::VectorXd evaluate(const Eigen::VectorXd& x, int k, Eigen::MatrixXd* jacobian = nullptr,
                           Responses responses = Responses::skip, Eigen::VectorXd* frequency_derivative = nullptr);
  /// The simulator of the last evaluation (its statistics are the run's counts, and its peaks
  /// when it recorded them; its energy() is no balance: it meters none).
  [[nodiscard]] const Simulator& simulator() const { return *sim_; }

 private:
  Model model_;
  double amplitude_ = 0.0, omega_ = 0.0;
  TimeHistoryOptions options_;
  int samples_ = 64;
  int dofs_ = 0;
  std::unique_ptr<Simulator> sim_;
  Eigen::VectorXd start_;  ///< the state a run starts from (put back on the stops)
  Eigen::MatrixXd projection_;  ///< ∂start/∂x
};

/// The linear frames' steady state at t = 0 (each frame alone, closed form): x = [u; u̇] (2N).
[[nodiscard]] Eigen::VectorXd linear_steady_state(const Model& model, double amplitude, double omega);

/// The state after `periods` forcing periods from x0: a starting guess near an attracting orbit.
[[nodiscard]] Eigen::VectorXd settled_state(StroboscopicMap& map, const Eigen::VectorXd& x0, int periods);

/// Newton's method for a period-k orbit from x0 = [u; v]. Returns the orbit (converged or not:
/// `converged` says which). The monodromy, multipliers, events and peaks are those of the last
/// iterate.
struct ShootingResult {
  PeriodicOrbit orbit;
  bool converged = false;
  std::string failure;  ///< why Newton stopped, when it did not converge
};
[[nodiscard]] ShootingResult shoot(StroboscopicMap& map, const Eigen::VectorXd& x0, int k, const ShootingOptions& options);

/// The orbit's minimal period: the least j dividing orbit.periodicity (k) for which P^j returns
/// its state on the Poincaré section to within `tolerance`, scaled as shooting's residual (a
/// fixed point of P^k may be one of P^j: a period-1 orbit shot as period 2, a doubled branch
/// back at its parent). Runs j periods for each divisor tried.
[[nodiscard]] int minimal_period(StroboscopicMap& map, const PeriodicOrbit& orbit, double tolerance);

/// One continued branch.
struct Branch {
  int id = 0;
  int periodicity = 1;
  int parent = -1;  ///< the branch it doubled from (−1: a starting branch)
  std::vector<PeriodicOrbit> points;
  std::string ended;  ///< why the continuation stopped
};

/// A family of models along a parameter: the map at p (a frequency ratio, or a model parameter
/// at a fixed frequency).
class OrbitFamily {
 public:
  virtual ~OrbitFamily() = default;
  /// The map at p, made current.
  virtual StroboscopicMap& at(double p) = 0;
  /// A second map at p for the parameter's difference (must not disturb at()'s).
  virtual StroboscopicMap& difference_at(double p) = 0;
  /// The length that scales states [m].
  [[nodiscard]] virtual double length_scale() const = 0;
  /// dω̄/dp when p moves the forcing frequency alone: ∂P/∂p then comes from the run itself
  /// (StroboscopicMap::evaluate's frequency_derivative). Empty when p changes the model: a
  /// difference of the map (difference_at).
  [[nodiscard]] virtual std::optional<double> frequency_rate() const { return std::nullopt; }
};

/// The frequency ratio ω̄/ω₁ of a fixed model.
class FrequencyFamily final : public OrbitFamily {
 public:
  FrequencyFamily(const Model& model, double amplitude, const TimeHistoryOptions& options, int samples_per_period);
  StroboscopicMap& at(double ratio) override;
  StroboscopicMap& difference_at(double ratio) override;
  [[nodiscard]] double length_scale() const override { return length_; }
  [[nodiscard]] std::optional<double> frequency_rate() const override { return omega1_; }
  [[nodiscard]] double reference_omega() const { return omega1_; }

 private:
  double omega1_ = 0.0, length_ = 0.0;
  StroboscopicMap map_, difference_;
};

/// A model parameter at a fixed frequency: `model_at(p)` builds the model.
class ParameterFamily final : public OrbitFamily {
 public:
  ParameterFamily(std::function<Model(double)> model_at, double amplitude, double ratio,
                  const TimeHistoryOptions& options, int samples_per_period);
  StroboscopicMap& at(double p) override;
  StroboscopicMap& difference_at(double p) override;
  [[nodiscard]] double length_scale() const override { return length_; }

 private:
  std::function<Model(double)> model_at_;
  double amplitude_, ratio_, length_ = 0.0;
  TimeHistoryOptions options_;
  int samples_;
  std::unique_ptr<StroboscopicMap> map_, difference_;
  double map_p_ = 0.0, difference_p_ = 0.0;
};

/// What a continuation run found.
struct ContinuationResult {
  std::vector<Branch> branches;
  long map_evaluations = 0;   ///< runs of the map (with or without the monodromy)
  long newton_iterations = 0;
  long events = 0;            ///< events crossed by the corrector's runs
  /// Branches restarted beyond a point the corrector could not pass (flagged grazing).
  long restarts = 0;
};

/// Follows the period-k branch through `start` (a converged orbit at p = start.parameter) in
/// the direction of increasing p (`direction` = +1) or decreasing (−1) until p leaves
/// [p_min, p_max]. At every period doubling located on a branch (up to max_periodicity) the
/// period-2k branch born there is switched to — its first orbit corrected from the doubling along
/// the eigenvector of the multiplier −1, in the state and p together — and followed away from the
/// doubling and back towards it; a period-2k branch that comes back to a doubling of a period-k
/// branch ends there, and that doubling is not switched at again (docs/periodic-orbits.md).
[[nodiscard]] ContinuationResult continue_orbits(OrbitFamily& family, const PeriodicOrbit& start, double p_min,
                                                 double p_max, int direction, const ShootingOptions& shooting,
                                                 const ContinuationOptions& options);

/// A frequency response by continuation (FrfMethod::continuation). The sorted ratios are cut into
/// pieces of ContinuationOptions::ratios_per_segment, continued in parallel, each on its own
/// budget: from a piece's lowest ratio a seed (simulated from rest until its sections repeat, then
/// shot) is continued upward to the next piece's lowest ratio, its period doublings followed;
/// where a branch ends before the top, the next ratio above it is seeded again, and where no
/// orbit converges or the budget is spent the point is simulated (FrfPoint::continued false) —
/// and, when the simulated response is periodic and the budget allows, shot from there and
/// continued after all. Then each ratio of the piece where every continued orbit is unstable is
/// seeded from rest again (simulated up to a quarter of max_periods until its sections repeat)
/// and a stable orbit found there is followed both ways. Every point of every branch in the
/// range is returned, stable or not, piece after piece; the result does not depend on the number
/// of threads.
[[nodiscard]] std::vector<FrfPoint> frequency_response_by_continuation(const Model& model,
                                                                       const FrequencyResponseOptions& options);

/// One point of a continuation in a model parameter: the parameter's value and the orbit's
/// response there (FrfPoint: ratio is the fixed ω̄/ω₁; branch, stability, multipliers, peaks).
struct ParameterPoint {
  double parameter = 0.0;
  FrfPoint response;
};

/// Periodic responses at one forcing frequency (options.ratios holds exactly one ratio) as a model
/// parameter p runs through [p_min, p_max]: `model_at(p)` builds the model. The orbit the response
/// from rest settles on at p_start is shot and continued up to p_max and down to p_min, its period
/// doublings followed (the shooting, continuation, steady-state — for the seed — and event options
/// are options'). Every point of every branch in the range, stable or not; throws SimulationError
/// when no orbit can be started at p_start, std::invalid_argument for options it cannot take.
[[nodiscard]] std::vector<ParameterPoint> parameter_response_by_continuation(
    const std::function<Model(double)>& model_at, double p_min, double p_max, double p_start,
    const FrequencyResponseOptions& options);

}  // namespace poundsim
