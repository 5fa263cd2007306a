#pragma once
/// @file
/// Reading a model file (TOML). The format is documented key by key in docs/input.md.
///
/// Every problem is an InputError whose message starts with the location — `file:line:column:`
/// for a key in the file, `file: --set key=value:` for an override — then names the key and the
/// rule it broke. Unknown keys are errors. Nothing is guessed. Sizes and amounts of work are
/// bounded (namespace limits) before anything is allocated or run.

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "poundsim/fields.hpp"
#include "poundsim/model/dimensionless.hpp"
#include "poundsim/model/excitation.hpp"
#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/analysis/response_spectrum.hpp"
#include "poundsim/model/model.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/ground_motion.hpp"

namespace poundsim::io {

/// Bounds on the size of an input, checked before anything is allocated or run, so that a typo
/// (or a hostile file) cannot ask for unbounded memory or time. docs/input.md lists them.
namespace limits {
inline constexpr std::uintmax_t model_file_bytes = 16u << 20;  ///< A model file: 16 MiB.
inline constexpr int storeys = 1000;          ///< Floors of one frame.
inline constexpr int frames = 100;            ///< Frames in a row.
inline constexpr int floors = 2000;           ///< Floors of all frames together (degrees of freedom).
inline constexpr double max_steps = 1e8;      ///< Default of analysis.max_steps.
inline constexpr double max_steps_limit = 1e15;  ///< analysis.max_steps itself (exact in a double).
inline constexpr int frf_points = 1'000'000;  ///< frf.points.
// frf.steps_per_period, max_periods, window_periods, max_periodicity: SteadyStateOptions's bounds.
inline constexpr int study_points = 1'000'000;  ///< Points of a study (all parameters together).
inline constexpr int evaluations = 1'000'000;   ///< Each stage of the optimiser.
inline constexpr int pareto_points = 1000;      ///< Points of a Pareto front (each an optimisation).
inline constexpr int threads = 1024;          ///< Any `threads` key.
inline constexpr int column = 10'000;         ///< excitation.column.
inline constexpr std::int64_t seed = 4294967295;  ///< Seeds are unsigned 32-bit.
/// An event bracket inside a step of length h cannot close much below the spacing of doubles
/// there: analysis.event_tolerance ≥ event_tolerance_ulps · 2⁻⁵² · h (h the longest step).
inline constexpr double event_tolerance_ulps = 64;
}  // namespace limits

/// A `threads` key: worker threads, 0 for all cores (fields.hpp).
template <class S>
constexpr auto threads_field(int S::*member, std::string_view meaning) {
  return IntegerField{"threads", member, 0, limits::threads, meaning, "0 means all cores"};
}

struct SettingValue;

/// The items of an array value, shared: a setting's value never changes once made.
using SettingArray = std::shared_ptr<const std::vector<SettingValue>>;

/// A value an input key is set to, typed as TOML types it: an integer, a number, a yes/no, a
/// string or an array of them.
struct SettingValue {
  std::variant<std::int64_t, double, bool, std::string, SettingArray> value;
  /// Equal types and values; arrays item by item.
  friend bool operator==(const SettingValue& a, const SettingValue& b);
};

/// One input key set to a value: a `--set` on the command line, a study point's coordinate, an
/// optimiser's design variable, an ensemble's record. It is applied to the file as parsed
/// (RunInput::parsed) as a typed value: no TOML text is written and read again.
struct Setting {
  std::string key;     ///< Dotted path: `gap_elements.stiffness`, `frames[2].mass` (frames from 1).
  SettingValue value;
  /// "key=value": as typed for a --set, as --set would take it otherwise. It names the setting
  /// in messages and identifies it in a study's fingerprint; it is never parsed again.
  std::string text;
  friend bool operator==(const Setting&, const Setting&) = default;
};

/// A setting of `key` to `value` (its text as --set would take it).
[[nodiscard]] Setting make_setting(std::string key, SettingValue value);

/// The TOML text of a value: integers and yes/no as words, numbers as toml_float, strings quoted.
[[nodiscard]] std::string to_text(const SettingValue& value);

/// Reads a `--set key=value` argument: the value is TOML, or a bare word read as a string
/// (`--set analysis.separation=force`). `file` starts the messages; a key or value it cannot
/// be is an InputError.
[[nodiscard]] Setting parse_setting(const std::string& text, const std::string& file);

/// The model file as parsed, before any setting (opaque: TOML stays inside io).
struct ParsedInput;

/// How an axis or a design variable spans its range: `log` is true on a logarithmic scale.
inline constexpr std::array<std::pair<std::string_view, bool>, 2> axis_scale_names{
    {{"linear", false}, {"log", true}}};

/// The text a figure's key rules out: what an empty one is told.
inline constexpr std::string_view name_a_figure = "name a figure (a study column)";

/// The names a string key admits, where its table's reader checks it by rules of its own.
namespace names {
/// The first names of `pairs` (a closed set of named values), then `extra`.
template <class E, std::size_t N, class... Extra>
constexpr auto first_names(const std::array<std::pair<std::string_view, E>, N>& pairs, Extra... extra) {
  std::array<std::string_view, N + sizeof...(Extra)> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = pairs[i].first;
  std::size_t i = N;
  ((out[i++] = std::string_view(extra)), ...);
  return out;
}
inline constexpr std::array<std::string_view, 3> pairing{"floor", "height", "listed"};
inline constexpr std::array<std::string_view, 3> excitation_kind{"harmonic", "record", "none"};
inline constexpr auto record_format = first_names(record_format_names);
inline constexpr const auto& record_units = record_unit_names;
inline constexpr auto axis_scale = first_names(axis_scale_names);
inline constexpr auto design_spectrum = first_names(eurocode8_type_names, tabulated_design_name);
inline constexpr auto ground_type = first_names(ground_type_names);
}  // namespace names

/// A key with its own rules that takes one of `names` (fields.hpp's CustomField with a shape).
template <class S, std::size_t N>
constexpr CustomField<S> named_field(std::string_view key, const std::array<std::string_view, N>& names,
                                     std::string_view meaning) {
  return CustomField<S>{key, meaning, Shape::text, std::span<const std::string_view>(names)};
}

/// The keys of the model file's tables that are read by rules of their own (arrays with one
/// value per floor, either-or keys, sub-tables), declared once (fields.hpp): each table's reader
/// accepts exactly its declared keys (a key it reads without declaring it is a logic_error), and
/// tests/io/input_docs_test.cpp checks that docs/input.md documents exactly these keys.
namespace keys {
/// [output] of a time history.
struct Output {
  static constexpr auto fields() {
    return std::tuple{
        CustomField<Output>{"channels", "the channels history.csv records, as patterns", Shape::texts}};
  }
};
/// [model.dimensionless]'s key besides the paper's parameters (DimensionlessParameters).
struct DimensionlessJoint {
  static constexpr auto fields() {
    return std::tuple{
        CustomField<DimensionlessJoint>{"joint_width", "w̄ = w λ²/g, the joint's width", Shape::number}};
  }
};
/// [model] of the dimensionless form (its parameters: DimensionlessParameters).
struct DimensionlessModel {
  static constexpr auto fields() {
    using C = CustomField<DimensionlessModel>;
    return std::tuple{
        C{"storeys", "the storeys of frames 1 and 2", Shape::integers},
        C{"storey_height", "h [m] of every storey of both frames", Shape::number},
        TableField<DimensionlessModel, DimensionlessParameters, DimensionlessJoint>{"dimensionless",
                                                                                  "the paper's parameters"},
    };
  }
};
/// [[frames]]' keys besides its per-storey values (Frame::fields()) and the parameters of its
/// storey law.
struct Frame {
  static constexpr auto fields() {
    using C = CustomField<Frame>;
    return std::tuple{
        C{"name", "a label for messages", Shape::text},
        C{"storeys", "the number of floors", Shape::integer},
        C{"damping_ratio", "ζ of stiffness-proportional damping", Shape::number},
        C{"rayleigh_ratios", "[ζ_i, ζ_j] of Rayleigh damping C = a₀M + a₁K", Shape::numbers},
        C{"rayleigh_modes", "[i, j], the modes of rayleigh_ratios", Shape::integers},
        LawField<Frame, StoreyLawParameters>{
            "storey_law", "the storeys' law (model/law.hpp's StoreyLawParameters), \"linear\" by default"},
    };
  }
};
/// [[gap_elements.pair]]'s keys.
struct GapPair {
  static constexpr auto fields() {
    using C = CustomField<GapPair>;
    return std::tuple{
        C{"frames", "the two neighbouring frames, e.g. [1, 2]", Shape::integers},
        C{"floors", "the floor of each, from 1: [left, right]", Shape::integers},
        C{"slab", "instead of floors: [frame, floor] of a slab that strikes the other frame's column",
          Shape::integers},
    };
  }
};
/// [[gap_elements.override]]'s keys besides the parameters of the element's law.
struct GapOverride {
  static constexpr auto fields() {
    using C = CustomField<GapOverride>;
    return std::tuple{
        LawField<GapOverride, GapLaw>{"law", "the element's law; [gap_elements]' by default", true},
        C{"frames", "the two neighbouring frames", Shape::integers},
        C{"floor", "the floor, from 1", Shape::integer},
        C{"right_floor", "the element's floor in the right frame, when elements share the left floor",
          Shape::integer},
        C{"joint_width", "w [m], the joint's width", Shape::number},
    };
  }
};
/// [gap_elements]' keys besides the parameters of the element's law (its Parameters' fields).
struct GapElements {
  static constexpr auto fields() {
    using G = GapElements;
    return std::tuple{
        LawField<G, GapLaw>{"law", "the gap elements' law (model/law.hpp's GapLaw), \"paper\" by default"},
        CustomField<G>{"joint_width", "w [m], the joint's width", Shape::number},
        TableField<G, GapOverride>{"override", "changes to single elements", true},
        named_field<G>("pairing", names::pairing,
                       "which floors the elements join: \"floor\" (same number), \"height\" or \"listed\""),
        TableField<G, GapPair>{"pair", "with pairing = \"listed\": one table per pair of floors", true},
    };
  }
};
/// [initial].
struct Initial {
  static constexpr auto fields() {
    using C = CustomField<Initial>;
    return std::tuple{
        C{"displacement", "u [m] per frame and floor", Shape::rows},
        C{"velocity", "u̇ [m/s] per frame and floor", Shape::rows},
    };
  }
};
/// [excitation].
struct Excitation {
  static constexpr auto fields() {
    using E = Excitation;
    using C = CustomField<E>;
    return std::tuple{
        named_field<E>("kind", names::excitation_kind, "harmonic, record or none"),
        C{"amplitude_g", "A [g]", Shape::number},
        C{"ratio", "ω̄/ω₁", Shape::number},
        C{"omega", "ω̄ [rad/s]", Shape::number},
        C{"frequency_hz", "ω̄/(2π) [Hz]", Shape::number},
        C{"file", "the record file", Shape::text},
        named_field<E>("format", names::record_format, "the record's format"),
        named_field<E>("units", names::record_units, "the record's units"),
        C{"scale", "a factor on the accelerations", Shape::number},
        C{"target_pga_g", "the peak to scale the record to [g]", Shape::number},
        C{"dt", "the sampling interval of a one-column file or of acceleration [s]", Shape::number},
        C{"column", "the acceleration column", Shape::integer},
        C{"acceleration", "the record's samples, every dt seconds (instead of a file)", Shape::numbers},
    };
  }
};
}  // namespace keys

/// How the excitation was described, for reports (the Excitation itself is in SI).
struct ExcitationInfo {
  std::string kind;                   ///< "none", "harmonic" or "record".
  double amplitude_g = 0.0;           ///< Harmonic: A/g.
  double omega = 0.0;                 ///< Harmonic: ω̄ [rad/s].
  double omega1 = 0.0;                ///< ω₁ of frame 1 alone [rad/s].
  std::filesystem::path record_file;  ///< Record: the file read.
  double record_scale = 1.0;          ///< Record: scale factor applied (given, or from the target PGA).
  std::string record_units;           ///< Record: units of the file's accelerations.
  std::string record_format;          ///< Record: "at2", "cosmos", "columns" or "single".
  std::string record_description;     ///< Record: event, station, component from the header.
  int record_points = 0;              ///< Record: samples.
  double record_dt = 0.0;             ///< Record: sampling interval [s] (0: not uniform).
  double record_pga_file_g = 0.0;     ///< Record: PGA of the file, in g.
  double record_pga_g = 0.0;          ///< Record: PGA applied, in g.
  double record_duration = 0.0;       ///< Record: last sample time [s].
  RecordOptions record_options;       ///< Record: the keys that read it (format, units, scale, …).
  /// Record given as samples (excitation.acceleration) instead of a file: them, unscaled.
  std::vector<double> record_samples;
};

/// How [ensemble.scaling] scales the records (docs/records.md#scaling-to-a-target).
enum class ScalingKind : std::uint8_t {
  pga,       ///< each record to a peak ground acceleration
  sa,        ///< each record to a spectral acceleration at one period (T₁ of a frame, or given)
  spectrum,  ///< one factor for the suite: its mean spectrum against a design spectrum over a range
};
inline constexpr std::array<std::pair<std::string_view, ScalingKind>, 3> scaling_kind_names{{
    {"pga", ScalingKind::pga},
    {"sa", ScalingKind::sa},
    {"spectrum", ScalingKind::spectrum},
}};

/// [ensemble.scaling]: the factor each record of an ensemble is scaled by before it runs (its
/// excitation.scale), from its elastic spectrum (analysis/response_spectrum.hpp). Accelerations
/// in g (9.81 m/s²), periods in s.
struct EnsembleScaling {
  ScalingKind kind = ScalingKind::spectrum;
  std::optional<double> target_g;         ///< pga; sa when no design spectrum gives the target.
  std::optional<DesignSpectrum> design;   ///< sa (its value at the period) or spectrum (required).
  std::optional<double> period;           ///< sa: the period [s]; default T₁ of `frame`.
  int frame = 1;                          ///< Whose T₁ (alone, fixed base) sets sa's period and spectrum's range.
  std::optional<double> period_min, period_max;  ///< spectrum: the range; default [0.2 T₁, 2 T₁] (EC8 §3.2.3.1.2).
  SuiteMatch match = SuiteMatch::least_squares;
  double fraction = 0.9;                  ///< not_below: the mean ≥ fraction × target over the range.
  int points = 50;                        ///< spectrum: periods of the range, log-spaced.
  SpectrumOptions spectrum;               ///< damping and sub-steps of the records' spectra.
  /// The design spectrum's accelerations as the file gave them (in g): input.toml writes them
  /// back to the bit, which a conversion from m/s² need not.
  double ag_g = 0.0;
  std::vector<std::vector<double>> table_g;

