// poundsim command line: parses arguments, calls the library, reports. Exit codes: 0 success,
// 1 failure during the run (numerical or file system), 2 bad input or usage (an output folder
// another run is writing into among them); stopped by SIGINT,
// SIGTERM or SIGHUP, it ends by that signal (a shell reports 130, 143, 129).

#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <optional>
#include <exception>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "poundsim/analysis/progress.hpp"
#include "poundsim/error.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/schema.hpp"
#include "poundsim/io/continuation_run.hpp"
#include "poundsim/io/frequency_response_run.hpp"
#include "poundsim/optimize/optimize_run.hpp"
#include "poundsim/io/output_files.hpp"
#include "poundsim/io/study_database.hpp"
#include "poundsim/io/study_run.hpp"
#include "poundsim/io/time_history_run.hpp"
#include "poundsim/analysis/verification.hpp"
#include "mpi_distribution.hpp"

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

/// --max-points N: a whole number ≥ 1.
long parse_max_points(const std::string& text) {
  long n = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, n);
  if (error != std::errc{} || stop != end || n < 1) {
    throw poundsim::InputError(fmt::format("--max-points {}: expected a whole number of points from 1 to {}",
                                           text, std::numeric_limits<long>::max()));
  }
  return n;
}

/// A one-line progress bar on a terminal; silent otherwise. Updates come from worker threads.
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled) {}
  void update(int done, int total) {
    if (!enabled_) return;
    const std::lock_guard lock(mutex_);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const std::optional<double> left = time_left_.update(done, total, elapsed);
    const int width = 40, filled = width * done / std::max(total, 1);
    // Padded: a shorter estimate must overwrite a longer one on the same line.
    fmt::print(stderr, "\r  [{}{}] {}/{} points, {} {:<16}", std::string(static_cast<std::size_t>(filled), '#'),
               std::string(static_cast<std::size_t>(width - filled), '.'), done, total,
               poundsim::readable_duration(elapsed), left ? "— " + poundsim::readable_duration(*left) + " left" : "");
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) fmt::print(stderr, "\n");
  }

 private:
  bool enabled_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  poundsim::TimeLeft time_left_;
};

/// Stops cleanly on SIGINT, SIGTERM and SIGHUP. The signals are blocked in every thread (the
/// workers started later inherit the mask) and taken by one thread with sigwait, so the clean-up
/// is ordinary code, not a signal handler: it removes the temporaries of unfinished output files,
/// closes the study databases (whole and resumable, without -wal or -shm) and then ends the process
/// by the same signal with its default action, as if it had not been caught. A signal ignored
/// when the program starts (nohup, a background job of a script) stays ignored: Linux keeps a
/// blocked signal pending even when its action is to ignore it, so it is left out of the set.
void stop_cleanly_on_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  int count = 0;
  // SIGXFSZ (a write beyond `ulimit -f`) is blocked too: the write then fails with EFBIG, and the
  // run ends as on any write error, its temporaries removed, instead of being killed mid-write.
  for (const int s : {SIGINT, SIGTERM, SIGHUP, SIGXFSZ}) {
    struct sigaction current {};
    if (sigaction(s, nullptr, &current) == 0 && current.sa_handler != SIG_IGN) {
      sigaddset(&signals, s);
      ++count;
    }
  }
  if (count == 0) return;
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread([signals] {
    int signal = 0;
    while (sigwait(&signals, &signal) != 0) {
    }
    poundsim::io::abandon_all_outputs();
    poundsim::io::StudyDatabase::close_all_before_exit();
    std::signal(signal, SIG_DFL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, signal);
    pthread_sigmask(SIG_UNBLOCK, &one, nullptr);
    std::raise(signal);
    _exit(128 + signal);  // not reached: the default action of these signals ends the process
  }).detach();
}

/// What `poundsim check` says of a file that is valid: its analysis, model and, for a study or
/// ensemble, how many points were read and validated. Bad input throws as `run` would.
std::string check_input(const std::string& file, const std::vector<std::string>& overrides) {
  using poundsim::io::AnalysisKind;
  const poundsim::io::RunInput input = poundsim::io::read_input(file, overrides);
  const AnalysisKind kind = input.analysis.kind;
  std::string text = fmt::format("{}: valid: analysis.kind = \"{}\", {} frames, {} gap elements", file, to_string(kind),
                                 input.model.frame_count(), input.model.gap_count());
  if (kind == AnalysisKind::study || kind == AnalysisKind::ensemble) {
    const std::size_t points = poundsim::io::point_inputs(input, kind).size();
    text += fmt::format(", {} {} read and valid", points, kind == AnalysisKind::ensemble ? "records" : "points");
  }
  return text + "\n";
}

}  // namespace

