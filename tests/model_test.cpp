#include "poundsim/model/model.hpp"

#include <gtest/gtest.h>

namespace poundsim {
namespace {

TEST(Model, ElementsJoinSharedFloorsOfNeighbours) {
  const Model m = make_model({make_uniform_frame(3, 1, 1, 0), make_uniform_frame(1, 1, 1, 0),
                              make_uniform_frame(2, 1, 1, 0)},
                             GapProperties{.gap = 0.01});
  ASSERT_EQ(m.gap_count(), 2);  // 1–2 at floor 1, 2–3 at floor 1
  EXPECT_EQ(m.gaps[0].left_frame, 0);
  EXPECT_EQ(m.gaps[1].left_frame, 1);
  EXPECT_EQ(m.gaps[1].floor, 0);
}

TEST(Model, OverridesReplaceOneElement) {
  const GapOverride o{0, 1, GapProperties{.gap = 0.5, .restitution = 0.2}};
  const Model m = make_model({make_uniform_frame(2, 1, 1, 0), make_uniform_frame(2, 1, 1, 0)},
                             GapProperties{.gap = 0.01}, std::span(&o, 1));
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(m.gaps[0]).gap, 0.01);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(m.gaps[1]).gap, 0.5);
  const GapOverride bad{0, 2, {}};
  EXPECT_THROW(make_model({make_uniform_frame(2, 1, 1, 0), make_uniform_frame(2, 1, 1, 0)}, {},
                          std::span(&bad, 1)),
               std::invalid_argument);
}

TEST(DofLayout, InterleavesLevelsSoThatMatricesAreBanded) {
  const Model m = make_model({make_uniform_frame(3, 1, 1, 0), make_uniform_frame(1, 1, 1, 0),
                              make_uniform_frame(2, 1, 1, 0)},
                             GapProperties{});
  const DofLayout layout(m);
  ASSERT_EQ(layout.size(), 6);
  // Level 1: frames 1, 2, 3; level 2: frames 1, 3; level 3: frame 1.
  EXPECT_EQ(layout.dof(0, 0), 0);
  EXPECT_EQ(layout.dof(1, 0), 1);
  EXPECT_EQ(layout.dof(2, 0), 2);
  EXPECT_EQ(layout.dof(0, 1), 3);
  EXPECT_EQ(layout.dof(2, 1), 4);
  EXPECT_EQ(layout.dof(0, 2), 5);
  // A storey couples DOFs at most (number of frames) apart.
  for (int i = 0; i < layout.size(); ++i) {
    if (layout.below(i) >= 0) {
      EXPECT_LE(i - layout.below(i), m.frame_count());
    }
    EXPECT_EQ(layout.dof(layout.frame_of(i), layout.floor_of(i)), i);
  }
  // Elements 1–2 and 2–3 at floor 1.
  EXPECT_EQ(layout.gap_left(0), 0);
  EXPECT_EQ(layout.gap_right(0), 1);
  EXPECT_EQ(layout.gap_left(1), 1);
  EXPECT_EQ(layout.gap_right(1), 2);
}

TEST(Model, ValidateNamesTheElement) {
  Model m = make_model({make_uniform_frame(1, 1, 1, 0), make_uniform_frame(1, 1, 1, 0)},
                       GapProperties{.gap = 0.01, .restitution = 1.5});
  try {
    validate(m);
    FAIL() << "restitution 1.5 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("restitution"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("frames 1 and 2"), std::string::npos) << e.what();
  }
  // The rule between the law's parameters holds for a model built in code as for a file: a
  // spring on an element without stroke would never act.
  m.gaps[0].law = GapProperties{.stiffness = 1e5, .gap = 0.01, .shortening = 0.0, .restitution = 0.5};
  try {
    validate(m);
    FAIL() << "a spring without stroke accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("shortening = 0 is a rigid stop"), std::string::npos) << e.what();
  }
  parameters_of<PaperGap>(m.gaps[0]).shortening = 0.002;
  EXPECT_NO_THROW(validate(m));
}

}  // namespace
}  // namespace poundsim