  static constexpr auto fields() {
    using S = EnsembleScaling;
    using C = CustomField<S>;
    return std::tuple{
        ChoiceField{"kind", &S::kind, scaling_kind_names, "what each record is scaled to", true},
        C{"target_g", "the target PGA or S_a [g]", Shape::number},
        named_field<S>("design", names::design_spectrum, "the design spectrum: \"ec8_type1\", \"ec8_type2\" or \"table\""),
        named_field<S>("ground_type", names::ground_type, "Eurocode 8 ground type A … E"),
        C{"ag_g", "Eurocode 8 design ground acceleration a_g on type A ground [g]", Shape::number},
        C{"table", "rows [T, S_a in g] of a tabulated design spectrum", Shape::rows},
        C{"period", "the period of S_a [s] (sa)", Shape::number},
        IntegerField{"frame", &S::frame, 1, limits::frames, "the frame whose T₁ sets the period or the range"},
        C{"period_min", "the range's shortest period [s] (spectrum)", Shape::number},
        C{"period_max", "the range's longest period [s] (spectrum)", Shape::number},
        ChoiceField{"match", &S::match, suite_match_names, "how the suite's factor is chosen (spectrum)"},
        NumberField{"fraction", &S::fraction, "", Interval{.lo = 0.0, .hi = 1.0, .lo_open = true},
                    "not_below: the fraction of the target the mean may not fall below"},
        IntegerField{"points", &S::points, 2, 10000, "periods of the range (spectrum)"},
    };
  }
};

/// [ensemble]: the records one model is run against.
struct EnsembleSettings {
  std::vector<std::filesystem::path> records;  ///< Resolved, in the order given (or sorted).
  int threads = 0;                             ///< 0: all cores.
  bool baseline = false;                       ///< Also run bare pounding for each record.
  std::optional<EnsembleScaling> scaling;      ///< [ensemble.scaling]: none keeps [excitation]'s scale.

