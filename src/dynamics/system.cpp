#include "poundsim/dynamics/system.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "contact_links.hpp"
#include "poundsim/model/impact.hpp"

namespace poundsim {

using detail::for_each_contact_link;
using detail::for_each_event_link;
using detail::kinematics;
using detail::with_contact_law;
using detail::with_event_law;

namespace {

/// The closing speed u̇_L − u̇_R of a pair counts only above this fraction of |u̇_L| + |u̇_R|: below
/// it, it is the round-off of equal velocities computed apart, or the remainder of the
/// sequential restitution of a chain, which stops there. One threshold for both, so that what
/// one impact resolution leaves behind never fires another.
constexpr double kClosingTolerance = 1e-12;

[[nodiscard]] bool closes(double v_left, double v_right) {
  return v_left - v_right > kClosingTolerance * (std::abs(v_left) + std::abs(v_right));
}

}  // namespace

PoundingSystem::PoundingSystem(Model model, Excitation excitation, EventRules rules)
    : model_(std::move(model)),
      layout_(model_),
      excitation_(std::move(excitation)),
      rules_(rules),
      links_(make_links(model_, layout_)),
      gaps_(model_.gap_count()) {
  for (const Link& link : links_) {
    if (link.element < 0) continue;
    const auto p = static_cast<std::size_t>(link.element);
    if (tracked_links_.size() <= p) tracked_links_.resize(p + 1);
    tracked_links_[p] = link;
  }
  contact_table_ = LinkTable(contact_links());
  tracked_table_ = LinkTable(tracked_links_);
  tracked_table_.for_each_law([&](auto links) {
    if constexpr (CommittingLaw<std::decay_t<decltype(links.front().law)>>) {
      has_committing_laws_ = has_committing_laws_ || !links.empty();
    }
  });
  mass_.resize(layout_.size());
  for (int i = 0; i < layout_.size(); ++i) {
    mass_(i) = model_.frames[static_cast<std::size_t>(layout_.frame_of(i))].mass[static_cast<std::size_t>(layout_.floor_of(i))];
  }
}

double PoundingSystem::kinetic_energy(const Eigen::VectorXd& v) const { return 0.5 * v.cwiseAbs2().dot(mass_); }

ContactState PoundingSystem::initial_contact(const KinematicState& x) const {
  const std::size_t ng = tracked_links_.size();
  ContactState c;
  c.config.assign(ng, LinkMode{0});
  for (std::size_t p = 0; p < ng; ++p) {
    const Link& link = tracked_links_[p];
    const LinkKinematics k = kinematics(x, link);
    const double d = k.ua - k.ub;
    try {
      c.config[p] = with_event_law<LinkMode>(
          link, [&](const auto& law) { return law.initial_mode(d); }, [] { return LinkMode{0}; });
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(
          fmt::format("initial displacements compress {} {}", describe(link, layout_), e.what()));
    }
  }
  c.states = LinkStates(links_);
  c.bias.assign(ng, 0.0);
  c.link_length.assign(ng, 0.0);
  c.transmits.assign(ng, 0);
  c.rigid.assign(ng, 0);
  c.stop_reaction.assign(ng, 0.0);
  c.stop_noise.assign(ng, 0.0);
  c.link_in.assign(static_cast<std::size_t>(layout_.size()), 0.0);
  c.impacts.reserve(ng);
  c.smooth.assign(ng, ForceTangent{});
  return c;
}

void PoundingSystem::refresh_flags(ContactState& c, std::size_t p) const {
  // What the element's law does in its mode, asked when the mode changes rather than per step.
  const std::optional<LinearForm> form = tracked_links_[p].linear_form(c.config[p]);
  c.transmits[p] = form.has_value() || tracked_links_[p].smooth_in(c.config[p]);
  c.rigid[p] = form && form->rigid;
}

void PoundingSystem::refresh_flags(ContactState& c) const {
  for (std::size_t p = 0; p < c.config.size(); ++p) refresh_flags(c, p);
}

LinearPhase& PoundingSystem::activate(ContactState& c, EventHandler& handler) const {
  LinearPhase& phase = handler.activate(c);
  refresh_flags(c);
  return phase;
}

void PoundingSystem::equilibrate(LinearPhase& phase, KinematicState& x, ContactState& c) const {
  if (phase.has_smooth_links()) smooth_forces(x, c, c.smooth);
  phase.equilibrate(ground_acceleration(x.t), x, c.smooth);
}

std::optional<LinearForm> PoundingSystem::linear_form(const Link& link, const ContactState& c) const {
  const LinkMode mode = mode_of(link, c.config);
  std::optional<LinearForm> form = link.linear_form(mode);
  if (form) form->force_at_zero += link.state_force(mode, c.states);
  return form;
}

void PoundingSystem::smooth_forces(const KinematicState& x, const ContactState& c,
                                   std::span<ForceTangent> by_element) const {
  tracked_table_.for_each_law([&](auto links) {
    using L = typename std::decay_t<decltype(links)>::value_type;
    if constexpr (SmoothLaw<decltype(L::law)>) {
      for (const auto& link : links) {
        const auto p = static_cast<std::size_t>(link.element);
        by_element[p] = link.law.force_tangent(kinematics(x, link), c.config[p], c.states.at(link));
      }
    }
  });
}

void PoundingSystem::commit_states(const KinematicState& x, ContactState& c) const {
  tracked_table_.for_each_law([&](auto links) {
    if constexpr (CommittingLaw<std::decay_t<decltype(links.front().law)>>) {
      for (const auto& link : links) {
        link.law.commit(kinematics(x, link), c.config[static_cast<std::size_t>(link.element)],
                        c.states.at(link.law, link.slot));
      }
    }
  });
}

double PoundingSystem::shortening(const KinematicState& x, int p) const {
  const Link& link = tracked_links_[static_cast<std::size_t>(p)];
  const LinkKinematics k = kinematics(x, link);
  return with_contact_law<double>(link, [&](const auto& law) { return law.shortening(k); });
}

double PoundingSystem::gap_force(const KinematicState& x, const ContactState& c, int p) const {
  const Link& link = tracked_links_[static_cast<std::size_t>(p)];
  return with_contact_law<double>(link, [&](const auto& law) {
    using L = std::decay_t<decltype(law)>;
    return gap_force(x, c, TypedLink<L, true>{.a = link.a, .b = link.b, .element = link.element, .slot = link.slot,
                                              .law = law, .a_column = link.a_column, .b_column = link.b_column});
  });
}

namespace {
/// λ of the locked links, called out of line: evaluate_guards inlines everything else it calls.
[[gnu::noinline]] void stop_reactions(const PoundingSystem& system, const KinematicState& x, const LinearPhase& phase,
                                      ContactState& c) {
  system.compute_stop_reactions(x, phase, c);
}
}  // namespace

// Flattened: this runs at every step and at every trial of event location, and each law's
// guards() then computes its values in registers instead of a GuardValue array in memory.
[[gnu::flatten]] void PoundingSystem::evaluate_guards(const KinematicState& x, const LinearPhase& phase,
                                                      ContactState& c, std::span<double> g,
                                                      std::span<double> dg) const {
  // Each guard is its value minus its round-off level (the law's): a guard within a few ulps of
  // zero is zero, and zero does not fire.
  if (!phase.is_unreduced()) stop_reactions(*this, x, phase, c);  // only locked links have a λ
  std::array<GuardValue, 2> values;
  for_each_event_link(tracked_table_, [&](const auto& link) {
    const auto p = static_cast<std::size_t>(link.element);
    const GuardContext context{.separation = rules_.separation,
                               .reaction = c.stop_reaction[p],
                               .reaction_noise = c.stop_noise[p]};
    link.law.guards(kinematics(x, link), c.config[p], c.states.at(link), context, values);
    for (std::size_t i = 0; i < values.size(); ++i) guard_entry(values[i], c.bias[p], g[2 * p + i], dg[2 * p + i]);
  });
}

void PoundingSystem::compute_stop_reactions(const KinematicState& x, const LinearPhase& phase,
                                            ContactState& c) const {
  // The force on a floor that the links must supply: f = f_S − m a_g − C u̇ − K u − m ü. Sweeping
  // each chain of locked elements from the left gives λ_out = f + λ_in.
  constexpr double kNoise = 8 * std::numeric_limits<double>::epsilon();
  if (phase.is_unreduced()) return;  // nothing locked
  const double ground = x.ground;
  const Eigen::VectorXd& m = phase.full_mass();
  const LinearPhase::SparseMatrix& cm = phase.full_damping();
  const LinearPhase::SparseMatrix& k = phase.full_stiffness();
  // A smooth law's force on a floor of the chain is a load like f_S: −F n (−F on its floor a, +F
  // on b).
  if (phase.has_smooth_links()) smooth_forces(x, c, c.smooth);
  const auto smooth_load = [&](int floor) {
    double load = 0.0;
    for (const LinearPhase::SmoothLink& link : phase.smooth_links()) {
      const double force = c.smooth[static_cast<std::size_t>(link.element)].force;
      for (const DofTerm& t : link.dofs.terms()) {
        if (t.dof == floor) load -= t.coefficient * force;
      }
    }
    return load;
  };
  for (std::size_t p = 0; p < c.config.size(); ++p) {
    if (c.rigid[p] == 0) continue;
    const int l = tracked_links_[p].a;
    const double load = phase.full_constant_load()(l) + smooth_load(l);
    double f = load - m(l) * (ground + x.a(l));
    double magnitude = std::abs(load) + m(l) * (std::abs(ground) + std::abs(x.a(l)));
    for (LinearPhase::SparseMatrix::InnerIterator it(cm, l); it; ++it) {  // symmetric: column = row
      f -= it.value() * x.v(it.row());
      magnitude += std::abs(it.value() * x.v(it.row()));
    }
    for (LinearPhase::SparseMatrix::InnerIterator it(k, l); it; ++it) {
      f -= it.value() * x.u(it.row());
      magnitude += std::abs(it.value() * x.u(it.row()));
    }
    c.stop_reaction[p] = f + c.link_in[l];
    c.stop_noise[p] = kNoise * (magnitude + std::abs(c.link_in[l]));
    c.link_in[tracked_links_[p].b] = c.stop_reaction[p];
  }
  for (std::size_t p = 0; p < c.config.size(); ++p) {
    if (c.rigid[p] != 0) c.link_in[tracked_links_[p].b] = 0.0;
  }
}

LinearPhase& PoundingSystem::apply_events(std::span<const double> fired, KinematicState& x, ContactState& c,
                                          LinearPhase& current, std::span<double> g, std::span<double> dg,
                                          EventHandler& handler) const {
  static_cast<void>(current);  // replaced: every call activates the phase of the new modes
  c.impacts.clear();
  for (std::size_t j = 0; j < fired.size(); ++j) {
    if (!(fired[j] > 0)) continue;
    const std::size_t p = j / 2;
    const int pi = static_cast<int>(p);
    const Link& link = tracked_links_[p];
    const LinkKinematics k = kinematics(x, link);
    const double vl = k.va, vr = k.vb;
    LinkMode m = c.config[p];
    const Transition transition = with_event_law<Transition>(
        link,
        [&](const auto& law) {
          return law.on_guard(static_cast<int>(j % 2), k, m, c.states.at(law, link.slot), rules_.separation);
        },
        []() -> Transition { throw std::logic_error("a guard fired on a link without events"); });
    c.config[p] = m;
    refresh_flags(c, p);  // the event handler below may ask for the element's force
    switch (transition) {
      case Transition::impact: c.impacts.push_back(pi); break;
      case Transition::contact:
        c.bias[p] = 0.0;
        handler.on_event(x, pi, EventKind::contact, vl, vr, 0.0);
        break;
      case Transition::separation:
        c.bias[p] = 0.0;
        handler.on_event(x, pi, EventKind::separation, vl, vr, 0.0);
        break;
      case Transition::unlock:
        c.bias[p] = 0.0;
        handler.on_event(x, pi, EventKind::unlock, vl, vr, 0.0);
        break;
      case Transition::yield: handler.on_event(x, pi, EventKind::yield, vl, vr, 0.0); break;
      case Transition::unload: handler.on_event(x, pi, EventKind::unload, vl, vr, 0.0); break;
    }
  }
  LinearPhase* phase = &activate(c, handler);
  if (!c.impacts.empty()) phase = &resolve_impacts(x, c, *phase, handler);
  equilibrate(*phase, x, c);
  evaluate_guards(x, *phase, c, g, dg);
  set_impact_biases(x, c, g);
  return *phase;
}

double PoundingSystem::stop_guard(const KinematicState& x, const ContactState& c, std::size_t p) const {
  const Link& link = tracked_links_[p];
  const LinkKinematics k = kinematics(x, link);
  const double distance = with_contact_law<double>(
      link, [&](const auto& law) { return law.stop_distance(k, c.config[p], c.states.at(law, link.slot)); });
  return distance - c.bias[p];
}

bool PoundingSystem::stop_guard_is_active(const ContactState& c, std::size_t p) const {
  return with_contact_law<bool>(tracked_links_[p], [&](const auto& law) {
    return law.traits.has_stop && law.stop_guard_is_active(c.config[p]);
  });
}

/// What resolve_impacts tracks over its rounds at one instant: each gap element's velocities
/// before, whether it takes part and the impulse it has taken, and the locks it made.
struct PoundingSystem::ImpactScratch {
  struct Lock {
    int element;
    double left_before, right_before, impulse;
  };
  std::span<const Link> gap_links;
  std::vector<double> left_before, right_before, impulse;
  std::vector<char> involved;
  std::vector<Lock> locks;
  int sweeps = 0, max_sweeps = 0;

