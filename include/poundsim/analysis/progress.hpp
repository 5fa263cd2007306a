#pragma once
/// @file
/// The time left of a run of many items (study points, ensemble records, optimiser evaluations,
/// frequencies), from the rate of the items done since the run began: the progress bars of the
/// command line and of the Python module show it. Items finished by an earlier run (a
/// resumed study) are reported done at the first update and do not count to the rate.

#include <optional>
#include <string>

namespace poundsim {

class TimeLeft {
 public:
  /// `done` of `total` items at `elapsed` seconds since the first update. Nothing until an item
  /// has been done since then (no rate yet); 0 when all are done.
  [[nodiscard]] std::optional<double> update(long done, long total, double elapsed);

 private:
  std::optional<long> first_done_;
};

/// "45 s", "3 min 20 s", "2 h 05 min": a duration as a progress bar shows it (rounded up to the
/// second).
[[nodiscard]] std::string readable_duration(double seconds);

}  // namespace poundsim
