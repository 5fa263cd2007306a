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

#include "poundsim/model/laws/bilinear_storey.hpp"
#include "poundsim/model/laws/bouc_wen.hpp"
#include "poundsim/model/laws/hertz.hpp"
#include "poundsim/model/laws/hertzdamp.hpp"
#include "poundsim/model/laws/impact.hpp"
#include "poundsim/model/laws/jankowski.hpp"
#include "poundsim/model/laws/kelvin_voigt.hpp"
#include "poundsim/model/laws/linear_storey.hpp"
#include "poundsim/model/laws/paper_gap.hpp"

namespace poundsim {

/// The closed set of laws.
using Law = std::variant<LinearStorey, PaperGap, KelvinVoigt, Hertz, Hertzdamp, Jankowski, BilinearStorey,
                         BoucWenStorey, Impact>;

/// A law whose force in some modes is a smooth function of the link's motion (not linear): it
/// gives the force with its consistent tangent, which Newmark's Newton iterations solve.
template <class L>
concept SmoothLaw = requires(const L& law, const LinkKinematics& k, LinkMode mode, const typename L::State& state) {
  { law.force_tangent(k, mode, state) } -> std::same_as<ForceTangent>;
  { L::carries_force(mode) } -> std::same_as<bool>;
};

/// A piecewise-linear law whose force at zero in a mode depends on its State (a plastic drift):
/// the phase's constant load follows the State (LinearPhase::set_law_states).
template <class L>
concept StateLoadedLaw = requires(const L& law, LinkMode mode, const typename L::State& state) {
  { law.state_force(mode, state) } -> std::same_as<double>;
};

/// A law that dissipates hysteretic energy: the plastic work between two states in one mode,
/// exact from the ends (the energy meter's H_storey for a storey, D_gap for a gap element,
/// dynamics/energy.hpp).
template <class L>
concept YieldingLaw = requires(const L& law, const LinkKinematics& k, LinkMode mode, const typename L::State& state) {
  { law.plastic_work(k, k, mode, state) } -> std::same_as<double>;
};

/// A law whose State follows the motion continuously (a Bouc–Wen storey's z): its force at a
/// trial state is a function of the committed State, and the loop commits the State at every
/// accepted state (OpenSees' trial/commit).
template <class L>
concept CommittingLaw = requires(const L& law, const LinkKinematics& k, LinkMode mode, typename L::State& state) {
  law.commit(k, mode, state);
};

/// A law whose links the system tracks (gives an index in the contact configuration): one with
/// modes and events, or one whose force is smooth. Storeys with such a law are tracked after the
/// gap elements.
template <class L>
concept TrackedLaw = EventLaw<L> || SmoothLaw<L>;

namespace detail {
/// std::variant<Wrap<L>...> of the laws L of the variant V for which Keep<L>::value, in V's order.
template <template <class> class Keep, template <class> class Wrap, class V>
struct LawsWhere;
template <template <class> class Keep, template <class> class Wrap, class... L>
struct LawsWhere<Keep, Wrap, std::variant<L...>> {
  template <class... Kept>
  static std::variant<Wrap<Kept>...> as_variant(std::tuple<Kept...>);
  using type = decltype(as_variant(
      std::tuple_cat(std::declval<std::conditional_t<Keep<L>::value, std::tuple<L>, std::tuple<>>>()...)));
};
template <class L>
struct IsContactLaw : std::bool_constant<ContactLaw<L>> {};
template <class L>
struct IsStoreyLaw : std::bool_constant<!ContactLaw<L>> {};
template <class L>
using Itself = L;
}  // namespace detail

/// The laws a gap element may carry: the contact laws of Law, in its order (so that adding a law
/// to Law is all it takes). The first is the default of a model file.
using GapLaw = detail::LawsWhere<detail::IsContactLaw, detail::Itself, Law>::type;

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

/// What a storey law declares to be chosen in a model file: its name, its parameters besides the
/// frame's K_i and C_i (declared fields, numbers given per storey), and how it is made from them.
template <class L>
concept StoreyLawModel = !ContactLaw<L> && requires(const typename L::Parameters& p) {
  { L::key } -> std::convertible_to<std::string_view>;
  { L::make(1.0, 0.0, p) } -> std::same_as<L>;
  { p.rule_violation() } -> std::same_as<std::optional<FieldRule>>;
};

/// A storey law L with the parameters of each storey, bottom up; none gives every storey the
/// default parameters.
template <class L>
struct PerStorey {
  static_assert(StoreyLawModel<L>, "a storey law declares key, Parameters, make()");
  using Law = L;
  std::vector<typename L::Parameters> values;
  [[nodiscard]] bool operator==(const PerStorey&) const = default;
};

/// A frame's storey law and its storeys' parameters: one alternative per storey law of Law (the
/// laws that are not contact laws, in its order; the first, the linear storey, is the default).
using StoreyLawParameters = detail::LawsWhere<detail::IsStoreyLaw, PerStorey, Law>::type;

/// The file names of the storey laws (`storey_law = "..."`), in StoreyLawParameters' order.
inline constexpr auto storey_law_names = []<class... P>(std::variant<P...>*) {
  return std::array<std::string_view, sizeof...(P)>{P::Law::key...};
}(static_cast<StoreyLawParameters*>(nullptr));

/// The storey law named `key`, with no parameters yet; nothing when no storey law has that name.
[[nodiscard]] inline std::optional<StoreyLawParameters> storey_law_named(std::string_view key) {
  std::optional<StoreyLawParameters> found;
  [&]<class... P>(std::variant<P...>*) {
    ((P::Law::key == key ? (found.emplace(P{}), 0) : 0), ...);
  }(static_cast<StoreyLawParameters*>(nullptr));
  return found;
}

/// Calls f(field, values) for each declared parameter of a frame's storey law (fields.hpp), with
/// its value at every storey, bottom up (none when the frame takes the law's defaults).
template <class F>
void for_each_storey_parameter(const StoreyLawParameters& law, F&& f) {
  std::visit(
      [&](const auto& per_storey) {
        using Parameters = typename std::decay_t<decltype(per_storey)>::Law::Parameters;
        for_each_field<Parameters>([&](const auto& field) {
          std::vector<double> values;
          values.reserve(per_storey.values.size());
          for (const Parameters& p : per_storey.values) values.push_back(p.*field.member);
          f(field, values);
        });
      },
      law);
}

/// The file name of a frame's storey law.
[[nodiscard]] inline std::string_view key_of(const StoreyLawParameters& law) {
  return std::visit([](const auto& p) -> std::string_view { return std::decay_t<decltype(p)>::Law::key; }, law);
}

/// Whether a gap element's or a frame's law is the one a model file has when it names none (the
/// first of its set): the writers (input.toml, summary.json, a study's fingerprint) name only
/// the others.
[[nodiscard]] inline bool is_default(const GapLaw& law) { return law.index() == 0; }
[[nodiscard]] inline bool is_default(const StoreyLawParameters& law) { return law.index() == 0; }

class LinkStates;

/// Where an end of a link meets its frame when that is not at a floor: a point of the column
/// between the end's floor and the floor below, struck by a neighbour's slab (Karayannis &
/// Favvata 2005, "Earthquake-induced interaction between adjacent reinforced concrete structures
/// with non-equal heights"). A shear frame's storey deforms linearly over its height, so the
/// point moves as u = w u_floor + (1 − w) u_below, and a force F there acts as w F on the floor
/// and (1 − w) F on the floor below (virtual work: the same weights, so that the link's power is
/// F times the point's velocity and momentum and energy stay exact). docs/model.md#slab-to-column.
struct ColumnPoint {
  int below = -1;       ///< DOF of the floor below the point, or −1 for the ground.
  double weight = 1.0;  ///< w of the end's own floor, in (0, 1]; 1: the end is at that floor.
  [[nodiscard]] bool at_floor() const { return weight == 1.0; }
  [[nodiscard]] bool operator==(const ColumnPoint&) const = default;
};

/// One term of a link's deformation d = Σ coefficient·u_dof (the ground omitted).
struct DofTerm {
  int dof = 0;
  double coefficient = 0.0;
};

/// A link's deformation as a combination of floor displacements: u_a − u_b for a link between
/// floors (u_a for a first storey), with the weights of a column point at either end
/// (ColumnPoint). Assembly (K += k n nᵀ, loads −f₀ n), the energy's quadratic forms and the exact
/// integrator's guard rows read it; for a link between floors its terms are (a, 1), (b, −1) so
/// that they add exactly what a two-node element adds.
struct LinkDofs {
  std::array<DofTerm, 4> term{};
  int size = 0;
  [[nodiscard]] std::span<const DofTerm> terms() const& { return std::span(term).first(static_cast<std::size_t>(size)); }
  /// Not of a temporary: `for (t : link_dofs(link).terms())` would read a destroyed array.
  std::span<const DofTerm> terms() const&& = delete;
};

/// The terms of a link's deformation, in the order a, the point below a, b, the point below b.
template <class LinkLike>
[[nodiscard]] LinkDofs link_dofs(const LinkLike& link) {
  LinkDofs d;
  const auto add = [&](int dof, double coefficient) {
    if (dof >= 0 && coefficient != 0.0) d.term[static_cast<std::size_t>(d.size++)] = {dof, coefficient};
  };
  add(link.a, link.a_column.weight);
  if (!link.a_column.at_floor()) add(link.a_column.below, 1.0 - link.a_column.weight);
  add(link.b, -link.b_column.weight);
  if (!link.b_column.at_floor()) add(link.b_column.below, -(1.0 - link.b_column.weight));
  return d;
}

/// A link between two degrees of freedom (DofLayout numbering) carrying a law.
struct Link {
  int a = 0;        ///< DOF of floor a.
  int b = -1;       ///< DOF of floor b, or −1 for the ground.
  Law law;
  /// The link's index in the contact configuration, where the system's ContactState keeps its
  /// mode: gap element p of Model::gaps is p; a storey whose law is tracked (TrackedLaw: a
  /// yielding storey) follows them, in DOF order; −1 for a storey with one mode and no events.
  int element = -1;
  /// Its index among the links of its law (make_links numbers them): LinkStates keeps its
  /// law's State by this index.
  int slot = 0;
  /// A gap element's end at a column point rather than at its floor (a slab striking the
  /// neighbour's column): a and b are then the floors above those points.
  ColumnPoint a_column{}, b_column{};
  /// Both ends at floors: d = u_a − u_b.
  [[nodiscard]] bool joins_floors() const { return a_column.at_floor() && b_column.at_floor(); }

