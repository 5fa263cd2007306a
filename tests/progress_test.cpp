// The time left that the progress bars show.

#include "poundsim/analysis/progress.hpp"

#include <gtest/gtest.h>

namespace poundsim {
namespace {

TEST(TimeLeft, IsTheRateSinceTheRunBeganTimesTheItemsLeft) {
  TimeLeft left;
  EXPECT_FALSE(left.update(0, 40, 0.0));  // no rate yet
  EXPECT_FALSE(left.update(0, 40, 3.0));
  EXPECT_DOUBLE_EQ(*left.update(10, 40, 5.0), 15.0);  // 2 items/s, 30 left
  EXPECT_DOUBLE_EQ(*left.update(30, 40, 12.0), 4.0);
  EXPECT_EQ(*left.update(40, 40, 13.0), 0.0);
}

// A resumed study reports its earlier points done at once: they say nothing of this run's rate.
TEST(TimeLeft, PointsFinishedBeforeTheRunDoNotCount) {
  TimeLeft left;
  EXPECT_FALSE(left.update(150, 200, 0.01));
  EXPECT_DOUBLE_EQ(*left.update(160, 200, 8.0), 32.0);  // 10 points in 8 s, 40 left
}

TEST(TimeLeft, ReadsAsABarShowsIt) {
  EXPECT_EQ(readable_duration(0.2), "1 s");
  EXPECT_EQ(readable_duration(45.0), "45 s");
  EXPECT_EQ(readable_duration(200.0), "3 min 20 s");
  EXPECT_EQ(readable_duration(7500.0), "2 h 05 min");
  EXPECT_EQ(readable_duration(-1.0), "?");
}

}  // namespace
}  // namespace poundsim
