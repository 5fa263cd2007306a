// poundsim._core, the extension under the Python package poundsim (python/poundsim/, docs/python.md):
// the typed library's inputs, runs and results, with NumPy arrays for histories.
//
// A run releases the GIL. At every output instant it samples the chosen channels into one buffer
// reserved for the whole run (rows × (1 + channels), time first), which becomes the NumPy array
// without a copy; at most every `progress_interval` seconds it takes the GIL back to check for
// Ctrl-C (PyErr_CheckSignals) and to call the progress callback. Either stops the run by an
// exception that unwinds it (nothing is left half-done: the C++ run owns no files here), and the
// pending Python error (KeyboardInterrupt, or the callback's) is raised once the GIL is back.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "poundsim/analysis/channels.hpp"
#include "poundsim/analysis/figures_of_merit.hpp"
#include "poundsim/analysis/progress.hpp"
#include "poundsim/error.hpp"
#include "poundsim/io/continuation_run.hpp"
#include "poundsim/io/frequency_response_run.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/output_files.hpp"
#include "poundsim/io/schema.hpp"
#include "poundsim/io/study_run.hpp"
#include "poundsim/io/table.hpp"
#include "poundsim/io/time_history_run.hpp"
#include "poundsim/optimize/optimize_run.hpp"

namespace py = pybind11;