  [[nodiscard]] const LawTraits& traits() const {
    return std::visit([](const auto& l) -> const LawTraits& { return l.traits; }, law);
  }
  /// F = k d + c ḋ + f₀ in `mode`; nothing when the link transmits no force in that mode, or
  /// a force that is not linear (smooth_in).
  [[nodiscard]] std::optional<LinearForm> linear_form(LinkMode mode) const {
    return std::visit(
        [mode](const auto& l) -> std::optional<LinearForm> { return l.linear_form(mode); }, law);
  }
  /// The part of f₀ the law's State sets in `mode` (StateLoadedLaw), 0 for other laws [N].
  [[nodiscard]] double state_force(LinkMode mode, const LinkStates& states) const;
  /// Whether the link's force in `mode` is a smooth law's (SmoothLaw): solved by Newton.
  [[nodiscard]] bool smooth_in(LinkMode mode) const {
    return std::visit(
        [mode](const auto& l) {
          if constexpr (SmoothLaw<std::decay_t<decltype(l)>>) {
            return l.carries_force(mode);
          } else {
            return false;
          }
        },
        law);
  }
};

/// A link whose law is known at compile time: the entries of a LinkTable. Whether an end may be
/// a column point is known too (AtColumn): the links between floors, all but a few slabs that
/// strike columns, then read their floors with no test on the loops of every step.
/// The end of a link that is its floor, as a ColumnPoint of weight 1 that takes no room.
struct FloorEnd {
  static constexpr int below = -1;
  static constexpr double weight = 1.0;
  [[nodiscard]] static constexpr bool at_floor() { return true; }
};

template <class L, bool AtColumn = false>
struct TypedLink {
  using End = std::conditional_t<AtColumn, ColumnPoint, FloorEnd>;
  int a = 0;
  int b = -1;
  int element = -1;
  int slot = 0;
  L law;
  [[no_unique_address]] End a_column{};
  [[no_unique_address]] End b_column{};
  [[nodiscard]] constexpr bool joins_floors() const { return a_column.at_floor() && b_column.at_floor(); }
};

namespace detail {
/// The index of the law L in the Law variant.
template <class L, class V = Law>
struct LawIndex;
template <class L, class... Ls>
struct LawIndex<L, std::variant<Ls...>> {
  static constexpr std::size_t value = [] {
    constexpr std::array<bool, sizeof...(Ls)> same{std::is_same_v<L, Ls>...};
    std::size_t i = 0;
    while (!same[i]) ++i;
    return i;
  }();
};
}  // namespace detail

/// The links sorted by law, one array per law of the Law variant (in its order), each in link
/// order, and then one per law for the links with a column point: loops over many links (energy,
/// every step) call each law's functions directly, with no dispatch per link.
class LinkTable {
 public:
  LinkTable() = default;
  explicit LinkTable(std::span<const Link> links) {
    for (const Link& link : links) {
      std::visit(
          [&](const auto& law) {
            using L = std::decay_t<decltype(law)>;
            if (link.joins_floors()) {
              std::get<std::vector<TypedLink<L>>>(tables_).push_back(
                  {.a = link.a, .b = link.b, .element = link.element, .slot = link.slot, .law = law});
            } else {
              std::get<std::vector<TypedLink<L, true>>>(column_tables_).push_back(
                  {link.a, link.b, link.element, link.slot, law, link.a_column, link.b_column});
              any_column_ = true;
            }
          },
          link.law);
    }
  }
  /// Calls f(links) with the array of each law in turn (std::span<const TypedLink<L>>), then
  /// with those of the links at column points (std::span<const TypedLink<L, true>>).
  template <class F>
  void for_each_law(F&& f) const {
    std::apply([&](const auto&... table) { (f(std::span(table)), ...); }, tables_);
    // Column links are rare: without them the loops of every step pay one test.
    if (any_column_) std::apply([&](const auto&... table) { (f(std::span(table)), ...); }, column_tables_);
  }