  /// The fields of [ensemble] read as declared (fields.hpp); the records have rules of their own.
  static constexpr auto fields() {
    using E = EnsembleSettings;
    using C = CustomField<E>;
    return std::tuple{
        C{"records", "the record files", Shape::texts},
        C{"folder", "a folder of records", Shape::text},
        C{"pattern", "the names of its files to run (* and ?)", Shape::text},
        threads_field(&E::threads, "records run in parallel"),
        BoolField{"baseline", &E::baseline, "also run bare pounding for each record"},
        TableField<E, EnsembleScaling, SpectrumOptions>{"scaling", "how each record is scaled (a table of its own)"},
    };
  }
};

/// What an input runs (analysis.kind).
enum class AnalysisKind : std::uint8_t { time_history, frf, continuation, ensemble, study, optimize };
inline constexpr std::array<std::pair<std::string_view, AnalysisKind>, 6> analysis_kind_names{{
    {"time_history", AnalysisKind::time_history},
    {"frf", AnalysisKind::frf},
    {"continuation", AnalysisKind::continuation},
    {"ensemble", AnalysisKind::ensemble},
    {"study", AnalysisKind::study},
    {"optimize", AnalysisKind::optimize},
}};
[[nodiscard]] constexpr std::string_view to_string(AnalysisKind kind) { return name_in(analysis_kind_names, kind); }

/// What one point of a study, or one evaluation of the optimiser, runs (`each`).
enum class PointRun : std::uint8_t { frf, time_history, ensemble };
inline constexpr std::array<std::pair<std::string_view, PointRun>, 3> point_run_names{{
    {"frf", PointRun::frf},
    {"time_history", PointRun::time_history},
    {"ensemble", PointRun::ensemble},
}};
[[nodiscard]] constexpr std::string_view to_string(PointRun run) { return name_in(point_run_names, run); }

/// How a study chooses its points (study.sampling).
enum class Sampling : std::uint8_t { grid, list, random };
inline constexpr std::array<std::pair<std::string_view, Sampling>, 3> sampling_names{{
    {"grid", Sampling::grid},
    {"list", Sampling::list},
    {"random", Sampling::random},
}};
[[nodiscard]] constexpr std::string_view to_string(Sampling sampling) { return name_in(sampling_names, sampling); }

/// [analysis]: what to run. Time-history keys apply to kind = "time_history".
struct AnalysisSettings {
  AnalysisKind kind = AnalysisKind::time_history;
  double duration = 0.0;        ///< [s]
  double output_dt = 0.0;       ///< Spacing of history rows [s], a multiple of dt.
  TimeHistoryOptions options;   ///< dt, integrator, event_tolerance, lock_time, separation, …
  /// The most integration steps (time history: duration/dt; frequency response: the worst case
  /// over all points) and history rows the input may ask for.
  double max_steps = limits::max_steps;

