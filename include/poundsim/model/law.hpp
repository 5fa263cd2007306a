#pragma once
/// @file
/// Links and their laws. Every storey and every gap element is a one-dimensional link between two
/// floors a and b (b the ground for a first storey) whose force follows a law from a closed set.
///
/// Sign convention, for every law: the deformation is d = u_a − u_b [m] (u relative to the
/// ground, positive to the right), and the link exerts −F on floor a and +F on floor b [N]. A
/// storey runs from a floor to the floor below, so F > 0 is its shear resisting a drift to the
/// right; a gap element runs from the left floor to the right one, so F > 0 is compression.
///
/// A piecewise-linear law (traits.piecewise_linear) is linear in each of its modes,
/// F = k d + c ḋ + f₀ (LinearForm); the phase system (dynamics/linear_phase.hpp) and the exact
/// integrator are assembled from these forms. A mode may make the link rigid (a locked gap
/// element): d is then held constant and the floors move as one group.
///
/// Adding a law: its header and source in model/laws/, its test, and its name in the Law
/// variant below (docs/architecture.md).

#include <array>
#include <optional>
#include <span>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "poundsim/model/laws/linear_storey.hpp"
#include "poundsim/model/laws/paper_gap.hpp"

namespace poundsim {

/// The closed set of laws.
using Law = std::variant<LinearStorey, PaperGap>;

namespace detail {
template <class V>
struct ContactLawsOf;
template <class... L>
struct ContactLawsOf<std::variant<L...>> {
  template <class... Kept>
  static std::variant<Kept...> as_variant(std::tuple<Kept...>);
  using type = decltype(as_variant(
      std::tuple_cat(std::declval<std::conditional_t<ContactLaw<L>, std::tuple<L>, std::tuple<>>>()...)));
};
}  // namespace detail

/// The laws a gap element may carry: the contact laws of Law, in its order (so that adding a law
/// to Law is all it takes). The first is the default of a model file.
using GapLaw = detail::ContactLawsOf<Law>::type;

/// The file names of the gap-element laws (`law = "..."`), in GapLaw's order.
inline constexpr auto gap_law_names = []<class... L>(std::variant<L...>*) {
  return std::array<std::string_view, sizeof...(L)>{L::key...};
}(static_cast<GapLaw*>(nullptr));

/// The law named `key` with its parameters' defaults; nothing when no law has that name.
[[nodiscard]] inline std::optional<GapLaw> gap_law_named(std::string_view key) {
  std::optional<GapLaw> found;
  [&]<class... L>(std::variant<L...>*) {
    ((L::key == key ? (found.emplace(L{}), 0) : 0), ...);
  }(static_cast<GapLaw*>(nullptr));
  return found;
}

/// The file name of the law `law` carries.
[[nodiscard]] inline std::string_view key_of(const GapLaw& law) {
  return std::visit([](const auto& l) -> std::string_view { return l.key; }, law);
}

/// A link between two degrees of freedom (DofLayout numbering) carrying a law.
struct Link {
  int a = 0;        ///< DOF of floor a.
  int b = -1;       ///< DOF of floor b, or −1 for the ground.
  Law law;
  /// Which gap element of Model::gaps the link stands for, −1 for a storey: the simulator still
  /// keeps each gap element's mode and memory by this index.
  int element = -1;

  [[nodiscard]] const LawTraits& traits() const {
    return std::visit([](const auto& l) -> const LawTraits& { return l.traits; }, law);
  }
  /// F = k d + c ḋ + f₀ in `mode`; nothing when the link transmits no force in that mode.
  [[nodiscard]] std::optional<LinearForm> linear_form(LinkMode mode) const {
    return std::visit(
        [mode](const auto& l) -> std::optional<LinearForm> { return l.linear_form(mode); }, law);
  }
};

/// A link whose law is known at compile time: the entries of a LinkTable.
template <class L>
struct TypedLink {
  int a = 0;
  int b = -1;
  int element = -1;
  L law;
};

/// The links sorted by law, one array per law of the Law variant (in its order), each in link
/// order: loops over many links (energy, every step) call each law's functions directly, with no
/// dispatch per link.
class LinkTable {
 public:
  LinkTable() = default;
  explicit LinkTable(std::span<const Link> links) {
    for (const Link& link : links) {
      std::visit(
          [&](const auto& law) {
            using L = std::decay_t<decltype(law)>;
            std::get<std::vector<TypedLink<L>>>(tables_).push_back(
                {link.a, link.b, link.element, law});
          },
          link.law);
    }
  }
  /// Calls f(links) with the array of each law in turn (std::span<const TypedLink<L>>).
  template <class F>
  void for_each_law(F&& f) const {
    std::apply([&](const auto&... table) { (f(std::span(table)), ...); }, tables_);
  }

 private:
  template <class V>
  struct TablesOf;
  template <class... L>
  struct TablesOf<std::variant<L...>> {
    using type = std::tuple<std::vector<TypedLink<L>>...>;
  };
  TablesOf<Law>::type tables_;
};

}  // namespace poundsim
