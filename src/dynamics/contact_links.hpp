#pragma once
// The system's and the integrators' access to the contact laws of the gap elements' links (contact_law.hpp).

#include <stdexcept>
#include <type_traits>
#include <variant>

#include "poundsim/dynamics/state.hpp"
#include "poundsim/dynamics/system.hpp"
#include "poundsim/model/law.hpp"

namespace poundsim::detail {

/// Calls `f` with the contact law of `link` (links of gap elements carry one, contact_law.hpp).
template <class R, class F>
R with_contact_law(const Link& link, F&& f) {
  return std::visit<R>(
      [&](const auto& law) -> R {
        if constexpr (ContactLaw<std::decay_t<decltype(law)>>) {
          return f(law);
        } else {
          throw std::logic_error("a storey link has no contact law");
        }
      },
      link.law);
}

/// Calls `f` with the law of `link` when it has modes and events (EventLaw: contact laws and
/// yielding storeys); `otherwise()` for the others (a smooth storey law without events).
template <class R, class F, class G>
R with_event_law(const Link& link, F&& f, G&& otherwise) {
  return std::visit<R>(
      [&](const auto& law) -> R {
        if constexpr (EventLaw<std::decay_t<decltype(law)>>) {
          return f(law);
        } else {
          return otherwise();
        }
      },
      link.law);
}

/// Calls f(link) for every link of `table` whose law is a contact law, law by law: the loops
/// that run every step call the law directly, with no dispatch per link.
template <class F>
void for_each_contact_link(const LinkTable& table, F&& f) {
  table.for_each_law([&](auto links) {
    using L = std::decay_t<decltype(links.front().law)>;
    if constexpr (ContactLaw<L>) {
      for (const auto& link : links) f(link);
    }
  });
}

}  // namespace poundsim::detail

namespace poundsim::detail {

/// Calls f(link) for every link of `table` whose law has modes and events (EventLaw), law by law.
template <class F>
void for_each_event_link(const LinkTable& table, F&& f) {
  table.for_each_law([&](auto links) {
    using L = std::decay_t<decltype(links.front().law)>;
    if constexpr (EventLaw<L>) {
      for (const auto& link : links) f(link);
    }
  });
}

}  // namespace poundsim::detail