  /// The keys of [analysis] besides the integration options (TimeHistoryOptions::fields()).
  static constexpr auto fields() {
    using A = AnalysisSettings;
    using C = CustomField<A>;
    return std::tuple{
        ChoiceField{"kind", &A::kind, analysis_kind_names, "the analysis", true},
        C{"duration", "simulated time; a record's length when absent", Shape::number},
        C{"dt", "the Newmark step of a time history", Shape::number},
        C{"output_dt", "the spacing of history rows, a multiple of dt (default dt)", Shape::number},
        NumberField{"max_steps", &A::max_steps, "", Interval{.lo = 1.0, .hi = limits::max_steps_limit},
                    "the most steps (and history rows) a run may take"},
    };
  }
};

/// [frf] of a frequency-response analysis.
struct FrfSettings {
  double amplitude_g = 0.0;           ///< A/g of a_g = A sin(ω̄t)
  std::vector<double> ratios;         ///< ω̄/ω₁, ascending
  FrfMethod method = FrfMethod::simulation;
  SweepMode sweep = SweepMode::from_rest;
  SteadyStateOptions steady;
  ShootingOptions shooting;           ///< [frf.continuation]
  ContinuationOptions continuation;   ///< [frf.continuation]
  int threads = 0;                    ///< 0: all cores
  int lanes = 8;                      ///< points stepped together by each thread (FrequencyResponseOptions::lanes)

