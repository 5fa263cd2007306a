// parallel_for's error is the lowest failing index's, whatever the threads (a study or an
// ensemble reports the same record's error on one thread, on many and on MPI ranks).

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "poundsim/analysis/parallel.hpp"

namespace poundsim {
namespace {

// Index 61 fails at once; index 23 fails only after a pause, so on several threads 61 fails
// first in time. Every index up to 23 runs; the error is 23's.
TEST(ParallelFor, RethrowsTheLowestFailingIndexWhateverTheThreads) {
  for (const int threads : {1, 2, 4, 8}) {
    SCOPED_TRACE(threads);
    std::atomic<int> ran_below{0};
    try {
      parallel_for(100, threads, [&](int i) {
        if (i < 23) ++ran_below;
        if (i == 23) {
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
          throw std::runtime_error("index 23");
        }
        if (i == 61) throw std::runtime_error("index 61");
      });
      ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "index 23");
    }
    EXPECT_EQ(ran_below.load(), 23);
  }
}

}  // namespace
}  // namespace poundsim
