#include "poundsim/event_location.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace poundsim {
namespace {

class FunctionGuards final : public GuardEvaluator {
 public:
  explicit FunctionGuards(std::vector<std::function<double(double)>> f) : f_(std::move(f)) {}
  void evaluate(double tau, std::span<double> g) override {
    for (std::size_t j = 0; j < f_.size(); ++j) g[j] = f_[j](tau);
  }
  void keep_trial_as_upper() override { ++kept; }
  int kept = 0;

 private:
  std::vector<std::function<double(double)>> f_;
};

EventBracket locate(FunctionGuards& guards, double hi, double tol, std::vector<double>& glo,
                    std::vector<double>& ghi) {
  std::vector<double> work(glo.size());
  guards.evaluate(0.0, glo);
  guards.evaluate(hi, ghi);
  return locate_first_event(0.0, hi, glo, ghi, work, tol, guards);
}

TEST(EventLocation, BracketsTheRootToTheTolerance) {
  const double root = 0.3141592653589793;
  FunctionGuards guards({[&](double t) { return std::sin(8 * (t - root)); }});
  std::vector<double> glo(1), ghi(1);
  for (const double tol : {1e-4, 1e-8, 1e-12}) {
    const EventBracket b = locate(guards, 0.5, tol, glo, ghi);
    EXPECT_LE(b.hi - b.lo, tol);
    EXPECT_LE(b.lo, root);
    EXPECT_GE(b.hi, root);
    EXPECT_GT(ghi[0], 0.0);
    EXPECT_LE(glo[0], 0.0);
  }
}

TEST(EventLocation, ConvergesFasterThanBisection) {
  // Bisection from 0.5 to 1e-12 needs 39 evaluations; Illinois needs far fewer on a smooth guard.
  const double root = 0.123456789;
  FunctionGuards guards({[&](double t) { return std::exp(t) - std::exp(root); }});
  std::vector<double> glo(1), ghi(1);
  const EventBracket b = locate(guards, 0.5, 1e-12, glo, ghi);
  EXPECT_LE(b.hi - b.lo, 1e-12);
  EXPECT_LE(b.evaluations, 15);
}

TEST(EventLocation, FindsTheEarliestOfSeveralGuards) {
  // Guard 1 fires at 0.4, guard 0 at 0.25: the bracket must close on 0.25 although guard 1
  // has the larger value at the upper end.
  FunctionGuards guards({[](double t) { return t - 0.25; }, [](double t) { return 100 * (t - 0.4); },
                         [](double) { return -std::numeric_limits<double>::infinity(); }});
  std::vector<double> glo(3), ghi(3);
  const EventBracket b = locate(guards, 1.0, 1e-10, glo, ghi);
  EXPECT_NEAR(b.hi, 0.25, 1e-10);
  EXPECT_GT(ghi[0], 0.0);
  EXPECT_LT(ghi[1], 0.0);
}

TEST(EventLocation, SimultaneousRootsFireTogether) {
  FunctionGuards guards({[](double t) { return t - 0.5; }, [](double t) { return 3 * (t - 0.5); }});
  std::vector<double> glo(2), ghi(2);
  const EventBracket b = locate(guards, 1.0, 1e-10, glo, ghi);
  EXPECT_GT(ghi[0], 0.0);
  EXPECT_GT(ghi[1], 0.0);
  EXPECT_LE(b.hi - b.lo, 1e-10);
}

TEST(EventLocation, KeepsTheStateOfTheUpperEnd) {
  // The evaluator is told each time a trial becomes the new upper end; the last one is the event.
  FunctionGuards guards({[](double t) { return t * t - 0.04; }});
  std::vector<double> glo(1), ghi(1);
  const EventBracket b = locate(guards, 1.0, 1e-12, glo, ghi);
  EXPECT_GT(guards.kept, 0);
  EXPECT_NEAR(b.hi, 0.2, 1e-12);
}

}  // namespace
}  // namespace poundsim