  /// The fields of [frf] read as declared (fields.hpp); the ratios and the steady-state options
  /// are read with their own rules.
  static constexpr auto fields() {
    using F = FrfSettings;
    return std::tuple{
        NumberField{"amplitude_g", &F::amplitude_g, "g", any_finite, "A of a_g = A g sin(ω̄t)", true},
        CustomField<F>{"ratios", "the list of ω̄/ω₁", Shape::number_or_numbers},
        CustomField<F>{"ratio_min", "the first of `points` evenly spaced ratios", Shape::number},
        CustomField<F>{"ratio_max", "the last of them", Shape::number},
        CustomField<F>{"points", "how many", Shape::integer},
        ChoiceField{"method", &F::method, frf_method_names,
                    "simulate until the response repeats, or shoot and continue every periodic branch"},
        ChoiceField{"sweep", &F::sweep, sweep_mode_names,
                    "simulation: every point from rest, or a sweep up, down or both ways through the ratios"},
        TableField<F, ContinuationOptions, ShootingOptions>{"continuation", "the continuation's options (method = \"continuation\")"},
        threads_field(&F::threads, "worker threads"),
        IntegerField{"lanes", &F::lanes, 1, 8,
                     "simulation from rest with Newmark: points each thread steps together (1: one at a time)"},
    };
  }
};

/// One varied input key of a parametric study: a list of values, or a range (either–or).
struct StudyParameter {
  std::string key;                  ///< Any input key, dotted (as --set takes it).
  std::vector<SettingValue> values;  ///< Grid or list: the values, typed as the file gives them.
  /// Range (grid with `points`, or random); not a number for a list of values.
  double min = std::numeric_limits<double>::quiet_NaN(), max = std::numeric_limits<double>::quiet_NaN();
  int points = 0;                   ///< A grid's points on the range; 0 for a list of values.
  bool log = false;                 ///< Logarithmic spacing / sampling of the range.
  std::string where;                ///< "file:line:column: study.parameter[i].key", for messages.

  static constexpr auto fields() {
    using S = StudyParameter;
    return std::tuple{TextField<S>{"key", &S::key, "any input key", true},
                      CustomField<S>{"values", "the values", Shape::scalars},
                      NumberField<S>{"min", &S::min, "", any_finite, "the range's start"},
                      NumberField<S>{"max", &S::max, "", any_finite, "the range's end"},
                      IntegerField<S>{"points", &S::points, 2, limits::study_points, "a grid's points"},
                      ChoiceField{"scale", &S::log, axis_scale_names, "linear or log"}};
  }
};

/// [study] (analysis.kind = "study").
struct StudySettings {
  PointRun each = PointRun::frf;     ///< What each point runs.
  Sampling sampling = Sampling::grid;
  std::vector<StudyParameter> parameters;
  int samples = 0;                   ///< Random sampling: number of points.
  unsigned seed = 1;                 ///< Random sampling: seed (same seed, same points).
  double band_min = 0.0, band_max = 0.0;  ///< Frequency band of the peak metrics (ω̄/ω₁).
  bool baseline = true;              ///< Also run bare pounding (k = c = ε = 0) for the ratios.
  int threads = 0;                   ///< 0: all cores.