namespace poundsim::python {
namespace {

/// Python asked the run to stop; its error is pending and is raised once the run has unwound.
struct PythonStop {};

/// A JSON value as the Python objects json.loads would give, built directly.
py::object to_python(const nlohmann::json& j) {
  using T = nlohmann::json::value_t;
  switch (j.type()) {
    case T::boolean: return py::bool_(j.get<bool>());
    case T::number_integer: return py::int_(j.get<std::int64_t>());
    case T::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case T::number_float: return py::float_(j.get<double>());
    case T::string: return py::str(j.get_ref<const std::string&>());
    case T::array: {
      py::list list;
      for (const nlohmann::json& item : j) list.append(to_python(item));
      return list;
    }
    case T::object: {
      py::dict dict;
      for (const auto& [key, value] : j.items()) dict[py::str(key)] = to_python(value);
      return dict;
    }
    default: return py::none();  // null (and the binary type, which poundsim never writes)
  }
}

/// `data` (rows × columns, row-major) as a NumPy array that owns it: no copy.
py::array_t<double> owning_array(std::vector<double>&& data, py::ssize_t rows, py::ssize_t columns) {
  auto* owner = new std::vector<double>(std::move(data));
  const py::capsule base(owner, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return py::array_t<double>({rows, columns},
                             {static_cast<py::ssize_t>(sizeof(double)) * columns, static_cast<py::ssize_t>(sizeof(double))},
                             owner->data(), base);
}

/// One row of events.csv, typed.
struct EventRow {
  double t;
  int frame_left, frame_right, floor, right_floor;
  std::string kind;
  double rate_before, rate_after, impulse;
};

/// What a time history returns to Python.
struct TimeHistoryRun {
  io::TimeHistoryResult result;
  py::array_t<double> data;  ///< rows × (1 + channels): t, then each channel
  std::vector<std::string> channels;
  std::vector<std::string> units;
  py::object events;  ///< NumPy structured array, one record per event
};

py::object events_array(const std::vector<EventRow>& rows) {
  const py::module_ np = py::module_::import("numpy");
  py::list fields;
  for (const auto& [name, type] : std::initializer_list<std::pair<const char*, const char*>>{
           {"t", "<f8"}, {"frame_left", "<i4"}, {"frame_right", "<i4"}, {"floor", "<i4"}, {"right_floor", "<i4"},
           {"kind", "<U10"}, {"relative_velocity_before", "<f8"}, {"relative_velocity_after", "<f8"}, {"impulse", "<f8"}}) {
    fields.append(py::make_tuple(name, type));
  }
  py::list records;
  for (const EventRow& e : rows) {
    records.append(py::make_tuple(e.t, e.frame_left, e.frame_right, e.floor, e.right_floor, e.kind, e.rate_before,
                                  e.rate_after, e.impulse));
  }
  return np.attr("array")(records, py::arg("dtype") = np.attr("dtype")(fields));
}

/// The wall-clock interval between progress calls: finite and ≥ 0.
double checked_interval(double seconds) {
  if (!(std::isfinite(seconds) && seconds >= 0)) {
    throw InputError(fmt::format("progress_interval: {} s must be a finite number ≥ 0", seconds));
  }
  return seconds;
}

/// Refuses an input whose analysis.kind is none of `kinds`, naming what the call runs.
void require_kind(const io::RunInput& input, std::initializer_list<io::AnalysisKind> kinds, std::string_view what) {
  if (std::find(kinds.begin(), kinds.end(), input.analysis.kind) == kinds.end()) {
    throw InputError(fmt::format("{}: analysis.kind: \"{}\" is not {}", input.source.string(),
                                      to_string(input.analysis.kind), what));
  }
}

TimeHistoryRun run_time_history(const io::RunInput& input, const std::optional<std::vector<std::string>>& patterns,
                                const py::object& progress, double progress_interval) {
  checked_interval(progress_interval);
  require_kind(input, {io::AnalysisKind::time_history}, "a time history");
  const HistoryChannels channels = [&] {
    try {
      return HistoryChannels(input.model, patterns ? *patterns : input.channels);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: output.channels: {}", input.source.string(), e.what()));
    }
  }();
  const double duration = input.analysis.duration;
  // Every row is known in advance (t = 0 and each output instant): one allocation for the run.
  const double instants = output_instants(duration, input.analysis.output_dt);
  if (!(instants >= 0 && instants <= input.analysis.max_steps)) {
    throw InputError(fmt::format("{}: analysis.output_dt: {} s over the duration {} s makes {} rows, more than "
                                 "analysis.max_steps = {}", input.source.string(), input.analysis.output_dt, duration,
                                 instants, input.analysis.max_steps));
  }
  const auto columns = static_cast<std::size_t>(channels.size() + 1);
  std::vector<double> data;
  data.reserve((static_cast<std::size_t>(instants) + 1) * columns);
  std::vector<EventRow> events;
  const auto interval = std::chrono::duration<double>(progress_interval);
  auto last = std::chrono::steady_clock::now();

  TimeHistoryObserver observer;
  const std::vector<GapElement>& gaps = input.model.gaps;
  observer.on_event = [&](const Event& e) {
    const GapElement& g = gaps[static_cast<std::size_t>(e.gap)];
    events.push_back({e.time, g.left_frame + 1, g.left_frame + 2, g.floor + 1, g.floor_right() + 1,
                      std::string(to_string(e.kind)), e.rate_before, e.rate_after, e.impulse});
  };
  observer.on_output = [&](const Simulator& sim) {
    const std::size_t at = data.size();
    data.resize(at + columns);  // within the reserved capacity
    data[at] = sim.state().t;
    channels.sample(sim, std::span(data).subspan(at + 1, columns - 1));
    const auto now = std::chrono::steady_clock::now();
    if (now - last < interval) return;
    last = now;
    const py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw PythonStop{};
    if (progress.is_none()) return;
    try {
      progress(sim.state().t, duration);
    } catch (py::error_already_set& e) {
      e.restore();
      throw PythonStop{};
    }
  };
  std::optional<io::TimeHistoryResult> result;
  bool stopped = false;
  {
    const py::gil_scoped_release release;
    try {
      result.emplace(io::analyse_run(input, observer));
    } catch (const PythonStop&) {
      stopped = true;
    }
  }
  if (stopped) throw py::error_already_set();
  if (!progress.is_none()) progress(duration, duration);

  TimeHistoryRun run{.result = std::move(*result), .data = {}, .channels = {}, .units = {}, .events = events_array(events)};
  for (const Channel& c : channels.channels()) {
    run.channels.push_back(c.name);
    run.units.emplace_back(c.unit);
  }
  const auto rows = static_cast<py::ssize_t>(data.size() / columns);
  run.data = owning_array(std::move(data), rows, static_cast<py::ssize_t>(columns));
  return run;
}

/// A Python value of a model document as JSON: dicts (str keys), lists and tuples, NumPy arrays
/// and scalars, bool, int, float, str and paths; `path` names it in messages.
/// Where a value of the document is, as a message names it: "frames[1].mass[3]". Built only for
/// a message — formatting it for every value of a long array took most of the conversion's time.
struct DocumentPath {
  const DocumentPath* parent = nullptr;
  std::string_view key;  ///< A table's key, or empty for an array's item
  std::size_t index = 0; ///< 1-based item of an array
  [[nodiscard]] std::string str() const {
    if (parent == nullptr) return key.empty() ? std::string("the model") : std::string(key);
    const std::string up = parent->parent == nullptr && parent->key.empty() ? std::string() : parent->str();
    if (!key.empty()) return up.empty() ? std::string(key) : up + "." + std::string(key);
    return fmt::format("{}[{}]", up.empty() ? std::string("the model") : up, index);
  }
};

/// A Python str as UTF-8 text, refused with its place named when it holds a lone surrogate (no
/// UTF-8 form) or a NUL (a model file's text cannot hold one, and a message would be cut at it).
std::string document_text(const py::handle& value, const DocumentPath& path) {
  PyObject* bytes = PyUnicode_AsEncodedString(value.ptr(), "utf-8", "strict");
  if (bytes == nullptr) {
    PyErr_Clear();
    throw InputError(fmt::format("{}: the text {} is not valid Unicode (a lone surrogate has no UTF-8 form)",
                                 path.str(), py::repr(value).cast<std::string>()));
  }
  std::string text(PyBytes_AsString(bytes), static_cast<std::size_t>(PyBytes_Size(bytes)));
  Py_DECREF(bytes);
  if (text.find('\0') != std::string::npos) {
    throw InputError(fmt::format("{}: the text {} holds a NUL character, which a model file's text cannot",
                                 path.str(), py::repr(value).cast<std::string>()));
  }
  return text;
}

nlohmann::json to_document(const py::handle& value, const DocumentPath& path, int depth = 0) {
  // A model file nests a few tables deep; deeper is a container that holds itself.
  if (depth > 32) throw InputError(fmt::format("{}: nested more than 32 deep (a container that holds itself?)", path.str()));
  if (py::isinstance<py::dict>(value)) {
    nlohmann::json object = nlohmann::json::object();
    for (const auto& [key, item] : py::reinterpret_borrow<py::dict>(value)) {
      if (!py::isinstance<py::str>(key)) {
        throw InputError(fmt::format("{}: the key {} is not a str", path.str(), py::repr(key).cast<std::string>()));
      }
      const std::string name = document_text(key, path);
      object[name] = to_document(item, DocumentPath{&path, name}, depth + 1);
    }
    return object;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    nlohmann::json items = nlohmann::json::array();
    items.get_ref<nlohmann::json::array_t&>().reserve(py::len(value));
    std::size_t k = 0;
    for (const py::handle item : value) items.push_back(to_document(item, DocumentPath{&path, {}, ++k}, depth + 1));
    return items;
  }
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
  if (py::isinstance<py::int_>(value)) {
    try {
      return value.cast<std::int64_t>();
    } catch (const py::cast_error&) {
      throw InputError(fmt::format("{}: the integer {} does not fit in 64 bits", path.str(),
                                   py::repr(value).cast<std::string>()));
    }
  }
  if (py::isinstance<py::float_>(value)) return value.cast<double>();
  if (py::isinstance<py::str>(value)) return document_text(value, path);
  // NumPy arrays and numbers that are not Python's (np.float64 is a float, above): as Python's.
  const py::module_ np = py::module_::import("numpy");
  if (py::isinstance(value, np.attr("ndarray")) && value.attr("ndim").cast<int>() == 1 &&
      value.attr("dtype").attr("kind").cast<std::string>() == "f" && value.attr("dtype").attr("itemsize").cast<int>() <= 8) {
    // A 1-D array of floats (a record's samples, a frame's storeys) straight from its buffer.
    const auto numbers = py::array_t<double, py::array::forcecast>::ensure(value);
    nlohmann::json items = nlohmann::json::array();
    auto& array = items.get_ref<nlohmann::json::array_t&>();
    array.reserve(static_cast<std::size_t>(numbers.size()));
    for (py::ssize_t i = 0; i < numbers.size(); ++i) array.emplace_back(numbers.at(i));
    return items;
  }
  if (py::isinstance(value, np.attr("ndarray")) || py::isinstance(value, np.attr("generic"))) {
    const py::object plain = value.attr("tolist")();
    // A NumPy number with no Python equivalent (long double, complex) stays itself: refused below.
    if (!py::isinstance(plain, np.attr("generic"))) return to_document(plain, path, depth + 1);
  }
  if (py::hasattr(value, "__fspath__")) {
    const py::object text = py::module_::import("os").attr("fsdecode")(value);  // bytes paths decoded
    return document_text(text, path);
  }
  throw InputError(fmt::format("{}: {} ({}) is not a value of a model file (dict, list, number, bool or str)",
                               path.str(), py::repr(value).cast<std::string>(),
                               py::str(value.get_type().attr("__name__")).cast<std::string>()));
}

/// A 1-D NumPy array that owns `values`: no copy.
template <typename T>
py::array_t<T> owning_vector(std::vector<T>&& values) {
  auto* owner = new std::vector<T>(std::move(values));
  const py::capsule base(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(static_cast<py::ssize_t>(owner->size()), owner->data(), base);
}

/// A table's columns (name → NumPy array: float64, int64 or str) and units (name → unit), in order,
/// into `columns` and `units`.
void table_to_python(io::Table&& table, py::dict& columns, py::dict& units) {
  const py::module_ np = py::module_::import("numpy");
  for (io::TableColumn& c : table.columns()) {
    py::object array = std::visit(
        [&](auto& values) -> py::object {
          using V = std::decay_t<decltype(values)>;
          if constexpr (std::is_same_v<V, io::TableColumn::Texts>) {
            return np.attr("array")(py::cast(values), py::arg("dtype") = "str");
          } else {
            return owning_vector(std::move(values));
          }
        },
        c.values);
    columns[py::str(c.name)] = array;
    units[py::str(c.name)] = py::str(c.unit);
  }
}

/// Runs `work(progress)` on a thread of its own while this (Python's main) thread waits with the
/// GIL released, waking at most every `interval` seconds to check for Ctrl-C and to call
/// `progress(done, total)` with the latest counts. Ctrl-C (or an exception of the callback) asks
/// the run to stop: the progress the work reports then throws RunStopped, so the run unwinds as
/// from any error (its output transaction commits nothing; a study's database is closed whole),
/// and the Python error is raised here. Signals reach Python's main thread only, hence the thread.
template <typename Work>
auto run_stoppable(const Work& work, const py::object& progress, double interval) {
  using Result = decltype(work(std::function<void(int, int)>{}, std::function<bool()>{}));
  checked_interval(interval);
  std::atomic<bool> stop{false};
  // (done, total) in one word, so that the two are read together; done never goes back (threads
  // report out of order).
  std::atomic<std::uint64_t> counts{0};
  const auto pack = [](std::uint32_t d, std::uint32_t t) { return (std::uint64_t{d} << 32) | t; };
  const std::function<bool()> stop_requested = [&] { return stop.load(); };
  const std::function<void(int, int)> report = [&](int d, int t) {
    const auto done = static_cast<std::uint32_t>(std::max(d, 0)), total = static_cast<std::uint32_t>(std::max(t, 0));
    std::uint64_t seen = counts.load();
    while ((seen >> 32) <= done && !counts.compare_exchange_weak(seen, pack(done, total))) {
    }
    if (stop) throw RunStopped();
  };
  const auto call_progress = [&] {
    const std::uint64_t now = counts.load();
    progress(static_cast<int>(now >> 32), static_cast<int>(now & 0xffffffffu));
  };
  std::optional<Result> result;
  std::exception_ptr error;
  std::mutex mutex;
  std::condition_variable finished_cv;
  bool finished = false;
  bool python_error = false;
  {
    const py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        result.emplace(work(report, stop_requested));
      } catch (...) {
        error = std::current_exception();
      }
      const std::lock_guard lock(mutex);
      finished = true;
      finished_cv.notify_all();
    });
    // Signals and the callback are looked at every `interval`, and at least every 10 ms.
    const auto wait = std::chrono::duration<double>(std::max(interval, 0.01));
    try {
      std::unique_lock lock(mutex);
      while (!finished_cv.wait_for(lock, wait, [&] { return finished; })) {
        lock.unlock();
        if (!python_error) {
          const py::gil_scoped_acquire gil;
          if (PyErr_CheckSignals() != 0) {
            python_error = true;
          } else if (!progress.is_none()) {
            try {
              call_progress();
            } catch (py::error_already_set& e) {
              e.restore();
              python_error = true;
            }
          }
          if (python_error) stop = true;
        }
        lock.lock();
      }
    } catch (...) {  // never leave the worker running (a joinable thread's destructor aborts)
      stop = true;
      worker.join();
      throw;
    }
    worker.join();
  }
  if (python_error) throw py::error_already_set();
  if (error) std::rethrow_exception(error);
  if (!progress.is_none()) {  // done: as far as it went (an optimiser may stop short of its budget)
    const auto done = static_cast<int>(counts.load() >> 32);
    progress(done, done);
  }
  return std::move(*result);
}

/// What a frequency response returns to Python.
struct FrequencyResponseRun {
  py::dict table, units, summary;
};

FrequencyResponseRun run_frequency_response(const io::RunInput& input, const py::object& progress, double interval) {
  require_kind(input, {io::AnalysisKind::frf}, "a frequency response");
  io::FrequencyResponseResult result = run_stoppable(
      [&](const std::function<void(int, int)>& report, const std::function<bool()>&) {
        return io::analyse_frequency_response(input, report);
      },
      progress, interval);
  FrequencyResponseRun run;
  run.summary = to_python(io::to_json(result));
  table_to_python(io::frf_table(input.model, result.points), run.table, run.units);
  return run;
}

/// What a continuation in a model parameter returns to Python.
struct ContinuationRun {
  py::dict table, units, summary;
};

ContinuationRun run_continuation(const io::RunInput& input) {
  require_kind(input, {io::AnalysisKind::continuation}, "a continuation");
  const io::ContinuationRunResult result = [&] {
    const py::gil_scoped_release release;  // other Python threads run meanwhile (Ctrl-C waits for the end)
    return io::analyse_continuation(input);
  }();
  ContinuationRun run;
  run.summary = to_python(io::to_json(result));
  table_to_python(io::continuation_table(result), run.table, run.units);
  return run;
}

/// What a study or an ensemble returns to Python.
struct StudyRun {
  py::dict table, units, summary;
  std::string database;
  py::object spectra = py::none();  ///< (columns, units) of spectra.csv, or None
};

StudyRun run_study(const io::RunInput& input, const std::filesystem::path& out_dir, long max_points,
                   const py::object& progress, double interval) {
  require_kind(input, {io::AnalysisKind::study, io::AnalysisKind::ensemble}, "a study or an ensemble");
  const io::AnalysisKind kind = input.analysis.kind;
  if (max_points < 0) {
    throw InputError(fmt::format("max_points: {}: expected a whole number of points from 1 (0: all)", max_points));
  }
  io::StudyResult result = run_stoppable(
      [&](const std::function<void(int, int)>& report, const std::function<bool()>& stop_requested) {
        io::StudyRunOptions options;
        if (max_points > 0) options.max_points = max_points;
        options.progress = report;
        options.stop_requested = stop_requested;
        return kind == io::AnalysisKind::ensemble ? io::run_ensemble(input, out_dir, options)
                                                  : io::run_study(input, out_dir, options);
      },
      progress, interval);
  StudyRun run;
  run.summary = to_python(io::to_json(result));
  table_to_python(io::study_table(result.parameters, result.rows), run.table, run.units);
  run.database = result.database.string();
  if (result.spectra) {
    py::dict columns, spectrum_units;
    table_to_python(std::move(*result.spectra), columns, spectrum_units);
    run.spectra = py::make_tuple(columns, spectrum_units);
  }
  return run;
}

/// What an optimisation returns to Python.
struct OptimizationRun {
  py::dict summary, evaluations, evaluation_units;
  py::object optimum_frf, bare_frf;  ///< (columns, units), or None
  py::object pareto;                 ///< (columns, units) of pareto.csv, or None
};

OptimizationRun run_optimization(const io::RunInput& input, const std::filesystem::path& out_dir,
                                 const py::object& progress, double interval) {
  require_kind(input, {io::AnalysisKind::optimize}, "an optimisation");
  optimize::OptimizationResult result = run_stoppable(
      [&](const std::function<void(int, int)>& report, const std::function<bool()>&) {
        return optimize::run_optimization(input, out_dir, report);
      },
      progress, interval);
  OptimizationRun run;
  run.summary = to_python(optimize::to_json(result));
  table_to_python(std::move(result.evaluation_table), run.evaluations, run.evaluation_units);
  const auto pair = [](std::optional<io::Table>& table) -> py::object {  // (columns, units), or None
    if (!table) return py::none();
    py::dict columns, units;
    table_to_python(std::move(*table), columns, units);
    return py::make_tuple(columns, units);
  };
  run.optimum_frf = pair(result.optimum_frf);
  run.bare_frf = pair(result.bare_frf);
  run.pareto = pair(result.pareto_table);
  return run;
}

std::vector<io::Setting> settings_of(const std::vector<std::string>& texts, const std::string& file) {
  std::vector<io::Setting> settings;
  for (const std::string& text : texts) settings.push_back(io::parse_setting(text, file));
  return settings;
}

}  // namespace
}  // namespace poundsim::python