  /// The speed at which element p closes (0 when it opens).
  [[nodiscard]] double closing_speed(const Eigen::VectorXd& v, std::size_t p) const {
    const double vl = v(gap_links[p].a), vr = v(gap_links[p].b);
    return closes(vl, vr) ? vl - vr : 0.0;
  }
  /// Whether element p shares a body (a floor's group) with an involved element.
  [[nodiscard]] bool shares_a_body(std::span<const int> group, std::size_t p) const {
    const int gl = group[static_cast<std::size_t>(gap_links[p].a)];
    const int gr = group[static_cast<std::size_t>(gap_links[p].b)];
    for (std::size_t q = 0; q < involved.size(); ++q) {
      if (!involved[q]) continue;
      const int ql = group[static_cast<std::size_t>(gap_links[q].a)];
      const int qr = group[static_cast<std::size_t>(gap_links[q].b)];
      if (gl == ql || gl == qr || gr == ql || gr == qr) return true;
    }
    return false;
  }
};

void PoundingSystem::restitution_sweeps(ImpactScratch& s, Eigen::VectorXd& v, const ContactState& c,
                                        const LinearPhase& phase, EventHandler& handler) const {
  const auto group = phase.group_of();
  const Eigen::VectorXd& group_mass = phase.mass();
  const std::size_t elements = s.involved.size();
  for (; s.sweeps < s.max_sweeps; ++s.sweeps) {
    std::size_t worst = elements;
    double closing = 0.0;
    for (std::size_t p = 0; p < elements; ++p) {
      if (!s.involved[p] || c.rigid[p] != 0) continue;
      const double w = s.closing_speed(v, p);
      if (w > closing) {
        closing = w;
        worst = p;
      }
    }
    if (worst == elements) break;
    const int l = s.gap_links[worst].a, r = s.gap_links[worst].b;
    const int gl = group[static_cast<std::size_t>(l)];
    const int gr = group[static_cast<std::size_t>(r)];
    const double rest = rules_.rest_velocity_ratio * (std::abs(v(l)) + std::abs(v(r)));
    const double restitution =
        closing <= rest ? 0.0
                        : with_contact_law<double>(s.gap_links[worst], [](const auto& law) {
                            return law.restitution();
                          });
    const ImpactOutcome o = restitution_impact(group_mass(gl), group_mass(gr), v(l), v(r), restitution);
    if (o.impulse > 0) handler.on_pair_impact(group, l, r, group_mass(gl), group_mass(gr), restitution);
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      const int gi = group[static_cast<std::size_t>(i)];
      if (gi == gl) v(i) = o.v_left;
      if (gi == gr) v(i) = o.v_right;
    }
    s.impulse[worst] += o.impulse;
  }
}