  /// The fields of [study] read as declared (fields.hpp); the others have rules of their own.
  static constexpr auto fields() {
    using S = StudySettings;
    using C = CustomField<S>;
    return std::tuple{
        ChoiceField{"each", &S::each, point_run_names, "what each point runs", true},
        ChoiceField{"sampling", &S::sampling, sampling_names, "grid, list or random"},
        C{"samples", "random sampling: the number of points", Shape::integer},
        C{"seed", "random sampling: the seed", Shape::integer},
        C{"band", "the frequency band of the peak metrics", Shape::numbers},
        TableField<S, StudyParameter>{"parameter", "a varied key", true},
        BoolField{"baseline", &S::baseline, "also run bare pounding for the ratio_to_bare metrics"},
        threads_field(&S::threads, "points run in parallel"),
    };
  }
};

/// [parameter] (analysis.kind = "continuation"): the model parameter periodic orbits are
/// continued in, at [frf]'s one forcing frequency.
struct ContinuedParameter {
  std::string key;                   ///< A numeric key of the model, dotted (as --set takes it).
  double min = 0.0, max = 0.0;
  std::optional<double> start;       ///< Where the seed is shot; the reader sets it to min if absent.
  std::string where;                 ///< "file:line:column: parameter.key", for messages.

  static constexpr auto fields() {
    using C = ContinuedParameter;
    return std::tuple{TextField<C>{"key", &C::key, "a numeric key of the model", true},
                      NumberField<C>{"min", &C::min, "", any_finite, "the range's start", true},
                      NumberField<C>{"max", &C::max, "", any_finite, "the range's end", true},
                      OptionalNumberField<C>{"start", &C::start, "", any_finite, "where the orbit is seeded (default min)"}};
  }
};

/// One design variable of the optimiser.
struct OptimizeVariable {
  std::string key;
  double min = 0.0, max = 0.0;
  std::optional<double> start;       ///< Default: the middle of [min, max] (geometric on a log scale).
  /// NLopt searches log(value) (scale = "log"; min > 0): steps and a global algorithm's samples
  /// spread over decades alike, as a study's log axis does.
  bool log = false;
  std::string where;                 ///< "file:line:column: optimize.variable[i].key", for messages.

  static constexpr auto fields() {
    using V = OptimizeVariable;
    return std::tuple{TextField<V>{"key", &V::key, "any input key", true},
                      NumberField<V>{"min", &V::min, "", any_finite, "the lower bound", true},
                      NumberField<V>{"max", &V::max, "", any_finite, "the upper bound", true},
                      OptionalNumberField<V>{"start", &V::start, "", any_finite, "the starting value"},
                      ChoiceField{"scale", &V::log, axis_scale_names,
                                  "\"linear\" or \"log\": NLopt searches the value or its logarithm"}};
  }
};

/// A limit on a figure of each evaluation, min ≤ figure ≤ max (either may be absent, not both).
struct OptimizeConstraint {
  std::string metric;  ///< A figure's column (docs/studies.md#figures).
  std::optional<double> min, max;
  std::string where;   ///< "file:line:column: optimize.constraint[i].metric", for messages.

  static constexpr auto fields() {
    using C = OptimizeConstraint;
    return std::tuple{
        TextField<C>{"metric", &C::metric, "a figure of each evaluation (a study column)", true, {}, name_a_figure},
        OptionalNumberField<C>{"min", &C::min, "", any_finite, "its lower limit"},
        OptionalNumberField<C>{"max", &C::max, "", any_finite, "its upper limit"}};
  }
};

/// The trade-off between two figures, by the ε-constraint method: `objective` is minimised with
/// `metric` ≤ each limit in turn.
struct ParetoSettings {
  std::string objective;        ///< The first figure's column (the reader defaults it to optimize.objective).
  std::string metric;           ///< The second one's.
  std::vector<double> limits;   ///< Given limits (ascending), or …
  int points = 0;               ///< … this many, spread between the two objectives' own optima.
  std::string where;            ///< "file:line:column: optimize.pareto.metric".
  std::string objective_where;  ///< "file:line:column: optimize.pareto.objective" ("" when defaulted).

