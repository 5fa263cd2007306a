// The C++ side of the Python-overhead benchmark (bench/python_overhead.py): the run that
// poundsim.run makes of bench/models/two_ten_storey_frames.toml (two 10-storey frames, 20 s of El
// Centro), through the library as a C++ program calls it — io::analyse_run sampling the default
// channels into one buffer reserved for the run, as the module does. The script times
// poundsim.run on the same file in the same session and reports the difference.

#include <cstddef>
#include <span>
#include <vector>

#include <benchmark/benchmark.h>

#include "poundsim/analysis/channels.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/time_history_run.hpp"

namespace {

using namespace poundsim;

void BM_TimeHistory2x10ThroughTheLibrary(benchmark::State& state) {
  const io::RunInput input = io::read_input(POUNDSIM_SOURCE_DIR "/bench/models/two_ten_storey_frames.toml");
  for (auto _ : state) {
    const HistoryChannels channels(input.model, input.channels);
    const auto columns = channels.size() + 1;
    std::vector<double> data;
    data.reserve((static_cast<std::size_t>(output_instants(input.analysis.duration, input.analysis.output_dt)) + 1) *
                 columns);
    TimeHistoryObserver observer;
    observer.on_output = [&](const Simulator& sim) {
      const std::size_t at = data.size();
      data.resize(at + columns);
      data[at] = sim.state().t;
      channels.sample(sim, std::span(data).subspan(at + 1, columns - 1));
    };
    const io::TimeHistoryResult result = io::analyse_run(input, observer);
    benchmark::DoNotOptimize(data.data());
    benchmark::DoNotOptimize(result.run_time);
  }
}
BENCHMARK(BM_TimeHistory2x10ThroughTheLibrary)->Unit(benchmark::kMillisecond);

}  // namespace