bool PoundingSystem::join_pairs_at_stops(ImpactScratch& s, const KinematicState& x, const ContactState& c,
                                         std::span<const int> group) const {
  bool joined = false;
  for (std::size_t p = 0; p < s.involved.size(); ++p) {
    if (s.involved[p]) continue;
    if (!stop_guard_is_active(c, p)) continue;
    const double w = s.closing_speed(x.v, p);
    if (!(w > 0) || !s.shares_a_body(group, p)) continue;
    const LinkKinematics k = kinematics(x, s.gap_links[p]);
    const double s_noise =
        with_contact_law<double>(s.gap_links[p], [&](const auto& law) { return law.position_noise(k); });
    if (stop_guard(x, c, p) < -(w * rules_.event_tolerance + s_noise)) continue;
    s.involved[p] = 1;
    joined = true;
  }
  return joined;
}

std::vector<int> PoundingSystem::pairs_to_lock(ImpactScratch& s, const KinematicState& x, const ContactState& c,
                                               const LinearPhase& phase) const {
  const auto group = phase.group_of();
  const Eigen::VectorXd& group_mass = phase.mass();
  const Eigen::VectorXd& v = x.v;
  std::vector<int> locking;
  for (std::size_t p = 0; p < s.involved.size(); ++p) {
    if (!s.involved[p] || c.rigid[p] != 0) continue;
    const int l = s.gap_links[p].a, r = s.gap_links[p].b;
    const int gl = group[static_cast<std::size_t>(l)], gr = group[static_cast<std::size_t>(r)];
    if (gl == gr) continue;  // already held together through other locked links
    const double pressing = x.a(l) - x.a(r);
    const double opening = -(v(l) - v(r));
    if (pressing > 0 && 2.0 * opening <= pressing * rules_.lock_time) {
      locking.push_back(static_cast<int>(p));
      const double ml = group_mass(gl), mr = group_mass(gr);
      s.locks.push_back({static_cast<int>(p), v(l), v(r), std::abs(v(l) - v(r)) * ml * mr / (ml + mr)});
    }
  }
  return locking;
}