  static constexpr auto fields() {
    using P = ParetoSettings;
    return std::tuple{
        TextField<P>{"objective", &P::objective, "the figure minimised along the front (default: optimize.objective)",
                     false, {}, name_a_figure},
        TextField<P>{"metric", &P::metric, "the second objective, bounded in turn", true, {}, name_a_figure},
        NumberListField<P>{"limits", &P::limits, "", any_finite, "its upper limits", 1,
                           static_cast<std::size_t>(limits::pareto_points), true},
        IntegerField<P>{"points", &P::points, 2, limits::pareto_points,
                        "points of the front between the two objectives' optima"}};
  }
};

/// What `optimize.objective = "max_peak"` (the first name it had) names: the column max_peak_V_W.
inline constexpr std::string_view objective_alias = "max_peak";

/// [optimize] (analysis.kind = "optimize").
struct OptimizeSettings {
  PointRun each = PointRun::frf;            ///< What each evaluation runs.
  /// The figure minimised: any column of an evaluation's figures (docs/studies.md#figures).
  std::string objective = "max_peak_V_W";
  std::string objective_where;              ///< Where the file gives it ("" when defaulted).
  double band_min = 0.0, band_max = 0.0;    ///< Band of the frequency-response objective.
  std::vector<OptimizeVariable> variables;
  std::vector<OptimizeConstraint> constraints;
  /// A constraint holds when it is broken by at most this share of its limit (or absolutely,
  /// for a limit of 0): NLopt's constrained algorithms approach a limit from either side.
  double constraint_tolerance = 1e-6;
  std::optional<ParetoSettings> pareto;
  std::string global_algorithm = "GN_DIRECT_L";  ///< NLopt name; "none" skips the global stage.
  std::string local_algorithm = "LN_BOBYQA";     ///< NLopt name; "none" skips the local stage.
  int global_evaluations = 100;
  int local_evaluations = 60;
  double relative_tolerance = 1e-4;         ///< Local stage: stop when the objective changes less.
  unsigned seed = 1;                        ///< For stochastic NLopt algorithms.
  int threads = 0;                          ///< Threads of each evaluation's frequency response.

