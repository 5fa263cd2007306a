#pragma once
/// @file
/// Which integrator can integrate which laws. The simulator's loop advances grid steps through one
/// interface with two implementations (src/integrate/steppers.hpp): Newmark's average
/// acceleration and the exact piecewise-analytic integrator, which between events solves each
/// phase in closed form. Both step the linear system of the current modes (LinearPhase, built
/// from each law's linear form). The exact integrator needs every law to be linear in each of its
/// modes (LawTraits::piecewise_linear); Newmark also takes the smooth laws that give their
/// consistent tangent (LawTraits::newton: Hertz, Hertzdamp, Jankowski), whose forces it solves by
/// Newton iterations (newmark.hpp). The simulator asks `supports` before it starts and rejects the
/// model with the reason.

#include <span>
#include <string>

#include "poundsim/model/law.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// How a phase is integrated between events.
enum class Integrator : std::uint8_t {
  /// Newmark's average-acceleration method with step dt; events located on its trajectory to
  /// event_tolerance.
  newmark,
  /// The closed-form solution of each phase (exact_phase.hpp); events are roots of exact guard
  /// functions, located to near machine precision with a proof that none is missed. dt is then
  /// only the sampling interval of peaks, energies and outputs.
  exact,
};

[[nodiscard]] std::string_view to_string(Integrator integrator);

/// Whether an integrator can integrate a set of laws; if not, `reason` says why and what to do.
struct IntegratorSupport {
  bool supported = true;
  std::string reason;
  explicit operator bool() const { return supported; }
};

/// Whether `integrator` can integrate links with these laws' traits (one per link, in order).
[[nodiscard]] IntegratorSupport supports(Integrator integrator, std::span<const LawTraits> laws);

/// The same for the laws of `links`, a refusal naming the link (describe).
[[nodiscard]] IntegratorSupport supports(Integrator integrator, std::span<const Link> links, const DofLayout& layout);

}  // namespace poundsim
