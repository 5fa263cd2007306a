#pragma once
/// @file
/// The command line's MPI: `mpirun -n N poundsim run study.toml` shares a study's or an
/// ensemble's points among N processes (io/point_distribution.hpp says how). MPI is initialised
/// only when a launcher started the process (its environment says so), so that the same binary
/// runs alone, and fast, without one. Only the C API of Open MPI is used, from the main thread
/// (MPI_THREAD_FUNNELED); rank 0 computes its own points on a second thread meanwhile.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "poundsim/io/point_distribution.hpp"

namespace poundsim::apps {

/// MPI_Init … MPI_Finalize around main, when launched by mpirun.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  /// Whether MPI was initialised (the process was launched by mpirun).
  [[nodiscard]] bool active() const { return active_; }
  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int size() const { return size_; }
  /// Ends every rank of the job with `code` (a rank that fails alone would leave the others
  /// waiting for it).
  [[noreturn]] void abort(int code) const;

 private:
  bool active_ = false;
  int rank_ = 0, size_ = 1;
};

class MpiDistribution final : public io::PointDistribution {
 public:
  explicit MpiDistribution(const MpiSession& session) : rank_(session.rank()), size_(session.size()) {}

  [[nodiscard]] int ranks() const override { return size_; }
  [[nodiscard]] bool is_coordinator() const override { return rank_ == 0; }
  bool run_phase(const std::vector<std::string>& tasks, const std::function<std::string(const std::string&)>& compute,
                 const std::function<void(std::size_t, const std::string&)>& store,
                 const std::function<bool()>& stop) override;
  void serve_until_finished(const std::function<std::string(const std::string&)>& compute) override;
  void finish() override;

 private:
  /// How the coordinator ended a phase.
  enum class End : std::uint8_t { done, stopped, finished };
  End serve(const std::function<std::string(const std::string&)>& compute) const;
  int rank_, size_;
};

}  // namespace poundsim::apps