LinearPhase& PoundingSystem::lock_and_merge(std::span<const int> locking, KinematicState& x, ContactState& c,
                                            EventHandler& handler) const {
  const std::span<const Link> gap_links = contact_links();
  for (const int p : locking) {
    const auto e = static_cast<std::size_t>(p);
    c.config[e] = with_contact_law<LinkMode>(gap_links[e], [](const auto& law) { return law.locked_mode(); });
    // The link keeps the floors where they are (on the stop, to the event tolerance).
    c.link_length[e] = x.u(gap_links[e].a) - x.u(gap_links[e].b);
  }
  LinearPhase& phase = activate(c, handler);
  // Plastic merge: each new group moves with the velocity of its centre of mass.
  const auto new_group = phase.group_of();
  const Eigen::VectorXd& m = phase.full_mass();
  Eigen::VectorXd momentum = Eigen::VectorXd::Zero(phase.reduced_size());
  for (Eigen::Index i = 0; i < x.v.size(); ++i) {
    momentum(new_group[static_cast<std::size_t>(i)]) += m(i) * x.v(i);
  }
  const Eigen::VectorXd group_v = momentum.cwiseQuotient(phase.mass());
  phase.scatter(group_v, x.v, false);
  handler.on_merge(new_group, m, phase.mass());
  return phase;
}

