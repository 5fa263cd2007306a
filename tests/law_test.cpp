// Links with laws: each law's linear form is its force, and the links of a model are its storeys
// and gap elements in the order assembly and energy sums follow.
#include "poundsim/model/law.hpp"

#include <gtest/gtest.h>

#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {
namespace {

double evaluate(const LinearForm& form, double d, double rate) {
  return form.stiffness * d + form.damping * rate + form.force_at_zero;
}

TEST(LinearStoreyLaw, ItsLinearFormIsItsForceAndItStoresHalfKDriftSquared) {
  const LinearStorey storey{.stiffness = 400.0, .damping = 3.0};
  const LinearForm form = *Link{.law = storey}.linear_form(0);
  EXPECT_EQ(form.stiffness, 400.0);
  EXPECT_EQ(form.damping, 3.0);
  EXPECT_FALSE(form.rigid);
  EXPECT_DOUBLE_EQ(evaluate(form, 0.02, -0.5), 400.0 * 0.02 - 3.0 * 0.5);
  EXPECT_DOUBLE_EQ(storey.force(0.02, -0.5), 6.5);
  EXPECT_DOUBLE_EQ(storey.stored_energy(0.02), 0.08);
  EXPECT_DOUBLE_EQ(storey.dissipated_power(-0.5), 0.75);
  EXPECT_FALSE(LinearStorey::traits.has_stop);
  EXPECT_EQ(LinearStorey::traits.energy, EnergyGroup::storey);
}

TEST(PaperGapLaw, OpenTransmitsNothingContactIsTheSpringAndDashpotLockedIsRigid) {
  const GapProperties p{.stiffness = 2e5, .damping = 300.0, .gap = 0.01, .shortening = 0.004,
                        .restitution = 0.6};
  const Link link{.a = 0, .b = 1, .law = PaperGap{p}, .element = 0};
  EXPECT_FALSE(link.linear_form(PaperGap::link_mode(GapMode::open)));
  const LinearForm contact = *link.linear_form(PaperGap::link_mode(GapMode::contact));
  // d = u_L − u_R = 0.012: s = 0.002 past the gap; ṡ = ḋ = 0.3.
  EXPECT_DOUBLE_EQ(evaluate(contact, 0.012, 0.3), contact_force(p, 0.002, 0.3));
  EXPECT_DOUBLE_EQ(evaluate(contact, 0.012, 0.3), 2e5 * 0.002 + 300.0 * 0.3);
  EXPECT_FALSE(contact.rigid);
  const LinearForm locked = *link.linear_form(PaperGap::link_mode(GapMode::locked));
  EXPECT_TRUE(locked.rigid);
  EXPECT_EQ(locked.stiffness, contact.stiffness);
  const PaperGap gap{p};
  const LinkKinematics pressed{.ua = 0.015, .ub = 0.003, .va = 0.5, .vb = 0.2};
  EXPECT_DOUBLE_EQ(gap.stored_energy(pressed, PaperGap::link_mode(GapMode::contact), {}),
                   0.5 * 2e5 * 0.002 * 0.002);
  EXPECT_DOUBLE_EQ(gap.dissipated_power(pressed, PaperGap::link_mode(GapMode::contact), {}),
                   300.0 * 0.3 * 0.3);
  EXPECT_EQ(gap.dissipated_power(pressed, PaperGap::link_mode(GapMode::open), {}), 0.0);
  // Open and relaxing after a force separation: the free end's shortening s_e(t).
  const PaperGap::State relaxing{.released_shortening = 0.001, .release_time = 1.0};
  const double se = 0.001 * std::exp(-2e5 / 300.0 * 0.001);
  EXPECT_NEAR(gap.stored_energy(LinkKinematics{.t = 1.001}, PaperGap::link_mode(GapMode::open),
                                relaxing),
              0.5 * 2e5 * se * se, 1e-12 * 0.5 * 2e5 * se * se);  // 1.001 − 1 is not 0.001 exactly
  EXPECT_EQ(gap.dashpot(PaperGap::link_mode(GapMode::open)), 0.0);
  // What the relaxing spring releases into its dashpot: ½ k (s_e(t0)² − s_e(t1)²).
  const double se2 = 0.001 * std::exp(-2e5 / 300.0 * 0.002);
  EXPECT_NEAR(gap.relaxation_release(PaperGap::link_mode(GapMode::open), relaxing, 1.001, 1.002),
              0.5 * 2e5 * (se * se - se2 * se2), 1e-12 * 0.5 * 2e5 * se * se);
  EXPECT_TRUE(PaperGap::traits.has_stop);
  EXPECT_EQ(PaperGap::traits.energy, EnergyGroup::gap_element);
}

TEST(Links, StoreysByDofThenGapElements) {
  const Model m = make_model({make_uniform_frame(2, 1.0, 100.0, 1.0),
                              make_uniform_frame(3, 2.0, 300.0, 2.0)},
                             GapProperties{.stiffness = 50.0, .gap = 0.01, .shortening = 0.02});
  const DofLayout layout(m);
  const std::vector<Link> links = make_links(m, layout);
  ASSERT_EQ(links.size(), 5u + 2u);
  for (int i = 0; i < layout.size(); ++i) {
    EXPECT_EQ(links[i].a, i);
    EXPECT_EQ(links[i].b, layout.below(i));
    EXPECT_EQ(std::get<LinearStorey>(links[i].law).stiffness,
              m.frames[layout.frame_of(i)].stiffness[layout.floor_of(i)]);
    EXPECT_EQ(links[i].element, -1);
    EXPECT_EQ(links[i].slot, i);  // the i-th linear storey
  }
  for (int p = 0; p < 2; ++p) {
    const Link& gap = links[5 + p];
    EXPECT_EQ(gap.element, p);
    EXPECT_EQ(gap.slot, p);  // the p-th paper's element
    EXPECT_EQ(gap.a, layout.gap_left(p));
    EXPECT_EQ(gap.b, layout.gap_right(p));
  }
}

// Each law's links keep their law's State, by slot: the storeys' (nothing) and the elements'.
TEST(Links, EachLinkKeepsItsLawsStateBySlot) {
  const Model m = make_model({make_uniform_frame(2, 1.0, 100.0, 1.0),
                              make_uniform_frame(3, 2.0, 300.0, 2.0)},
                             GapProperties{.stiffness = 50.0, .damping = 1.0, .gap = 0.01, .shortening = 0.02});
  const std::vector<Link> links = make_links(m, DofLayout(m));
  LinkStates states(links);
  EXPECT_EQ(states.of(LinearStorey{}).size(), 5U);
  ASSERT_EQ(states.of(PaperGap{}).size(), 2U);
  const PaperGap& second = std::get<PaperGap>(links[6].law);
  states.at(second, links[6].slot) = {.released_shortening = 0.003, .release_time = 2.0};
  EXPECT_EQ(states.of(PaperGap{})[0], PaperGap::State{});
  states.shift_clock(0.5);
  EXPECT_EQ(states.at(second, 1).release_time, 1.5);
  EXPECT_EQ(states.at(second, 1).released_shortening, 0.003);
  EXPECT_EQ(states.of(PaperGap{})[0].release_time, -0.5);
}

TEST(Links, PhaseAssemblyAddsEachLinkInItsMode) {
  // Two single-storey frames, the element in contact: K = [[K1 + k, −k], [−k, K2 + k]] and the
  // load +kδ on the left floor, −kδ on the right one (the paper's a(t)).
  const Model m = make_model({make_uniform_frame(1, 1.0, 100.0, 1.0),
                              make_uniform_frame(1, 2.0, 300.0, 2.0)},
                             GapProperties{.stiffness = 50.0, .damping = 5.0, .gap = 0.01,
                                           .shortening = 0.02});
  const DofLayout layout(m);
  const LinearPhase contact(m, layout, {PaperGap::link_mode(GapMode::contact)}, 1e-3);
  const Eigen::MatrixXd k = Eigen::MatrixXd(contact.full_stiffness());
  EXPECT_EQ(k(0, 0), 150.0);
  EXPECT_EQ(k(1, 1), 350.0);
  EXPECT_EQ(k(0, 1), -50.0);
  EXPECT_EQ(Eigen::MatrixXd(contact.full_damping())(1, 1), 7.0);
  EXPECT_DOUBLE_EQ(contact.full_constant_load()(0), 0.5);
  EXPECT_DOUBLE_EQ(contact.full_constant_load()(1), -0.5);
  const LinearPhase open(m, layout, {PaperGap::link_mode(GapMode::open)}, 1e-3);
  EXPECT_EQ(Eigen::MatrixXd(open.full_stiffness())(0, 1), 0.0);
  EXPECT_EQ(open.full_constant_load().norm(), 0.0);
  const LinearPhase locked(m, layout, {PaperGap::link_mode(GapMode::locked)}, 1e-3);
  EXPECT_EQ(locked.reduced_size(), 1);  // one group: the rigid link joins the floors
  EXPECT_DOUBLE_EQ(locked.offset()(1), -0.03);  // u_R = u_L − (δ + ε)
}

}  // namespace
}  // namespace poundsim
