#pragma once
/// @file
/// The options of shooting and continuation of periodic orbits (periodic_orbits.hpp), and what a
/// continued point can be: read from a model file's [frf.continuation] (docs/input.md).

#include <array>
#include <cstdint>
#include <string_view>
#include <utility>

#include "poundsim/fields.hpp"

namespace poundsim {

/// How a frequency response finds its steady states.
enum class FrfMethod : std::uint8_t {
  simulation,    ///< brute force: simulate until the Poincaré sections repeat
  continuation,  ///< shooting and pseudo-arclength continuation of every branch (periodic_orbits.hpp)
};
inline constexpr std::array<std::pair<std::string_view, FrfMethod>, 2> frf_method_names{{
    {"simulation", FrfMethod::simulation}, {"continuation", FrfMethod::continuation}}};

/// Newton's method on the stroboscopic map, and the sampling of a converged orbit's peaks.
struct ShootingOptions {
  /// Converged when max |P^k(w) − w| ≤ tolerance × max(1, max |w|) in the scaled state w.
  double tolerance = 1e-10;
  int max_iterations = 25;  ///< Newton iterations before a point is declared not converged.

  static constexpr auto fields() {
    using O = ShootingOptions;
    return std::tuple{
        NumberField{"tolerance", &O::tolerance, "", Interval{.lo = 0.0, .hi = 1e-3, .lo_open = true},
                    "Newton stops when the scaled state repeats to this"},
        IntegerField{"max_iterations", &O::max_iterations, 1, 1000, "Newton iterations per point"},
    };
  }
  void validate() const;
};

/// What is special about a point of a branch.
enum class BifurcationKind : std::uint8_t {
  none,
  fold,              ///< a multiplier passes +1: the branch turns back in the parameter
  period_doubling,   ///< a multiplier passes −1: a period-2k branch is born
  neimark_sacker,    ///< a complex pair leaves (or enters) the unit circle
  grazing,           ///< the orbit's events change: an element starts or stops touching
  end,               ///< the branch ends: Newton failed below the smallest step
};

[[nodiscard]] std::string_view to_string(BifurcationKind kind);



/// The ratios of a frequency response by continuation that are also simulated from rest, to seed
/// the stable orbits no continued branch reaches (coexisting responses born at a fold or a
/// grazing rather than at a period doubling of a branch followed).
enum class RestSeeds : std::uint8_t {
  unstable,  ///< only the ratios where every continued orbit is unstable
  every,     ///< every ratio: the response from rest is always among the stable orbits reported
};

/// Options of pseudo-arclength continuation. Step lengths are in the scaled space (w, p).
struct ContinuationOptions {
  double initial_step = 0.05;
  double min_step = 1e-6;
  double max_step = 1.0;
  /// The largest change of the parameter in one step (keeps a branch as finely resolved as a
  /// brute-force sweep of the same range).
  double max_parameter_step = 0.01;
  int max_points = 5000;          ///< per branch
  int max_periodicity = 8;        ///< period doublings are followed up to this k
  int newton_iterations = 8;      ///< corrector iterations before the step is halved
  /// Relative forward-difference step for ∂F/∂p.
  double difference_step = 1e-7;
  /// Runs of the map (one forcing period each, k for a period-k orbit) allowed per ratio of a
  /// frequency response: the budget of the whole continuation is this × the ratios. Where it is
  /// spent, the ratios not yet reached are simulated.
  int evaluations_per_ratio = 200;
  /// Events the corrector's runs may cross per ratio (a second budget, beside the runs: a run of
  /// 150 impacts costs some 75 runs of 2). Where it is spent, the piece's ratios not yet reached
  /// are simulated.
  int events_per_ratio = 2000;
  /// A frequency response is continued in pieces of this many ratios, each seeded at its lowest
  /// ratio, continued up to the next piece's and spending only its own share of the budget; the
  /// pieces run in parallel (FrequencyResponseOptions::threads) and are fixed by the ratios, so
  /// the result does not depend on the threads. A branch that crosses into the next piece is
  /// followed there again from that piece's seed, under another branch id.
  int ratios_per_segment = 12;
  /// Where the response from rest is simulated (up to a quarter of the steady state's
  /// max_periods) and, when it settles on a stable orbit no branch has reached, continued both
  /// ways on a ratio's budget. `every` costs about a simulated frequency response more.
  RestSeeds seeds_from_rest = RestSeeds::every;
  /// The runs one continue_orbits call may make (the frequency response sets it from the above).
  long max_evaluations = 10'000'000;
  /// The events one continue_orbits call's runs may cross (the frequency response sets it from
  /// events_per_ratio).
  long max_events = 1'000'000'000'000;
  /// A continued period-k orbit is labelled with the least j dividing k for which P^j returns
  /// its state to within this (scaled as the shooting residual, 10³ × its default tolerance): a
  /// period-2 orbit closer than that to repeating every period is at its period doubling.
  double period_tolerance = 1e-7;

  static constexpr auto fields() {
    using O = ContinuationOptions;
    return std::tuple{
        NumberField{"initial_step", &O::initial_step, "", positive, "first arclength step (scaled state and parameter)"},
        NumberField{"min_step", &O::min_step, "", positive, "below this a branch ends"},
        NumberField{"max_step", &O::max_step, "", positive, "largest arclength step"},
        NumberField{"max_parameter_step", &O::max_parameter_step, "", positive,
                    "largest change of the parameter in one step"},
        IntegerField{"max_points", &O::max_points, 2, 1'000'000, "points per branch"},
        IntegerField{"max_periodicity", &O::max_periodicity, 1, 64, "period doublings followed up to this k"},
        IntegerField{"newton_iterations", &O::newton_iterations, 2, 100, "corrector iterations before halving the step"},
        NumberField{"difference_step", &O::difference_step, "", Interval{.lo = 0.0, .hi = 1e-2, .lo_open = true},
                    "relative step of the parameter's forward difference"},
        IntegerField{"evaluations_per_ratio", &O::evaluations_per_ratio, 1, 1'000'000,
                     "runs of the map allowed per ratio; beyond, the remaining ratios are simulated"},
        IntegerField{"events_per_ratio", &O::events_per_ratio, 1, 1'000'000'000,
                     "events the runs may cross per ratio; beyond, the remaining ratios are simulated"},
        IntegerField{"ratios_per_segment", &O::ratios_per_segment, 1, 1'000'000,
                     "the ratios continued as one piece, on its own budget and thread"},
        ChoiceField{"seeds_from_rest", &O::seeds_from_rest,
                    std::array{std::pair<std::string_view, RestSeeds>{"every", RestSeeds::every},
                               std::pair<std::string_view, RestSeeds>{"unstable", RestSeeds::unstable}},
                    "ratios simulated from rest to seed the stable orbits no branch reached: every ratio, or "
                    "only where every continued orbit is unstable"},
    };
  }
  void validate() const;
};

}  // namespace poundsim
