#pragma once
/// @file
/// Ground-motion records in the formats engineers download (details and real examples in
/// data/ground_motions/FORMATS.md):
///
/// - PEER `.AT2` — four header lines, then NPTS values; every NPTS/DT spelling (`NPTS= 5372,
///   DT= .0100 SEC`, `4096 0.0100 NPTS, DT`, reversed, unlabelled); units from line 3.
/// - COSMOS V2 (`.V2c`, format v01.20) — text, integer, real and comment headers with their own
///   counts; dt from real header #62 (ms); units from the data-section header. First channel.
/// - Column text — time and acceleration (and possibly more columns: choose one); header lines
///   and `#`/`%` comments skipped; blanks, tabs, `,` or `;` between values.
/// - One column — one acceleration per line, dt given.
///
/// Every problem is an InputError naming the file and the line: a header that says nothing of
/// NPTS or DT, a count larger than the file can hold or that its lines do not hold (COSMOS), a
/// sampling interval that is not a finite number > 0, times that overflow, fewer or more values
/// than NPTS, text where a number should be, NaN or infinity, times that do not increase,
/// unknown units. Nothing is guessed: column files must declare their units.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "poundsim/error.hpp"
#include "poundsim/model/excitation.hpp"

namespace poundsim::io {

enum class RecordFormat { automatic, at2, cosmos, columns, single };
/// The names of excitation.format (docs/records.md), for the reader and the echo writer.
inline constexpr std::array<std::pair<std::string_view, RecordFormat>, 5> record_format_names{{
    {"auto", RecordFormat::automatic},
    {"at2", RecordFormat::at2},
    {"cosmos", RecordFormat::cosmos},
    {"columns", RecordFormat::columns},
    {"single", RecordFormat::single},
}};

/// The units a record's accelerations may be in (RecordOptions::units).
inline constexpr std::array<std::string_view, 3> record_unit_names{"g", "m/s2", "cm/s2"};

struct RecordOptions {
  RecordFormat format = RecordFormat::automatic;  ///< From the extension and the first line.
  std::string units;           ///< "g", "m/s2" or "cm/s2"; required for column formats; when
                               ///< given for AT2/COSMOS it must agree with the file.
  double scale = 1.0;          ///< Factor on the accelerations.
  std::optional<double> target_pga_g;  ///< Scale instead so that max|a_g| = this × g.
  double dt = 0.0;             ///< Single column: the sampling interval [s].
  int column = 2;              ///< Columns: the acceleration column (1-based; column 1 is time).
  double gravity = 9.81;       ///< g [m/s²] for records in g (the paper's value).
};

/// The record is fine but `scale` or `target_pga_g` makes an acceleration overflow in m/s²: a
/// caller reading them from its own input can blame that key rather than the file.
class RecordScaleError : public InputError {
 public:
  using InputError::InputError;
};

/// A record read and converted to m/s².
struct GroundMotionRecord {
  RecordExcitation excitation;  ///< time [s], acceleration [m/s²] (scaled)
  std::string format;           ///< "at2", "cosmos", "columns" or "single"
  std::string description;      ///< Event, station, component as the header says.
  std::string file_units;       ///< Units of the file's numbers.
  int points = 0;
  double dt = 0.0;              ///< Sampling interval [s] (0 for non-uniform column files).
  double pga_file_g = 0.0;      ///< Peak |a| of the file before scaling, in g.
  double scale = 1.0;           ///< Factor applied (scale or from target_pga_g).
  double pga_g = 0.0;           ///< Peak |a_g| after scaling, in g.
  double duration = 0.0;        ///< Last sample time [s].
};

/// Reads `file`. Throws InputError naming the file and line on any problem. Files larger than
/// 64 MiB are refused (the longest records are tens of MB; a device never ends), and no header
/// count is trusted beyond what the file can hold.
GroundMotionRecord read_ground_motion(const std::filesystem::path& file, const RecordOptions& options);

/// The same for a file's `content` already in memory; `file` names it in messages and, with its
/// extension, chooses the format as read_ground_motion does (for tests and fuzzing).
GroundMotionRecord parse_ground_motion(std::string content, const std::filesystem::path& file,
                                       const RecordOptions& options);

/// A record given as its samples (the Python module's arrays, excitation.acceleration):
/// `acceleration` in `options.units` every `options.dt` seconds from t = 0, scaled as a file's
/// would be. Throws InputError naming `name` for a missing dt or units, fewer than two samples or
/// one that is not finite.
GroundMotionRecord record_from_samples(std::vector<double> acceleration, const RecordOptions& options,
                                       const std::filesystem::path& name);

/// "g" → gravity, "m/s2" → 1, "cm/s2" → 0.01; throws InputError for anything else.
double units_to_si(const std::string& units, double gravity);

}  // namespace poundsim::io
