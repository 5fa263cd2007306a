#include "poundsim/model/frame.hpp"

#include <cmath>
#include <complex>
#include <numbers>

#include <string>

#include <gtest/gtest.h>

namespace poundsim {
namespace {

TEST(Frame, SingleStoreyFrequencyIsSqrtKOverM) {
  EXPECT_NEAR(fundamental_frequency(make_uniform_frame(1, 2.0, 800.0, 0.0)), 20.0, 1e-12);
}

TEST(Frame, UniformChainFrequenciesMatchClosedForm) {
  // Uniform shear chain fixed at the base, free at the top:
  // ω_r = 2 λ sin((2r − 1) π / (2 (2n + 1))), λ² = K/M.
  const int n = 5;
  const double m = 3.0, k = 1200.0, lambda = std::sqrt(k / m);
  const Eigen::VectorXd w = natural_frequencies(make_uniform_frame(n, m, k, 0.0));
  ASSERT_EQ(w.size(), n);
  for (int r = 1; r <= n; ++r) {
    const double exact = 2 * lambda * std::sin((2 * r - 1) * std::numbers::pi / (2 * (2 * n + 1)));
    EXPECT_NEAR(w(r - 1), exact, 1e-10 * exact) << "mode " << r;
  }
}

TEST(Frame, HarmonicAmplitudesOfASingleStoreyAreTheClosedForm) {
  // m ü + c u̇ + k u = −m A sin ω̄t: u = Im(U e^{iω̄t}), U = −m A / (k − ω̄² m + iω̄c).
  const double m = 2.0, k = 800.0, c = 4.0, a = 1.5, w = 17.0;
  const Eigen::VectorXcd u = harmonic_amplitudes(make_uniform_frame(1, m, k, c), a, w);
  ASSERT_EQ(u.size(), 1);
  const std::complex<double> exact = -m * a / std::complex<double>(k - w * w * m, w * c);
  EXPECT_NEAR(std::abs(u(0) - exact), 0.0, 1e-14 * std::abs(exact));
}

TEST(Frame, WeightIsGravityTimesTheTotalMass) {
  Frame f = make_uniform_frame(3, 2.0e5, 1.0e7, 0.0);
  f.mass[2] = 1.0e5;
  EXPECT_DOUBLE_EQ(weight(f), 5.0e5 * 9.81);  // g = 9.81 m/s², as in the paper
}

TEST(Frame, StiffnessProportionalDampingGivesTheRatioInModeOne) {
  const Frame f = make_uniform_frame(3, 1.0, 400.0, 0.0);
  const std::vector<double> c = stiffness_proportional_damping(f, 0.05);
  // C = a K with a = 2ζ/ω₁: the modal damping ratio of mode 1 is a ω₁ / 2 = ζ.
  const double a = c[0] / f.stiffness[0];
  EXPECT_NEAR(a * fundamental_frequency(f) / 2, 0.05, 1e-14);
  EXPECT_DOUBLE_EQ(c[1] / f.stiffness[1], a);
}

TEST(Frame, ValidateRejectsNonPhysicalValues) {
  Frame f = make_uniform_frame(2, 1.0, 1.0, 0.0);
  f.mass[1] = 0.0;
  try {
    validate(f);
    ADD_FAILURE() << "a floor without mass";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "frame: mass[2] = 0 kg must be > 0");  // Frame::fields()' rule
  }
  f = make_uniform_frame(2, 1.0, 1.0, 0.0);
  f.storey_height = {3.0, std::nan("")};
  EXPECT_THROW(validate(f), std::invalid_argument);
  f = make_uniform_frame(2, 1.0, 1.0, 0.0);
  f.damping[0] = -1.0;
  EXPECT_THROW(validate(f), std::invalid_argument);
  f = make_uniform_frame(2, 1.0, 1.0, 0.0);
  f.stiffness.pop_back();
  EXPECT_THROW(validate(f), std::invalid_argument);
  // Storey-law parameters for every storey or none.
  f = make_uniform_frame(2, 1.0, 1.0, 0.0);
  f.storey_law = PerStorey<LinearStorey>{.values = {{}, {}}};
  EXPECT_NO_THROW(validate(f));
  f.storey_law = PerStorey<LinearStorey>{.values = {{}, {}, {}}};
  try {
    validate(f);
    ADD_FAILURE() << "three storeys' parameters for two storeys";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("given for 3 storeys, the frame has 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace poundsim
