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

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "poundsim/analysis/channels.hpp"
#include "poundsim/error.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/time_history_run.hpp"

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

TimeHistoryRun run_time_history(const io::RunInput& input, const std::optional<std::vector<std::string>>& patterns,
                                const py::object& progress, double progress_interval) {
  if (input.analysis.kind != io::AnalysisKind::time_history) {
    throw py::value_error(fmt::format("{}: analysis.kind: \"{}\" is not a time history", input.source.string(),
                                      to_string(input.analysis.kind)));
  }
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

  // Bad input is a ValueError with the command line's message (file, key, rule); a failed
  // integration a RuntimeError.
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
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
