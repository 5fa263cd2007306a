#include "poundsim/analysis/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace poundsim {

int hardware_threads() { return std::max(1, static_cast<int>(std::thread::hardware_concurrency())); }

void parallel_for(int count, int threads, const std::function<void(int)>& body) {
  if (count <= 0) return;
  const int workers = std::clamp(threads > 0 ? threads : hardware_threads(), 1, count);
  std::atomic<int> next{0};
  // The error of the lowest index that fails, whatever the threads: indices are handed out in
  // order, so every index below a failed one still runs, and none above it starts.
  std::atomic<int> first_failed{count};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&] {
    for (int i = next++; i < count && i < first_failed; i = next++) {
      try {
        body(i);
      } catch (...) {
        const std::lock_guard lock(error_mutex);
        if (i < first_failed) {
          first_failed = i;
          error = std::current_exception();
        }
      }
    }
  };
  if (workers == 1) {
    work();
  } else {
    std::vector<std::jthread> pool;
    for (int w = 0; w < workers; ++w) pool.emplace_back(work);
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace poundsim