int main(int argc, char** argv) {
  stop_cleanly_on_signals();  // first: MPI's threads inherit the blocked signals
  const poundsim::apps::MpiSession mpi(argc, argv);
  const bool worker = mpi.rank() != 0;
  CLI::App app{"poundsim: seismic pounding of adjacent buildings with unilateral visco-elastic gap elements"};
  app.set_version_flag("--version", std::string("poundsim ") + POUNDSIM_VERSION);
  app.require_subcommand(1);

  std::string model_file, out_dir;
  std::vector<std::string> overrides;
  bool quiet = false;
  CLI::App* run = app.add_subcommand("run", "Run the analysis that MODEL.toml describes");
  run->add_option("model", model_file, "Model file (TOML), see docs/input.md")->required();
  run->add_option("--out,-o", out_dir, "Output folder (created if needed)")->required();
  run->add_option("--set", overrides, "Override an input key: --set analysis.dt=0.001 (repeatable)")
      ->take_all();
  run->add_flag("--quiet,-q", quiet, "Print nothing on success");
  std::string max_points_text;  // checked below: CLI11's own check prints a 309-digit range
  run->add_option("--max-points", max_points_text,
                  "Study or ensemble: run at most this many new points, then stop (run again to go on)");

  std::string check_file;
  std::vector<std::string> check_overrides;
  CLI::App* check = app.add_subcommand("check", "Validate MODEL.toml (and its records and study points) without running");
  check->add_option("model", check_file, "Model file (TOML), see docs/input.md")->required();
  check->add_option("--set", check_overrides, "Override an input key, as for run (repeatable)")->take_all();

  std::string schema_file;
  CLI::App* schema = app.add_subcommand("schema", "Write the JSON Schema of model files (for editors: docs/input.md)");
  schema->add_option("--out,-o", schema_file, "File to write (default: standard output)");

  std::string database, export_file;
  CLI::App* exporter = app.add_subcommand("export", "Write the points of a study database as CSV");
  exporter->add_option("database", database, "study.sqlite of a study")->required();
  exporter->add_option("--out,-o", export_file, "CSV file to write")->required();

  std::string verification_file;
  CLI::App* verify = app.add_subcommand(
      "verify", "Compare Newmark with the exact integrator on the paper's systems and print the tables");
  verify->add_option("--write", verification_file,
                     "Also write the report as Markdown (docs/verification.md)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return worker ? 0 : app.exit(e);
  } catch (const CLI::ParseError& e) {
    if (!worker) app.exit(e);
    return kExitBadInput;
  }
  // Under mpirun only rank 0 speaks; an error on any rank ends the whole job with its code.
  if (worker) quiet = true;
  const auto fail = [&](int code, const std::string& message) {
    if (worker) {
      // Bad input stops every rank alike, and rank 0 says so and ends the job; an error of this
      // rank alone (a record it cannot read) is said here, with its rank, once rank 0 has had
      // time to end the job for a shared one.
      std::this_thread::sleep_for(std::chrono::seconds(5));
      fmt::print(stderr, "{} (rank {})\n", message, mpi.rank());
    } else {
      fmt::print(stderr, "{}\n", message);
    }
    if (mpi.size() > 1) mpi.abort(code);
    return code;
  };

  try {
    // Only studies, ensembles and optimisations share their work; anything else runs on rank 0 alone.
    if (worker && !run->parsed()) return 0;
    if (verify->parsed()) {
      const poundsim::VerificationReport report = poundsim::run_verification();
      fmt::print("{}", poundsim::to_text(report));
      if (!verification_file.empty()) {
        const std::filesystem::path path(verification_file);
        poundsim::io::OutputTransaction out(poundsim::io::folder_of(path));
        out.open(path.filename().string()).text(poundsim::to_markdown(report));
        out.commit();
        fmt::print("wrote {}\n", verification_file);
      }
      return 0;
    }
    if (check->parsed()) {
      fmt::print("{}", check_input(check_file, check_overrides));
      return 0;
    }
    if (schema->parsed()) {
      if (schema_file.empty()) {
        fmt::print("{}", poundsim::io::input_schema());
        return 0;
      }
      const std::filesystem::path path(schema_file);
      poundsim::io::OutputTransaction out(poundsim::io::folder_of(path));
      out.open(path.filename().string()).text(poundsim::io::input_schema());
      out.commit();
      return 0;
    }
    if (exporter->parsed()) {
      poundsim::io::export_study(database, export_file);
      if (!quiet) fmt::print("wrote {}\n", export_file);
      return 0;
    }
    const long max_points = run->count("--max-points") > 0 ? parse_max_points(max_points_text) : 0;
    const poundsim::io::RunInput input = poundsim::io::read_input(model_file, overrides);
    using poundsim::io::AnalysisKind;
    const AnalysisKind kind = input.analysis.kind;
    const bool study = kind == AnalysisKind::study || kind == AnalysisKind::ensemble;
    if (max_points > 0 && !study) {
      throw poundsim::InputError(
          fmt::format("--max-points applies to studies and ensembles only, not to analysis.kind = \"{}\"",
                      to_string(kind)));
    }
    poundsim::apps::MpiDistribution ranks(mpi);
    // An optimisation shares its batches of designs (and an ensemble design's records); every
    // analysis but studies, ensembles and optimisations runs on rank 0 alone.
    const bool shared_optimisation = kind == AnalysisKind::optimize && mpi.size() > 1;
    if (worker && shared_optimisation) {
      poundsim::optimize::serve_optimization(input, ranks);
      return 0;
    }
    if (worker && !study) return 0;
    // One run at a time in a folder: a second one is refused before it computes anything.
    // (Rank 0 writes; the workers of a study send it their points.)
    std::optional<poundsim::io::OutputFolderLock> folder_lock;
    if (!worker) folder_lock.emplace(out_dir);
    ProgressBar bar(!quiet && ::isatty(STDERR_FILENO) != 0);
    const auto progress = [&bar](int done, int total) { bar.update(done, total); };
    if (study) {
      poundsim::io::StudyRunOptions options;
      if (max_points > 0) options.max_points = max_points;
      options.progress = progress;
      if (mpi.size() > 1) options.distribution = &ranks;
      const poundsim::io::StudyResult result = kind == AnalysisKind::ensemble
                                                   ? poundsim::io::run_ensemble(input, out_dir, options)
                                                   : poundsim::io::run_study(input, out_dir, options);
      bar.finish();
      if (!quiet && !result.worker) fmt::print("{}", poundsim::io::report(result, out_dir));
      return 0;
    }
    if (kind == AnalysisKind::optimize) {
      const poundsim::optimize::OptimizationResult result = poundsim::optimize::run_optimization(input, out_dir, progress, shared_optimisation ? &ranks : nullptr);
      bar.finish();
      if (!quiet) fmt::print("{}", poundsim::optimize::report(result, out_dir));
      return 0;
    }
    if (kind == AnalysisKind::continuation) {
      const poundsim::io::ContinuationRunResult result = poundsim::io::run_continuation(input, out_dir);
      if (!quiet) fmt::print("{}", poundsim::io::report(result, out_dir));
      return 0;
    }
    if (kind == AnalysisKind::frf) {
      const poundsim::io::FrequencyResponseResult result =
          poundsim::io::run_frequency_response(input, out_dir, progress);
      bar.finish();
      if (!quiet) fmt::print("{}", poundsim::io::report(result, out_dir));
      return 0;
    }
    const poundsim::io::TimeHistoryResult result = poundsim::io::run_time_history(input, out_dir);
    if (!quiet) fmt::print("{}", poundsim::io::report(result, out_dir));
    return 0;
  } catch (const poundsim::RunStopped& e) {
    // Rank 0 stopped the job: a worker ends quietly.
    return worker ? 0 : fail(kExitFailure, fmt::format("poundsim: error: {}", e.what()));
  } catch (const poundsim::InputError& e) {
    return fail(kExitBadInput, fmt::format("poundsim: error: {}", e.what()));
  } catch (const poundsim::io::FolderBusy& e) {
    return fail(kExitBadInput, fmt::format("poundsim: error: {}", e.what()));
  } catch (const poundsim::SimulationError& e) {
    return fail(kExitFailure, fmt::format("poundsim: simulation failed: {}", e.what()));
  } catch (const std::exception& e) {
    return fail(kExitFailure, fmt::format("poundsim: error: {}", e.what()));
  }
}
