// Reading the inputs of many points: what a study or an ensemble reads before its points run.
// Each point is the model file read again with its settings (io::point_inputs); a point's record
// is read from its file, scaled by the point's own factor.

#include <benchmark/benchmark.h>

#include "poundsim/io/input.hpp"
#include "poundsim/io/study_run.hpp"

namespace {

using namespace poundsim;

/// The 40 points of a study of excitation.scale under one record (El Centro, 2 688 samples).
void BM_StudyPointsOfOneRecord(benchmark::State& state) {
  const io::RunInput input = io::read_input(POUNDSIM_SOURCE_DIR "/bench/models/record_scale_study.toml");
  for (auto _ : state) {
    const std::vector<io::RunInput> points = io::point_inputs(input, io::AnalysisKind::study);
    benchmark::DoNotOptimize(points.data());
  }
  state.counters["points"] = 40;
}
BENCHMARK(BM_StudyPointsOfOneRecord)->Unit(benchmark::kMillisecond);

/// The four records of an ensemble, each scaled to a PGA of 0.2 g.
void BM_EnsembleRecordInputs(benchmark::State& state) {
  const io::RunInput input = io::read_input(POUNDSIM_SOURCE_DIR "/examples/ensemble_fig2_frames.toml");
  for (auto _ : state) {
    const std::vector<io::RunInput> points = io::point_inputs(input, io::AnalysisKind::ensemble);
    benchmark::DoNotOptimize(points.data());
  }
}
BENCHMARK(BM_EnsembleRecordInputs)->Unit(benchmark::kMillisecond);

}  // namespace
