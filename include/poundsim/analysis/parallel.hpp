#pragma once
/// @file
/// A parallel loop over independent tasks. Each task writes only its own results, so the outcome
/// does not depend on the number of threads or on the order in which tasks finish.

#include <functional>

namespace poundsim {

/// Runs body(0) … body(count−1) on `threads` threads (0: all hardware threads, at most count).
/// The exception of the lowest index that throws is rethrown after every thread has stopped,
/// the same whatever the threads (every task below it still runs; tasks above it not yet
/// started are skipped).
void parallel_for(int count, int threads, const std::function<void(int)>& body);

/// The number of threads `threads` = 0 stands for.
[[nodiscard]] int hardware_threads();

}  // namespace poundsim