 private:
  template <class V, bool AtColumn>
  struct TablesOf;
  template <class... L, bool AtColumn>
  struct TablesOf<std::variant<L...>, AtColumn> {
    using type = std::tuple<std::vector<TypedLink<L, AtColumn>>...>;
  };
  TablesOf<Law, false>::type tables_;
  TablesOf<Law, true>::type column_tables_;
  bool any_column_ = false;
};

/// The State of every link's law (law_traits.hpp's LawState), one array per law of Law, indexed
/// by the link's slot: what the laws keep between events, committed at each event. The loop
/// owns it (ContactState); the laws read it and their events change it.
class LinkStates {
 public:
  LinkStates() = default;
  /// Every link's law in its initial state.
  explicit LinkStates(std::span<const Link> links) {
    for (const Link& link : links) {
      std::visit([&](const auto& law) { of(law).emplace_back(); }, link.law);
    }
  }
  /// The states of the links of law L, by slot.
  template <class L>
  [[nodiscard]] std::vector<typename L::State>& of(const L& /*law*/) {
    return std::get<detail::LawIndex<L>::value>(states_);
  }
  template <class L>
  [[nodiscard]] const std::vector<typename L::State>& of(const L& /*law*/) const {
    return std::get<detail::LawIndex<L>::value>(states_);
  }
  /// The state of a link whose law is L.
  template <class L>
  [[nodiscard]] typename L::State& at(const L& law, int slot) {
    return of(law)[static_cast<std::size_t>(slot)];
  }
  template <class L>
  [[nodiscard]] const typename L::State& at(const L& law, int slot) const {
    return of(law)[static_cast<std::size_t>(slot)];
  }
  template <class L, bool AtColumn>
  [[nodiscard]] const typename L::State& at(const TypedLink<L, AtColumn>& link) const {
    return at(link.law, link.slot);
  }
  /// The clock restarts at `origin`: every time kept becomes relative to it.
  void shift_clock(double origin) {
    std::apply([&](auto&... arrays) { (shift(arrays, origin), ...); }, states_);
  }
  [[nodiscard]] bool operator==(const LinkStates&) const = default;

 private:
  template <class S>
  static void shift(std::vector<S>& states, double origin) {
    for (S& s : states) s.shift_clock(origin);
  }
  template <class V>
  struct StatesOf;
  template <class... L>
  struct StatesOf<std::variant<L...>> {
    static_assert((LawState<typename L::State> && ...), "every law declares its State (law_traits.hpp)");
    using type = std::tuple<std::vector<typename L::State>...>;
  };
  StatesOf<Law>::type states_;
};

inline double Link::state_force(LinkMode mode, const LinkStates& states) const {
  return std::visit(
      [&](const auto& l) {
        if constexpr (StateLoadedLaw<std::decay_t<decltype(l)>>) {
          return l.state_force(mode, states.at(l, slot));
        } else {
          return 0.0;
        }
      },
      law);
}

}  // namespace poundsim
