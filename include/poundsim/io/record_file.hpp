#pragma once
/// @file
/// Ground-motion records as plain text: two columns, time [s] and acceleration, separated by
/// blanks or a comma. Blank lines and lines starting with '#' are skipped. Errors name the file
/// and the line.

#include <filesystem>

#include "poundsim/excitation.hpp"

namespace poundsim::io {

/// Reads a two-column record; accelerations are multiplied by `to_si` (e.g. scale × g for a file
/// in g) to give m/s². Throws InputError for an unreadable file, a malformed line, a non-finite
/// value, times that do not increase strictly, a negative first time or fewer than two samples.
RecordExcitation read_two_column_record(const std::filesystem::path& file, double to_si);

}  // namespace poundsim::io
