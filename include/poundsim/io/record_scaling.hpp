#pragma once
/// @file
/// [ensemble.scaling] applied: the factor of each record of an ensemble from its elastic spectrum
/// (analysis/response_spectrum.hpp), and the scaled spectra that show what the factors did.
/// Each record then runs with its factor as excitation.scale (docs/records.md#scaling-to-a-target).

#include <optional>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "poundsim/analysis/response_spectrum.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/table.hpp"

namespace poundsim::io {

struct SuiteScaling {
  std::vector<double> factors;      ///< Per record, in the ensemble's order.
  std::vector<double> pga_file_g;   ///< Per record, of the file (unscaled) [g].
  double first_period = 0.0;        ///< T₁ of the scaling's frame alone [s].
  std::optional<double> period;     ///< sa: the period of S_a [s].
  std::optional<std::pair<double, double>> range;  ///< spectrum: the matched range [s].
  std::optional<double> target_g;   ///< pga, sa: the target [g].
  std::vector<RecordExcitation> unscaled;  ///< The records as read, scale 1.
};

/// The factors of `input`'s [ensemble.scaling] (which must be there) for `input`'s model. Throws
/// InputError naming ensemble.scaling and the record when a record cannot be scaled (a zero
/// spectrum) or the range leaves the design spectrum's periods.
[[nodiscard]] SuiteScaling suite_scaling(const RunInput& input);

/// spectra.csv: period_s, target_g (the design spectrum, when there is one), mean_g, and sa_<i>_g
/// for record i (1-based, the ensemble's order) scaled by its factor, at `periods` log-spaced
/// from 0.02 to 4 s.
[[nodiscard]] Table scaled_spectra_table(const RunInput& input, const SuiteScaling& scaling, int periods = 100);

/// What summary.json says of it.
[[nodiscard]] nlohmann::json to_json(const RunInput& input, const SuiteScaling& scaling);

}  // namespace poundsim::io
