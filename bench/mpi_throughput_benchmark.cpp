// A study's throughput on one process, two threads and two MPI ranks (two ranks should give
// ≥ 1.8× one rank on ≥ 200 points), side by side in one run: bench/models/study_200_points.toml through
// the command line, wall clock, MPI's start-up included. And what rank 0 spends per point beside
// computing: storing a result (one SQLite transaction) and decoding it, the terms of the
// efficiency model in docs/studies.md#distributed-studies-on-mpi.
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "poundsim/io/study_database.hpp"

namespace {

namespace fs = std::filesystem;

// 0: one process, one thread; 1: one process, two threads; 2: two ranks of one thread each.
void BM_Study200Points(benchmark::State& state) {
  const fs::path out = fs::temp_directory_path() / fmt::format("poundsim_bench_ranks_{}", state.range(0));
  const std::string model = std::string(POUNDSIM_SOURCE_DIR) + "/bench/models/study_200_points.toml";
  const std::string root = ::geteuid() == 0 ? " --allow-run-as-root" : "";
  const std::string launch =
      state.range(0) == 2 ? "mpirun --oversubscribe" + root + " -n 2 " : std::string();
  const std::string threads = state.range(0) == 1 ? " --set study.threads=2" : " --set study.threads=1";
  const std::string command =
      fmt::format("{}{} run {} --out {} --quiet{}", launch, POUNDSIM_CLI, model, out.string(), threads);
  for (auto _ : state) {
    fs::remove_all(out);
    if (std::system(command.c_str()) != 0) {
      state.SkipWithError(("failed: " + command).c_str());
      return;
    }
  }
  fs::remove_all(out);
  state.counters["points_per_s"] = benchmark::Counter(200.0 * static_cast<double>(state.iterations()),
                                                      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Study200Points)->Arg(0)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// The frequency-response optimisation of examples/optimize_gap_elements.toml (DIRECT then
// BOBYQA, 64 evaluations of 27 frequencies each): 0: one process, one thread; 1: one process, two
// threads (each evaluation's frequencies shared); 2: two ranks, each computing a design of the
// batch NLopt is foreseen to ask for.
void BM_OptimizeOnRanks(benchmark::State& state) {
  const fs::path out = fs::temp_directory_path() / fmt::format("poundsim_bench_optimize_ranks_{}", state.range(0));
  const std::string model = std::string(POUNDSIM_SOURCE_DIR) + "/examples/optimize_gap_elements.toml";
  const std::string root = ::geteuid() == 0 ? " --allow-run-as-root" : "";
  const std::string launch = state.range(0) == 2 ? "mpirun --oversubscribe" + root + " -n 2 " : std::string();
  const std::string threads = state.range(0) == 1 ? " --set optimize.threads=2" : " --set optimize.threads=1";
  const std::string command = fmt::format("{}{} run {} --out {} --quiet{}", launch, POUNDSIM_CLI, model, out.string(), threads);
  for (auto _ : state) {
    fs::remove_all(out);  // no database to resume from: every design computed
    if (std::system(command.c_str()) != 0) {
      state.SkipWithError(("failed: " + command).c_str());
      return;
    }
  }
  fs::remove_all(out);
}
BENCHMARK(BM_OptimizeOnRanks)->Arg(0)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// Rank 0's own cost per point: decoding a result (CBOR) and recording it, as run_points does.
void BM_StoreOnePoint(benchmark::State& state) {
  const fs::path file = fs::temp_directory_path() / "poundsim_bench_store.sqlite";
  fs::remove(file);
  poundsim::io::StudyDatabase db(file, "bench", nlohmann::json{{"points", 1}});
  nlohmann::json metrics = nlohmann::json::object();
  for (int k = 0; k < 30; ++k) metrics[fmt::format("figure_{}", k)] = 0.1234567890123 * k;
  const std::vector<std::uint8_t> bytes =
      nlohmann::json::to_cbor({{"status", "done"}, {"error", ""}, {"metrics", metrics}, {"seconds", 0.05}});
  long id = 0;
  for (auto _ : state) {
    const nlohmann::json r = nlohmann::json::from_cbor(bytes);
    db.record(id++, nlohmann::json{{"eta", 0.5}, {"mu", 1.0}}, r.at("status").get<std::string>(),
              r.at("error").get<std::string>(), r.at("metrics"), r.at("seconds").get<double>());
  }
  fs::remove(file);
}
BENCHMARK(BM_StoreOnePoint)->Unit(benchmark::kMicrosecond);

}  // namespace
