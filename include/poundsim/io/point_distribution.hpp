#pragma once
/// @file
/// Where the points of a study or an ensemble (and the designs of an optimisation's batches) run
/// when more than one process shares them: the ranks of an MPI job (`mpirun -n N poundsim run
/// study.toml`, apps/mpi_distribution.hpp). The
/// io layer knows only this interface, so the library links no MPI. One rank, the coordinator,
/// owns the study database: it hands the points out one at a time, the next to whichever rank
/// returns a result first (points differ in cost by orders of magnitude), computes points itself
/// meanwhile, and records each result as it arrives. The other ranks, the workers, compute what
/// they are sent. A task and its result are opaque bytes: every rank has read the same input, so a
/// task need only name its point (docs/studies.md#distributed-studies-on-mpi).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace poundsim::io {

/// `value` as CBOR in a task's or a result's bytes (every double to the bit).
[[nodiscard]] inline std::string cbor_bytes(const nlohmann::json& value) {
  const std::vector<std::uint8_t> bytes = nlohmann::json::to_cbor(value);
  return {bytes.begin(), bytes.end()};
}

class PointDistribution {
 public:
  virtual ~PointDistribution() = default;

  /// The processes sharing the points, the coordinator included (≥ 1).
  [[nodiscard]] virtual int ranks() const = 0;
  /// True on the process that owns the database and hands out the points.
  [[nodiscard]] virtual bool is_coordinator() const = 0;

  /// One phase of a run, called by every rank in the same order. On the coordinator: hands out
  /// `tasks`, computes some of them itself with `compute`, and calls `store(index, result)` on
  /// this thread for each result as it arrives; once `stop()` is true it hands out no more and
  /// waits for those out. On a worker: computes every task it is sent until the coordinator ends
  /// the phase (`tasks`, `store` and `stop` unused). Returns, on every rank, whether the phase
  /// was stopped before all its tasks were handed out.
  virtual bool run_phase(const std::vector<std::string>& tasks,
                         const std::function<std::string(const std::string&)>& compute,
                         const std::function<void(std::size_t, const std::string&)>& store,
                         const std::function<bool()>& stop) = 0;

  /// For a run whose number of phases only the coordinator knows (an optimisation: one phase per
  /// evaluation). On a worker: serves phases until the coordinator calls finish(). On the
  /// coordinator: nothing.
  virtual void serve_until_finished(const std::function<std::string(const std::string&)>& compute) = 0;
  /// On the coordinator: ends serve_until_finished on every worker.
  virtual void finish() = 0;
};

}  // namespace poundsim::io