LinearPhase& PoundingSystem::resolve_impacts(KinematicState& x, ContactState& c, LinearPhase& current,
                                             EventHandler& handler) const {
  LinearPhase* phase = &current;
  const double kinetic_before = kinetic_energy(x.v);
  // Impacts are between gap elements only: the tracked storeys follow them in c.
  const auto elements = static_cast<std::size_t>(gaps_);
  ImpactScratch s{.gap_links = contact_links(),
                  .left_before = std::vector<double>(elements),
                  .right_before = std::vector<double>(elements),
                  .impulse = std::vector<double>(elements, 0.0),
                  .involved = std::vector<char>(elements, 0),
                  .locks = {},
                  .sweeps = 0,
                  .max_sweeps = 10000 * static_cast<int>(elements)};
  for (std::size_t p = 0; p < elements; ++p) {
    s.left_before[p] = x.v(s.gap_links[p].a);
    s.right_before[p] = x.v(s.gap_links[p].b);
  }
  for (const int p : c.impacts) s.involved[static_cast<std::size_t>(p)] = 1;
  // Rounds at one instant, until nothing changes:
  // 1. Sequential pairwise restitution until no involved pair approaches: exact for independent
  //    pairs, the Newton's-cradle answer for a chain of frames that share a floor. Floors held
  //    together by locked elements collide as one body (their group). A pair that sits at its
  //    stop — within the distance it closes in one event tolerance — and is driven into it by
  //    these impulses joins in: its collision would follow within the tolerance, and resolving a
  //    chain one located event at a time is an endless ping-pong of a light floor squeezed
  //    between heavy ones (e → 0) that only the limit of this loop settles.
  // 2. Lock the involved pairs that are pressed together and would only bounce for less than
  //    lock_time. Their plastic merge changes the velocities of the others, which may close
  //    again: back to 1.
  for (;;) {
    do {
      restitution_sweeps(s, x.v, c, *phase, handler);
    } while (join_pairs_at_stops(s, x, c, phase->group_of()));
    equilibrate(*phase, x, c);
    const std::vector<int> locking = pairs_to_lock(s, x, c, *phase);
    if (locking.empty()) break;
    phase = &lock_and_merge(locking, x, c, handler);
  }
  handler.on_impact_loss(kinetic_before - kinetic_energy(x.v));
  for (std::size_t p = 0; p < elements; ++p) {
    // A pair whose guard fired without closing (a touch at equal speeds) took no impulse: it is no
    // impact, though it may have locked.
    if (s.involved[p] && s.impulse[p] > 0) {
      handler.on_event(x, static_cast<int>(p), EventKind::impact, s.left_before[p], s.right_before[p], s.impulse[p]);
    }
  }
  for (const ImpactScratch::Lock& lock : s.locks) {
    handler.on_event(x, lock.element, EventKind::lock, lock.left_before, lock.right_before, lock.impulse);
  }
  return *phase;
}

void PoundingSystem::set_impact_biases(const KinematicState& x, ContactState& c, std::span<double> g) const {
  // At an impact the state is taken at the upper end of the event bracket, a hair past the stop
  // (by at most |ṡ| × tolerance). The element now moves away from the stop; offset its guard by
  // that hair so that the next impact is detected when the stop is reached again.
  for (std::size_t p = 0; p < static_cast<std::size_t>(gaps_); ++p) {
    const std::size_t j = 2 * p;
    if (!stop_guard_is_active(c, p) || !(g[j] > 0)) continue;
    // Still closing: a genuine impact, applied by the caller.
    if (closes(x.v(tracked_links_[p].a), x.v(tracked_links_[p].b))) continue;
    c.bias[p] += g[j];
    g[j] = 0.0;
  }
}

}  // namespace poundsim