PYBIND11_MODULE(_core, m) {
  using namespace poundsim;
  using namespace poundsim::python;
  m.doc() = "poundsim's C++ core: inputs, runs and results (use the package poundsim, docs/python.md).";
  m.attr("__version__") = POUNDSIM_VERSION;
  m.attr("max_storeys") = io::limits::storeys;  // checked in Python before a huge array is copied

  // Bad input — a key, a value or an argument — is poundsim.InputError with the command line's
  // message (file, key, rule): a ValueError and, for a value of the wrong type, a TypeError too,
  // so that either `except` Python code writes catches it. A failed integration is a RuntimeError.
  {
    PyObject* bases = PyTuple_Pack(2, PyExc_ValueError, PyExc_TypeError);
    static PyObject* const input_error = PyErr_NewException("poundsim._core.InputError", bases, nullptr);
    Py_DECREF(bases);
    m.attr("InputError") = py::handle(input_error);  // a new reference the module keeps, never released
    py::register_exception_translator([](std::exception_ptr p) {
      try {
        if (p) std::rethrow_exception(p);
      } catch (const InputError& e) {
        PyErr_SetString(input_error, e.what());
      }
    });
  }
  py::register_exception<SimulationError>(m, "SimulationError", PyExc_RuntimeError);

  py::class_<io::RunInput>(m, "Input", "A model file read and checked: the model, its excitation and its analysis.")
      .def_property_readonly("title", [](const io::RunInput& in) { return in.title; })
      .def_property_readonly("source", [](const io::RunInput& in) { return in.source; })
      .def_property_readonly("kind", [](const io::RunInput& in) { return std::string(to_string(in.analysis.kind)); },
                             "analysis.kind: \"time_history\", \"frf\", \"study\", \"ensemble\" or \"optimize\"")
      .def_property_readonly("duration", [](const io::RunInput& in) { return in.analysis.duration; }, "[s]")
      .def_property_readonly("dt", [](const io::RunInput& in) { return in.analysis.options.dt; }, "[s]")
      .def_property_readonly("output_dt", [](const io::RunInput& in) { return in.analysis.output_dt; }, "[s]")
      .def_property_readonly("channels", [](const io::RunInput& in) { return in.channels; },
                             "[output] channels (empty: the default ones)")
      .def_property_readonly("frame_count", [](const io::RunInput& in) { return in.model.frame_count(); })
      .def_property_readonly("gap_count", [](const io::RunInput& in) { return in.model.gap_count(); })
      .def(
          "available_channels",
          [](const io::RunInput& in) {
            std::vector<std::pair<std::string, std::string>> out;
            for (const Channel& c : HistoryChannels::available(in.model)) out.emplace_back(c.name, std::string(c.unit));
            return out;
          },
          "Every channel the model offers, as (name, unit), in the model's order.")
      .def("to_toml", &io::to_toml, "The input as TOML, as the command line's input.toml writes it.")
      .def("to_dict", [](const io::RunInput& in) { return to_python(io::input_document(in)); },
           "The model file as written (its settings applied, paths absolute) as dicts and lists: "
           "poundsim.from_dict of it reads the same input.")
      .def(
          "save",
          [](const io::RunInput& in, const std::filesystem::path& file) {
            io::OutputTransaction out(io::folder_of(file));  // whole or not at all
            out.open(file.filename().string()).text(io::to_toml_as_written(in));
            out.commit();
          },
          py::arg("file"), "Writes the model file as written (TOML) that `poundsim run FILE` runs.")
      .def(
          "with_settings",
          [](const io::RunInput& in, const std::vector<std::string>& settings) {
            return io::with_settings(in, settings_of(settings, in.source.string()));
          },
          py::arg("settings"),
          "The same file read again with these `key=value` settings after its own (as --set takes them).");

  m.def(
      "load",
      [](const std::filesystem::path& file, const std::vector<std::string>& settings) {
        return io::read_input(file, settings);
      },
      py::arg("file"), py::arg("settings") = std::vector<std::string>{},
      "Reads and checks a model file, with `key=value` settings applied as --set applies them.");
  m.def(
      "loads",
      [](const std::string& text, const std::string& name, const std::filesystem::path& base_dir,
         const std::vector<std::string>& settings) { return io::read_input_string(text, name, base_dir, settings); },
      py::arg("text"), py::arg("name") = "model.toml", py::arg("base_dir") = ".",
      py::arg("settings") = std::vector<std::string>{},
      "Reads and checks a model given as TOML text; `name` names it in messages, relative record paths start "
      "from `base_dir`.");

  m.def(
      "from_dict",
      [](const py::dict& document, const std::string& name, const std::filesystem::path& base_dir,
         const std::vector<std::string>& settings) {
        return io::read_input_document(to_document(document, DocumentPath{}), name, base_dir, settings);
      },
      py::arg("document"), py::arg("name") = "model", py::arg("base_dir") = ".",
      py::arg("settings") = std::vector<std::string>{},
      "Reads and checks a model given as the model file's tables (dicts, lists, numbers, str; NumPy arrays): "
      "the keys, rules and messages of a file, `name` in place of the file's.");

  py::class_<FrequencyResponseRun>(m, "FrequencyResponseRun", "What a frequency response found: frf.csv's table.")
      .def_readonly("table", &FrequencyResponseRun::table, "column → NumPy array (frf.csv's columns)")
      .def_readonly("units", &FrequencyResponseRun::units, "column → unit")
      .def_readonly("summary", &FrequencyResponseRun::summary, "summary.json's content");
  m.def("run_frequency_response", &run_frequency_response, py::arg("input"), py::arg("progress") = py::none(),
        py::arg("progress_interval") = 0.1,
        "Runs a frequency-response input; `progress(points done, points)` at most every `progress_interval` s.");

  py::class_<ContinuationRun>(m, "ContinuationRun", "What a continuation in a parameter found: orbits.csv's table.")
      .def_readonly("table", &ContinuationRun::table, "column → NumPy array (orbits.csv's columns)")
      .def_readonly("units", &ContinuationRun::units, "column → unit")
      .def_readonly("summary", &ContinuationRun::summary, "summary.json's content");
  m.def("run_continuation", &run_continuation, py::arg("input"),
        "Runs a continuation input (analysis.kind = \"continuation\"): every continued orbit.");

  py::class_<StudyRun>(m, "StudyRun", "What a study or an ensemble found: study.csv's (ensemble.csv's) table.")
      .def_readonly("table", &StudyRun::table, "column → NumPy array")
      .def_readonly("units", &StudyRun::units, "column → unit")
      .def_readonly("summary", &StudyRun::summary, "summary.json's content")
      .def_readonly("database", &StudyRun::database, "the SQLite database the points are kept in")
      .def_readonly("spectra", &StudyRun::spectra, "(columns, units) of spectra.csv (an ensemble with scaling), or None");
  py::class_<TimeLeft>(m, "TimeLeft",
                       "The time left of a run of many items, from the rate since the first update (analysis/progress.hpp).")
      .def(py::init<>())
      .def("update", &TimeLeft::update, py::arg("done"), py::arg("total"), py::arg("elapsed"),
           "Seconds left with `done` of `total` items at `elapsed` s since the first update; None before a rate.");
  m.def(
      "declared_unit",
      [](const std::string& column) -> std::optional<std::string> {
        const std::optional<std::string_view> unit = declared_unit(column);
        return unit ? std::optional<std::string>(*unit) : std::nullopt;
      },
      py::arg("column"),
      "The declared unit of a study column of a point's figures (analysis/figures_of_merit.hpp: \"1\" a ratio, "
      "\"\" a count), or None for a column no figure declares.");
  m.def("input_schema", &poundsim::io::input_schema,
        "The JSON Schema (draft 7) of a model file, as `poundsim schema` writes it (io/schema.hpp).");
  m.def("readable_duration", &readable_duration, py::arg("seconds"), "\"45 s\", \"3 min 20 s\", \"2 h 05 min\".");
  m.def("run_study", &run_study, py::arg("input"), py::arg("out"), py::arg("max_points") = 0,
        py::arg("progress") = py::none(), py::arg("progress_interval") = 0.1,
        "Runs a study or an ensemble into the folder `out` (its database, table, summary), as the command line "
        "does; at most `max_points` new points when > 0.");

  py::class_<OptimizationRun>(m, "OptimizationRun", "What an optimisation found.")
      .def_readonly("summary", &OptimizationRun::summary, "optimize.json's content")
      .def_readonly("evaluations", &OptimizationRun::evaluations, "evaluations.csv's columns")
      .def_readonly("evaluation_units", &OptimizationRun::evaluation_units)
      .def_readonly("optimum_frf", &OptimizationRun::optimum_frf, "(columns, units) of optimum_frf.csv, or None")
      .def_readonly("bare_frf", &OptimizationRun::bare_frf, "(columns, units) of bare_frf.csv, or None")
      .def_readonly("pareto", &OptimizationRun::pareto, "(columns, units) of pareto.csv, or None");
  m.def("run_optimization", &run_optimization, py::arg("input"), py::arg("out"), py::arg("progress") = py::none(),
        py::arg("progress_interval") = 0.1, "Runs an optimisation into the folder `out`, as the command line does.");

  py::class_<TimeHistoryRun>(m, "TimeHistoryRun", "What a time history found: its history, events and summary.")
      .def_readonly("data", &TimeHistoryRun::data, "rows × (1 + channels): t [s], then each channel")
      .def_readonly("channels", &TimeHistoryRun::channels)
      .def_readonly("units", &TimeHistoryRun::units)
      .def_readonly("events", &TimeHistoryRun::events)
      .def("summary", [](const TimeHistoryRun& r) { return to_python(io::to_json(r.result)); },
           "summary.json's content, as dicts and lists");
  m.def("run_time_history", &run_time_history, py::arg("input"), py::arg("channels") = py::none(),
        py::arg("progress") = py::none(), py::arg("progress_interval") = 0.1,
        "Runs a time-history input; `channels` (patterns) overrides its [output] channels; `progress(t, duration)` is "
        "called at most every `progress_interval` seconds of wall time.");
}
