// Which integrator integrates which laws (integrate/integrator.hpp): both step the linear phase of
// each mode, so both refuse a law that is not piecewise linear (Newmark until it has a Newton
// iteration), naming the link and why, rather than drop its force.

#include "poundsim/integrate/integrator.hpp"

#include <array>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "test_models.hpp"

namespace poundsim {
namespace {

TEST(IntegratorSupport, ExactNeedsPiecewiseLinearLawsNewmarkATangent) {
  const LawTraits without_tangent{.piecewise_linear = false, .newton = false, .has_stop = false,
                                  .energy = EnergyGroup::gap_element, .name = "a law without tangent"};
  const std::array<LawTraits, 3> laws{LinearStorey::traits, PaperGap::traits, Hertz::traits};
  const IntegratorSupport exact = supports(Integrator::exact, laws);
  EXPECT_FALSE(exact);
  EXPECT_NE(exact.reason.find("link 3 (the Hertz contact) is not piecewise linear: use integrator = \"newmark\""),
            std::string::npos)
      << exact.reason;
  EXPECT_TRUE(supports(Integrator::newmark, laws));
  const std::array<LawTraits, 2> untangent{LinearStorey::traits, without_tangent};
  const IntegratorSupport newmark = supports(Integrator::newmark, untangent);
  EXPECT_FALSE(newmark);
  EXPECT_NE(newmark.reason.find("link 2 (a law without tangent) is neither"), std::string::npos) << newmark.reason;
  EXPECT_TRUE(supports(Integrator::exact, std::span(laws).first(2)));
  EXPECT_TRUE(supports(Integrator::newmark, std::span(laws).first(2)));
}

TEST(IntegratorSupport, BothIntegrateThePapersModels) {
  const Model model = make_model(testing::fig2('c'), {4, 4});
  const std::vector<Link> links = make_links(model, DofLayout(model));
  EXPECT_EQ(links.size(), 8u + 4u);  // eight storeys, four gap elements
  EXPECT_TRUE(supports(Integrator::newmark, links, DofLayout(model)));
  EXPECT_TRUE(supports(Integrator::exact, links, DofLayout(model)));
}

// A link is named by its floors and its law in every message about it.
TEST(LinkDescription, NamesTheFloorsAndTheLaw) {
  const Model model = make_model(testing::fig2('c'), {2, 3});
  const DofLayout layout(model);
  const std::vector<Link> links = make_links(model, layout);
  ASSERT_EQ(links.size(), 5u + 2u);
  EXPECT_EQ(describe(links[static_cast<std::size_t>(layout.dof(1, 2))], layout), "storey 3 of frame 2 (linear storey)");
  EXPECT_EQ(describe(links[static_cast<std::size_t>(layout.dof(0, 0))], layout), "storey 1 of frame 1 (linear storey)");
  EXPECT_EQ(describe(links[6], layout), "the paper's gap element between frames 1 and 2 at floor 2");
}

}  // namespace
}  // namespace poundsim
