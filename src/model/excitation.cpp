#include "poundsim/model/excitation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace poundsim {

namespace {
template <class... F>
struct overloaded : F... {
  using F::operator()...;
};
template <class... F>
overloaded(F...) -> overloaded<F...>;

double record_acceleration(const RecordExcitation& r, double t) {
  if (t < r.time.front() || t > r.time.back()) return 0.0;
  // First sample strictly after t; the segment is [k-1, k].
  const auto it = std::upper_bound(r.time.begin(), r.time.end(), t);
  if (it == r.time.end()) return r.acceleration.back();
  const auto k = static_cast<std::size_t>(it - r.time.begin());
  const double t0 = r.time[k - 1], t1 = r.time[k];
  const double w = (t - t0) / (t1 - t0);
  return r.acceleration[k - 1] + w * (r.acceleration[k] - r.acceleration[k - 1]);
}
}  // namespace

double ground_acceleration(const Excitation& excitation, double t) {
  return std::visit(
      overloaded{[](const NoExcitation&) { return 0.0; },
                 [t](const HarmonicExcitation& h) { return h.amplitude * std::sin(h.omega * t); },
                 [t](const RecordExcitation& r) { return record_acceleration(r, t); }},
      excitation);
}

double ForcingPiece::at(double t) const {
  return kind == Kind::harmonic ? amplitude * std::sin(omega * t) : value + slope * (t - start);
}

ForcingPiece forcing_piece(const Excitation& excitation, double t) {
  constexpr double forever = std::numeric_limits<double>::infinity();
  return std::visit(
      overloaded{[t](const NoExcitation&) { return ForcingPiece{.start = t, .end = forever}; },
                 [t](const HarmonicExcitation& h) {
                   return ForcingPiece{.kind = ForcingPiece::Kind::harmonic, .start = t,
                                       .end = forever, .amplitude = h.amplitude, .omega = h.omega};
                 },
                 [t](const RecordExcitation& r) {
                   if (t < r.time.front()) return ForcingPiece{.start = t, .end = r.time.front()};
                   if (t >= r.time.back()) return ForcingPiece{.start = t, .end = forever};
                   const auto k = static_cast<std::size_t>(
                       std::upper_bound(r.time.begin(), r.time.end(), t) - r.time.begin());
                   const double t0 = r.time[k - 1], t1 = r.time[k];
                   const double slope = (r.acceleration[k] - r.acceleration[k - 1]) / (t1 - t0);
                   return ForcingPiece{.start = t0, .end = t1, .value = r.acceleration[k - 1],
                                       .slope = slope};
                 }},
      excitation);
}

void validate(const Excitation& excitation) {
  std::visit(overloaded{[](const NoExcitation&) {},
                        [](const HarmonicExcitation& h) {
                          if (!std::isfinite(h.amplitude)) {
                            throw std::invalid_argument("harmonic excitation: amplitude is not finite");
                          }
                          if (!std::isfinite(h.omega) || h.omega <= 0) {
                            throw std::invalid_argument(fmt::format(
                                "harmonic excitation: omega = {} rad/s must be > 0", h.omega));
                          }
                        },
                        [](const RecordExcitation& r) {
                          if (r.time.size() != r.acceleration.size()) {
                            throw std::invalid_argument("record: time and acceleration differ in length");
                          }
                          if (r.time.size() < 2) {
                            throw std::invalid_argument("record: needs at least two samples");
                          }
                          if (!(r.time.front() >= 0)) {
                            throw std::invalid_argument("record: the first time must be ≥ 0");
                          }
                          for (std::size_t k = 0; k < r.time.size(); ++k) {
                            if (!std::isfinite(r.time[k]) || !std::isfinite(r.acceleration[k])) {
                              throw std::invalid_argument(
                                  fmt::format("record: sample {} is not finite", k + 1));
                            }
                            if (k > 0 && !(r.time[k] > r.time[k - 1])) {
                              throw std::invalid_argument(fmt::format(
                                  "record: times must increase strictly (sample {})", k + 1));
                            }
                          }
                        }},
             excitation);
}

}  // namespace poundsim
