#include "poundsim/io/record_scaling.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "poundsim/error.hpp"
#include "poundsim/io/ground_motion.hpp"
#include "poundsim/model/frame.hpp"
#include "poundsim/units.hpp"

namespace poundsim::io {

namespace {

[[noreturn]] void fail(const RunInput& input, const std::string& message) {
  throw InputError(fmt::format("{}: ensemble.scaling: {}", input.source.string(), message));
}

double design_at(const RunInput& input, const DesignSpectrum& design, double period) {
  try {
    return spectral_acceleration(design, period);
  } catch (const std::invalid_argument& e) {
    fail(input, e.what());
  }
}

/// The spectrum, its refusals (a period too short for the record) as the input's.
ResponseSpectrum spectrum_of(const RunInput& input, const RecordExcitation& record, std::span<const double> periods,
                             const SpectrumOptions& options) {
  try {
    return response_spectrum(record, periods, options);
  } catch (const std::invalid_argument& e) {
    fail(input, fmt::format("{}: {}", record.source, e.what()));
  }
}

}  // namespace

SuiteScaling suite_scaling(const RunInput& input) {
  if (!input.ensemble || !input.ensemble->scaling) throw std::logic_error("suite_scaling: no [ensemble.scaling]");
  const EnsembleScaling& s = *input.ensemble->scaling;
  SuiteScaling out;
  RecordOptions options = input.excitation_info.record_options;
  options.scale = 1.0;
  options.target_pga_g.reset();
  for (const std::filesystem::path& file : input.ensemble->records) {
    GroundMotionRecord record = read_ground_motion(file, options);
    out.pga_file_g.push_back(record.pga_file_g);
    out.unscaled.push_back(std::move(record.excitation));
  }
  const Frame& frame = input.model.frames.at(static_cast<std::size_t>(s.frame - 1));
  out.first_period = 2 * std::numbers::pi / fundamental_frequency(frame);
  const auto record_name = [&](std::size_t r) { return input.ensemble->records[r].filename().string(); };
  switch (s.kind) {
    case ScalingKind::pga: {
      out.target_g = s.target_g;
      for (std::size_t r = 0; r < out.unscaled.size(); ++r) {
        const double pga = peak_ground_acceleration(out.unscaled[r]);
        if (!(pga > 0)) fail(input, fmt::format("record {} ({}) has no acceleration to scale", r + 1, record_name(r)));
        out.factors.push_back(*s.target_g * standard_gravity / pga);
      }
      break;
    }
    case ScalingKind::sa: {
      const double period = s.period.value_or(out.first_period);
      out.period = period;
      const double target = s.target_g ? *s.target_g * standard_gravity : design_at(input, *s.design, period);
      out.target_g = target / standard_gravity;
      const double periods[] = {period};
      for (std::size_t r = 0; r < out.unscaled.size(); ++r) {
        const double sa = spectrum_of(input, out.unscaled[r], periods, s.spectrum).pseudo_acceleration[0];
        if (!(sa > 0)) fail(input, fmt::format("record {} ({}) has S_a = 0 at {} s", r + 1, record_name(r), period));
        out.factors.push_back(target / sa);
      }
      break;
    }
    case ScalingKind::spectrum: {
      const double lo = s.period_min.value_or(0.2 * out.first_period), hi = s.period_max.value_or(2.0 * out.first_period);
      out.range = {lo, hi};
      const std::vector<double> periods = log_spaced_periods(lo, hi, s.points);
      std::vector<double> target;
      for (const double t : periods) target.push_back(design_at(input, *s.design, t));
      std::vector<ResponseSpectrum> spectra;
      for (const RecordExcitation& record : out.unscaled) spectra.push_back(spectrum_of(input, record, periods, s.spectrum));
      double factor = 0.0;
      try {
        factor = suite_scale_factor(spectra, target, s.match, s.fraction);
      } catch (const std::invalid_argument& e) {
        fail(input, fmt::format("the range [{}, {}] s: {}", lo, hi, e.what()));
      }
      out.factors.assign(out.unscaled.size(), factor);
      break;
    }
  }
  for (std::size_t r = 0; r < out.factors.size(); ++r) {
    if (!std::isfinite(out.factors[r])) {
      fail(input, fmt::format("record {} ({}): its factor {} is not finite", r + 1, record_name(r), out.factors[r]));
    }
  }
  return out;
}

Table scaled_spectra_table(const RunInput& input, const SuiteScaling& scaling, int count) {
  const EnsembleScaling& s = *input.ensemble->scaling;
  const std::vector<double> periods = log_spaced_periods(0.02, 4.0, count);
  Table table;
  auto& period = table.numbers("period_s", "s");
  period = periods;
  if (s.design) {
    auto& target = table.numbers("target_g", "g");
    for (const double t : periods) {
      // A table covers its own periods only: outside them the column is empty (NaN, never written).
      double value = std::numeric_limits<double>::quiet_NaN();
      try {
        value = spectral_acceleration(*s.design, t) / standard_gravity;
      } catch (const std::invalid_argument&) {
      }
      target.push_back(value);
    }
  }
  std::vector<ResponseSpectrum> spectra;
  for (const RecordExcitation& record : scaling.unscaled) spectra.push_back(response_spectrum(record, periods, s.spectrum));
  auto& mean = table.numbers("mean_g", "g");
  mean.assign(periods.size(), 0.0);
  for (std::size_t r = 0; r < spectra.size(); ++r) {
    auto& column = table.numbers(fmt::format("sa_{}_g", r + 1), "g");
    for (std::size_t i = 0; i < periods.size(); ++i) {
      const double sa = scaling.factors[r] * spectra[r].pseudo_acceleration[i] / standard_gravity;
      column.push_back(sa);
      mean[i] += sa / static_cast<double>(spectra.size());
    }
  }
  return table;
}

nlohmann::json to_json(const RunInput& input, const SuiteScaling& scaling) {
  const EnsembleScaling& s = *input.ensemble->scaling;
  nlohmann::json records = nlohmann::json::array();
  for (std::size_t r = 0; r < scaling.factors.size(); ++r) {
    records.push_back({{"record", input.ensemble->records[r].string()},
                       {"factor", scaling.factors[r]},
                       {"pga_file_g", scaling.pga_file_g[r]},
                       {"pga_g", scaling.factors[r] * scaling.pga_file_g[r]}});
  }
  nlohmann::json j{{"kind", name_in(scaling_kind_names, s.kind)},
                   {"damping", s.spectrum.damping},
                   {"frame", s.frame},
                   {"first_period_s", scaling.first_period},
                   {"records", records}};
  if (scaling.period) j["period_s"] = *scaling.period;
  if (scaling.target_g) j["target_g"] = *scaling.target_g;
  if (scaling.range) {
    j["range_s"] = {scaling.range->first, scaling.range->second};
    j["match"] = name_in(suite_match_names, s.match);
    if (s.match == SuiteMatch::not_below) j["fraction"] = s.fraction;
  }
  if (s.design) j["design"] = design_name(*s.design);
  return j;
}

}  // namespace poundsim::io
