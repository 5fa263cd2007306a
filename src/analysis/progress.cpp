#include "poundsim/analysis/progress.hpp"

#include <cmath>

#include <fmt/format.h>

namespace poundsim {

std::optional<double> TimeLeft::update(long done, long total, double elapsed) {
  if (!first_done_) first_done_ = done;
  if (done >= total) return 0.0;
  const long since = done - *first_done_;
  if (since <= 0 || !(elapsed > 0)) return std::nullopt;
  return elapsed * static_cast<double>(total - done) / static_cast<double>(since);
}

std::string readable_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const double whole = std::ceil(seconds);
  if (whole < 60) return fmt::format("{:.0f} s", whole);
  const auto s = static_cast<long long>(whole);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
}

}  // namespace poundsim
