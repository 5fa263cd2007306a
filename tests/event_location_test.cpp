#include "poundsim/integrate/event_location.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace poundsim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Guards given as functions of τ, with their derivatives (or none).
class FunctionGuards final : public GuardEvaluator {
 public:
  using F = std::function<double(double)>;
  FunctionGuards(std::vector<F> f, std::vector<F> df = {}) : f_(std::move(f)), df_(std::move(df)) {}
  void evaluate(double tau, GuardSample out) override {
    for (std::size_t j = 0; j < f_.size(); ++j) {
      out.value[j] = f_[j](tau);
      out.rate[j] = j < df_.size() ? df_[j](tau) : kNaN;
    }
  }
  void keep_trial_as_upper() override { ++kept; }
  int kept = 0;
  std::size_t size() const { return f_.size(); }

 private:
  std::vector<F> f_, df_;
};

struct Located {
  EventBracket bracket;
  std::vector<double> lo, hi;
};

Located locate(FunctionGuards& guards, double hi, double tol) {
  const std::size_t n = guards.size();
  std::vector<double> glo(n), ghi(n), gw(n), dlo(n), dhi(n), dw(n);
  guards.evaluate(0.0, {glo, dlo});
  guards.evaluate(hi, {ghi, dhi});
  const EventBracket b = locate_first_event(0.0, hi, {glo, dlo}, {ghi, dhi}, {gw, dw}, tol, guards);
  return {b, glo, ghi};
}

TEST(EventLocation, BracketsTheRootToTheTolerance) {
  const double root = 0.3141592653589793;
  FunctionGuards guards({[&](double t) { return std::sin(8 * (t - root)); }});
  for (const double tol : {1e-4, 1e-8, 1e-12}) {
    const Located r = locate(guards, 0.5, tol);
    EXPECT_LE(r.bracket.hi - r.bracket.lo, tol);
    EXPECT_LE(r.bracket.lo, root);
    EXPECT_GE(r.bracket.hi, root);
    EXPECT_GT(r.hi[0], 0.0);
    EXPECT_LE(r.lo[0], 0.0);
  }
}

TEST(EventLocation, ConvergesFasterThanBisection) {
  // Bisection from 0.5 to 1e-12 needs 39 evaluations; Illinois needs far fewer on a smooth guard.
  const double root = 0.123456789;
  FunctionGuards guards({[&](double t) { return std::exp(t) - std::exp(root); }});
  const Located r = locate(guards, 0.5, 1e-12);
  EXPECT_LE(r.bracket.hi - r.bracket.lo, 1e-12);
  EXPECT_LE(r.bracket.evaluations, 15);
}

TEST(EventLocation, RatesFindAFlatStartInAFewEvaluations) {
  // A pair just after a small bounce: g = −r τ + ½ a τ², zero at the start and back to zero at
  // 2r/a = 5e-6 s, a step of 1e-3 s. Linear interpolation creeps from the start; the cubic model
  // with rates predicts the root at once.
  const double r = 6e-7, a = 0.24;
  FunctionGuards guards({[&](double t) { return -r * t + 0.5 * a * t * t; }},
                        {[&](double t) { return -r + a * t; }});
  const Located res = locate(guards, 1e-3, 1e-10);
  EXPECT_NEAR(res.bracket.hi, 2 * r / a, 1e-10);
  EXPECT_LE(res.bracket.evaluations, 4);
}

TEST(EventLocation, FindsTheEarliestOfSeveralGuards) {
  // Guard 1 fires at 0.4, guard 0 at 0.25: the bracket must close on 0.25 although guard 1
  // has the larger value at the upper end.
  FunctionGuards guards({[](double t) { return t - 0.25; }, [](double t) { return 100 * (t - 0.4); },
                         [](double) { return -std::numeric_limits<double>::infinity(); }});
  const Located r = locate(guards, 1.0, 1e-10);
  EXPECT_NEAR(r.bracket.hi, 0.25, 1e-10);
  EXPECT_GT(r.hi[0], 0.0);
  EXPECT_LT(r.hi[1], 0.0);
}

TEST(EventLocation, SimultaneousRootsFireTogether) {
  FunctionGuards guards({[](double t) { return t - 0.5; }, [](double t) { return 3 * (t - 0.5); }});
  const Located r = locate(guards, 1.0, 1e-10);
  EXPECT_GT(r.hi[0], 0.0);
  EXPECT_GT(r.hi[1], 0.0);
  EXPECT_LE(r.bracket.hi - r.bracket.lo, 1e-10);
}

TEST(EventLocation, KeepsTheStateOfTheUpperEnd) {
  // The evaluator is told each time a trial becomes the new upper end; the last one is the event.
  FunctionGuards guards({[](double t) { return t * t - 0.04; }});
  const Located r = locate(guards, 1.0, 1e-12);
  EXPECT_GT(guards.kept, 0);
  EXPECT_NEAR(r.bracket.hi, 0.2, 1e-12);
}

TEST(EventLocation, WrongRatesStillConverge) {
  // Rates that do not belong to the function (as round-off can make them near a tangency) only
  // cost evaluations: the bracket and the bisection safeguard still close on the root.
  FunctionGuards guards({[](double t) { return t - 0.3; }}, {[](double t) { return -5.0 + t; }});
  const Located r = locate(guards, 1.0, 1e-10);
  EXPECT_NEAR(r.bracket.hi, 0.3, 1e-10);
  EXPECT_LE(r.bracket.evaluations, 80);
}

}  // namespace
}  // namespace poundsim
