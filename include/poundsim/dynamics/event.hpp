#pragma once
/// @file
/// Events of a time history: changes of a gap element's phase and impacts, and a storey's
/// yielding and unloading.

#include <cstdint>
#include <string_view>

namespace poundsim {

enum class EventKind : std::uint8_t {
  contact,     ///< The gap closed (s = 0, closing): spring and dashpot engage.
  separation,  ///< Contact ended (s = 0 opening, or F = 0 under the force criterion).
  impact,      ///< The stop was reached (s = ε, closing): velocities jump by the restitution law.
  lock,        ///< Chattering impacts were replaced by a persistent contact at s = ε.
  unlock,      ///< The stop reaction of a locked element turned tensile: it lets go.
  yield,       ///< A storey began to yield (its drift past the yield drift from its plastic drift).
  unload,      ///< A yielding storey turned back: elastic again about a new plastic drift.
};

[[nodiscard]] std::string_view to_string(EventKind kind);

struct Event {
  double time = 0.0;         ///< [s]
  int gap = 0;               ///< Index into Model::gaps.
  EventKind kind = EventKind::contact;
  double rate_before = 0.0;  ///< ṡ = u̇_L − u̇_R before the event [m/s] (closing > 0).
  double rate_after = 0.0;   ///< ṡ after the event [m/s].
  double impulse = 0.0;      ///< Impulse of an impact or lock [N·s]; 0 otherwise.
  double left_velocity_before = 0.0;   ///< u̇_L before [m/s].
  double right_velocity_before = 0.0;  ///< u̇_R before [m/s].
  double left_velocity_after = 0.0;    ///< u̇_L after [m/s].
  double right_velocity_after = 0.0;   ///< u̇_R after [m/s].
};

}  // namespace poundsim