  /// The fields of [optimize] read as declared (fields.hpp); the others have rules of their own.
  static constexpr auto fields() {
    using O = OptimizeSettings;
    using C = CustomField<O>;
    return std::tuple{
        ChoiceField{"each", &O::each, point_run_names, "what each evaluation runs", true},
        TextField<O>{"objective", &O::objective, "the figure minimised (a study column; max_peak: max_peak_V_W)",
                     false, {}, name_a_figure},
        TableField<O, OptimizeConstraint>{"constraint", "a limit on a figure", true},
        TableField<O, ParetoSettings>{"pareto", "a trade-off with a second figure"},
        NumberField{"constraint_tolerance", &O::constraint_tolerance, "", positive,
                    "a constraint holds when broken by at most this share of its limit"},
        C{"band", "the frequency band of the objective", Shape::numbers},
        TextField<O>{"global", &O::global_algorithm, "the global NLopt algorithm, or none"},
        TextField<O>{"local", &O::local_algorithm, "the local NLopt algorithm, or none"},
        TableField<O, OptimizeVariable>{"variable", "a design variable", true},
        IntegerField{"global_evaluations", &O::global_evaluations, 1, limits::evaluations,
                     "the budget of the global stage"},
        IntegerField{"local_evaluations", &O::local_evaluations, 1, limits::evaluations,
                     "the budget of the local stage"},
        NumberField{"relative_tolerance", &O::relative_tolerance, "", positive,
                    "the local stage stops when the objective changes less"},
        IntegerField{"seed", &O::seed, 0, limits::seed, "for stochastic NLopt algorithms"},
        threads_field(&O::threads, "threads of each evaluation's frequency response"),
    };
  }
};

namespace keys {
/// The top level of the file: its tables and the structs that declare their keys. It is the
/// root of the input's schema (io/schema.hpp).
struct File {
  static constexpr auto fields() {
    using F = File;
    return std::tuple{
        CustomField<F>{"title", "free text, copied to summary.json", Shape::text},
        TableField<F, DimensionlessModel>{"model", "the dimensionless form"},
        TableField<F, Frame, poundsim::Frame>{"frames", "the physical form: one table per frame", true},
        TableField<F, GapElements>{"gap_elements", "the physical form's gap elements"},
        TableField<F, Initial>{"initial", "initial displacements and velocities"},
        TableField<F, Excitation>{"excitation", "the ground acceleration"},
        TableField<F, TimeHistoryOptions, AnalysisSettings>{"analysis", "what to run", false, true},
        TableField<F, FrfSettings, SteadyStateOptions>{"frf", "a frequency response"},
        TableField<F, StudySettings>{"study", "a parametric study"},
        TableField<F, OptimizeSettings>{"optimize", "an optimisation"},
        TableField<F, EnsembleSettings>{"ensemble", "the records of an ensemble"},
        TableField<F, ContinuedParameter>{"parameter", "the model parameter a continuation follows"},
        TableField<F, Output>{"output", "what a time history records"},
    };
  }
};
}  // namespace keys

/// Everything a run needs, in SI.
struct RunInput {
  std::filesystem::path source;  ///< The model file.
  /// Its text: with the settings, it identifies the run in a study database (fingerprint).
  std::string text;
  /// The file as parsed, before the settings: a study point or an optimiser evaluation applies
  /// its own settings to a copy of it (with_settings).
  std::shared_ptr<const ParsedInput> parsed;
  std::vector<Setting> settings;  ///< The --set applied to it, in order.
  std::filesystem::path base_dir;  ///< Folder that relative paths in it start from.
  std::string title;
  Model model;
  /// Per element of model.gaps: the width w [m] of the joint between the two buildings, where
  /// their floors would collide without the element (gap + shortening ≤ w). Bare pounding, the
  /// reference of studies and the optimiser, closes at w. Default: the element's gap.
  std::vector<double> joint_widths;
  std::optional<DimensionlessParameters> dimensionless;  ///< When given in that form.
  Excitation excitation;
  ExcitationInfo excitation_info;
  AnalysisSettings analysis;
  std::optional<FrfSettings> frf;  ///< For kind = "frf" and "continuation" (which have no [excitation]).
  std::optional<ContinuedParameter> parameter;  ///< For kind = "continuation".
  std::optional<StudySettings> study;        ///< For kind = "study".
  std::optional<EnsembleSettings> ensemble;  ///< For kind = "ensemble", or each = "ensemble".
  std::optional<OptimizeSettings> optimize;  ///< For kind = "optimize".
  /// What one point of the analysis runs: kind itself, or study.each / optimize.each; an
  /// ensemble's points are time histories.
  [[nodiscard]] PointRun each() const {
    if (study) return study->each;
    if (optimize) return optimize->each;
    return analysis.kind == AnalysisKind::frf || analysis.kind == AnalysisKind::continuation ? PointRun::frf
                                                                                              : PointRun::time_history;
  }
  InitialConditions initial;
  /// [output] channels: what history.csv records, as patterns of channel names
  /// (analysis/channels.hpp); empty: the default channels.
  std::vector<std::string> channels;
};

/// What a reading of the file with settings is for. An ensemble's record is set as
/// `excitation.file` (and, for a scaled suite, its factor as `excitation.scale`), which [ensemble]
/// forbids anywhere else: the reader is told, rather than guessing it from the keys set.
enum class Reading {
  run,              ///< The run as given, a study point, an optimiser evaluation.
  ensemble_record,  ///< One of the ensemble's records, named by the settings.
};

/// `base` read again with `settings` applied after its own (a study point, an optimiser evaluation,
/// an ensemble's record): the same checks, on the file as parsed, with typed values.
RunInput with_settings(const RunInput& base, std::span<const Setting> settings, Reading reading = Reading::run);

/// Reads and validates `file`, after applying the `--set key=value` overrides (dotted keys,
/// `frames[2].mass` for the second frame; the value is a TOML value, or a bare string).
/// Relative record paths are resolved against the model file's folder.
RunInput read_input(const std::filesystem::path& file, std::span<const std::string> overrides = {});

/// The TOML text of `x` for a `--set` value: the shortest form that reads back to the same double,
/// with ".0" added when needed so that it stays a float (1 → "1.0").
[[nodiscard]] std::string toml_float(double x);

/// The input as run, as a model file: every key with the value used (defaults, --set and study
/// values applied, the model in the physical form and SI, record paths absolute). Reading it
/// gives the same model, excitation and settings (not the dimensionless parameters: the model is
/// written in the physical form); time histories, frequency responses and ensembles write it to
/// DIR/input.toml, so that the run can be repeated from its outputs alone (docs/output.md).
/// Studies and optimisations write to_toml_as_written instead.
[[nodiscard]] std::string to_toml(const RunInput& input);

/// The input as written: the file as parsed, with its settings (--set) applied and its record
/// paths (excitation.file, ensemble.records and folder, a study's excitation.file values) made
/// absolute. Studies and optimisations write it to DIR/input.toml: their axes and variables name
/// keys of the file's own form (model.dimensionless.eta, excitation.ratio, a key gap-element
/// overrides inherit), which to_toml would rewrite.
[[nodiscard]] std::string to_toml_as_written(const RunInput& input);

/// Like read_input, from the model file's document as JSON (objects for tables, arrays, numbers
/// — an integer stays one — strings, booleans): a model built in Python (docs/python.md). The
/// same keys, rules and messages as a file, with `name` for the file; `base_dir` resolves paths.
RunInput read_input_document(const nlohmann::json& document, const std::string& name,
                             const std::filesystem::path& base_dir, std::span<const std::string> overrides = {});

/// The input as written (to_toml_as_written) as such a JSON document: read_input_document of it
/// reads the same input.
[[nodiscard]] nlohmann::json input_document(const RunInput& input);

/// Like read_input, from TOML text; `name` is used in messages and `base_dir` resolves paths.
RunInput read_input_string(std::string_view text, const std::string& name,
                           const std::filesystem::path& base_dir,
                           std::span<const std::string> overrides = {});

}  // namespace poundsim::io
