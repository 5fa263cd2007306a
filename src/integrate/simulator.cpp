#include "poundsim/integrate/simulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "contact_links.hpp"
#include "hermite_cubic.hpp"
#include "steppers.hpp"
#include "poundsim/error.hpp"
#include "poundsim/model/impact.hpp"

namespace poundsim {

using detail::for_each_contact_link;
using detail::kinematics;
using detail::with_contact_law;

namespace {

/// The linear form of each frame's first storey (its law's, on the ground): V = k u₁ is its
/// spring force, k u₁ + c u̇₁ its whole force.
std::vector<LinearForm> first_storey_forms(const Model& model, const DofLayout& layout) {
  std::vector<LinearForm> forms(static_cast<std::size_t>(model.frame_count()));
  for (const Link& link : make_links(model, layout)) {
    if (link.element < 0 && link.b < 0) {
      forms[static_cast<std::size_t>(layout.frame_of(link.a))] = link.linear_form(0).value_or(LinearForm{});
    }
  }
  return forms;
}
constexpr double kInactive = -std::numeric_limits<double>::infinity();
/// The closing speed u̇_L − u̇_R of a pair counts only above this fraction of |u̇_L| + |u̇_R|: below
/// it, it is the round-off of equal velocities computed apart, or the remainder of the
/// sequential restitution of a chain, which stops there. One threshold for both, so that what
/// one impact resolution leaves behind never fires another.
constexpr double kClosingTolerance = 1e-12;

[[nodiscard]] bool closes(double v_left, double v_right) {
  return v_left - v_right > kClosingTolerance * (std::abs(v_left) + std::abs(v_right));
}

Model validated(Model model) {
  validate(model);
  return model;
}

}  // namespace

std::string_view to_string(EventKind kind) {
  switch (kind) {
    case EventKind::contact: return "contact";
    case EventKind::separation: return "separation";
    case EventKind::impact: return "impact";
    case EventKind::lock: return "lock";
    case EventKind::unlock: return "unlock";
  }
  return "?";
}

std::optional<std::string> TimeHistoryOptions::lock_time_violation() const {
  if (lock_time >= 10 * event_tolerance) return std::nullopt;
  return fmt::format("{} s must be at least 10 × event_tolerance = {} s", lock_time, 10 * event_tolerance);
}

void TimeHistoryOptions::validate() const {
  if (!std::isfinite(dt) || dt <= 0) {
    throw std::invalid_argument(fmt::format("dt = {} s must be > 0", dt));
  }
  if (const auto violation = first_violation(*this)) throw std::invalid_argument(*violation);
  // Between fields:
  if (event_tolerance >= dt) {
    throw std::invalid_argument(fmt::format(
        "event_tolerance = {} s must be smaller than dt = {} s", event_tolerance, dt));
  }
  if (const auto violation = lock_time_violation()) throw std::invalid_argument("lock_time = " + *violation);
  if (max_events_per_step < 1) throw std::invalid_argument("max_events_per_step must be ≥ 1");
  if (phase_cache_size < 1) throw std::invalid_argument("phase_cache_size must be ≥ 1");
}


Simulator::Simulator(Model model, Excitation excitation, TimeHistoryOptions options,
                     const InitialConditions& initial)
    : model_(validated(std::move(model))),
      layout_(model_),
      excitation_(std::move(excitation)),
      options_(options),
      newmark_(layout_.size()),
      energy_(model_, layout_),
      monitor_(model_, layout_, first_storey_forms(model_, layout_)) {
  options_.validate();
  validate(excitation_);
  const int n = layout_.size();
  const int gaps = model_.gap_count();
  const auto ng = static_cast<std::size_t>(gaps);
  state_.resize(n);

  const auto load = [&](const std::vector<std::vector<double>>& values, Eigen::VectorXd& out,
                        const char* what) {
    if (values.empty()) return;
    if (static_cast<int>(values.size()) != model_.frame_count()) {
      throw std::invalid_argument(fmt::format("initial {}: {} frames given, the model has {}",
                                              what, values.size(), model_.frame_count()));
    }
    for (int f = 0; f < model_.frame_count(); ++f) {
      if (static_cast<int>(values[f].size()) != layout_.storeys(f)) {
        throw std::invalid_argument(
            fmt::format("initial {} of frame {}: {} values given, the frame has {} floors", what,
                        f + 1, values[f].size(), layout_.storeys(f)));
      }
      for (int i = 0; i < layout_.storeys(f); ++i) {
        if (!std::isfinite(values[f][i])) {
          throw std::invalid_argument(fmt::format("initial {} of frame {} floor {} is not finite",
                                                  what, f + 1, i + 1));
        }
        out(layout_.dof(f, i)) = values[f][i];
      }
    }
  };
  load(initial.displacement, state_.u, "displacement");
  load(initial.velocity, state_.v, "velocity");

  std::vector<Link> links = make_links(model_, layout_);
  if (const IntegratorSupport support = supports(options_.integrator, links, layout_); !support) {
    throw std::invalid_argument(support.reason);
  }
  for (Link& link : links) {
    if (link.element >= 0) contact_links_.push_back(std::move(link));
  }
  if (options_.integrator == Integrator::exact) {
    stepper_ = std::make_unique<detail::ExactStepper>(n, gaps);
  } else {
    stepper_ = std::make_unique<detail::NewmarkStepper>(n);
  }
  contact_table_ = LinkTable(contact_links_);
  config_.assign(ng, LinkMode{0});
  for (int p = 0; p < gaps; ++p) {
    const Link& link = contact_links_[static_cast<std::size_t>(p)];
    const double d = state_.u(link.a) - state_.u(link.b);
    try {
      config_[p] =
          with_contact_law<LinkMode>(link, [&](const auto& law) { return law.initial_mode(d); });
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(
          fmt::format("initial displacements compress {} {}", describe(link, layout_), e.what()));
    }
  }
  memory_.assign(ng, GapMemory{});
  transmits_.assign(ng, 0);
  rigid_.assign(ng, 0);
  bias_.assign(ng, 0.0);
  stop_reaction_.assign(ng, 0.0);
  stop_noise_.assign(ng, 0.0);
  link_in_.assign(static_cast<std::size_t>(n), 0.0);
  for (auto* g : {&g_lo_, &g_hi_, &g_work_, &dg_lo_, &dg_hi_, &dg_work_}) g->assign(2 * ng, 0.0);
  impacts_.reserve(ng);

  link_length_.assign(ng, 0.0);
  settle_state();
  record_statistics();
}

void Simulator::settle_state() {
  activate_phase();
  newmark_.equilibrate(*phase_, ground_acceleration(excitation_, state_.t), state_);
  evaluate_guards(state_, g_lo_, dg_lo_);
  apply_pending_events();
  energy_.start(state_, config_, memory_);
  events_this_step_ = 0;
}

void Simulator::restart(Excitation excitation, double dt) {
  throw_if_failed();  // a failed simulation has no state to continue from
  validate(excitation);
  TimeHistoryOptions options = options_;
  options.dt = dt;
  options.validate();
  options_ = options;
  excitation_ = std::move(excitation);
  // Shift the clock to 0; the relaxing free ends remember their release relative to it.
  for (GapMemory& m : memory_) m.release_time -= state_.t;
  state_.t = 0.0;
  grid_origin_ = 0.0;
  grid_index_ = 0;
  phases_.clear();  // factorised for the old step
  stepper_->phases_cleared();
  try {
    settle_state();
  } catch (const SimulationError& e) {
    record_failure(e);
    throw;
  }
  reset_statistics();
}

void Simulator::reset_statistics() {
  monitor_.reset();
  record_statistics();
}

Simulator::~Simulator() = default;

double Simulator::ground_acceleration_now() const {
  return ground_acceleration(excitation_, state_.t);
}

LinkMode Simulator::mode(std::size_t p) const { return config_[p]; }

void Simulator::refresh_link_flags(std::size_t p) {
  // What the element's law does in its mode, asked when the mode changes rather than per step.
  const std::optional<LinearForm> form = contact_links_[p].linear_form(mode(p));
  transmits_[p] = form.has_value();
  rigid_[p] = form && form->rigid;
}

bool Simulator::is_rigid(std::size_t p) const { return rigid_[p] != 0; }

double Simulator::shortening(int p) const {
  const Link& link = contact_links_[static_cast<std::size_t>(p)];
  const LinkKinematics k = kinematics(state_, link);
  return with_contact_law<double>(link, [&](const auto& law) { return law.shortening(k); });
}

double Simulator::gap_force(int p) const {
  const auto e = static_cast<std::size_t>(p);
  const Link& link = contact_links_[e];
  const LinkKinematics k = kinematics(state_, link);
  const double force =
      with_contact_law<double>(link, [&](const auto& law) { return law.force(k, mode(e)); });
  return is_rigid(e) ? force + stop_reaction_[e] : force;
}

double Simulator::base_shear(int f) const {
  return monitor_.base_shear(state_, f);
}

double Simulator::storey_shear(int f) const {
  return monitor_.storey_shear(state_, f);
}

void Simulator::activate_phase() {
  stepper_->phase_changed();
  auto it = phases_.find(config_);
  if (it == phases_.end()) {
    if (phases_.size() >= options_.phase_cache_size) {
      phases_.clear();
      stepper_->phases_cleared();
    }
    auto phase = std::make_unique<LinearPhase>(model_, layout_, config_, options_.dt);
    ++monitor_.counts().phases_factorised;
    it = phases_.emplace(config_, std::move(phase)).first;
  }
  phase_ = it->second.get();
  if (!phase_->is_unreduced()) phase_->set_link_lengths(link_length_);
  for (std::size_t p = 0; p < config_.size(); ++p) refresh_link_flags(p);
}

void Simulator::step() { advance_to(grid_origin_ + static_cast<double>(grid_index_ + 1) * options_.dt); }

void Simulator::throw_if_failed() const {
  if (failure_) throw SimulationError(failure_->message, failure_->reason);
}

void Simulator::record_failure(const SimulationError& e) {
  failure_ = SimulationStatus{e.reason(), state_.t, e.what()};
}

void Simulator::advance_to(double t_target) {
  throw_if_failed();
  const double dt = options_.dt, slack = 1e-9 * dt;
  try {
    while (state_.t < t_target - slack) {
      const double next = grid_origin_ + static_cast<double>(grid_index_ + 1) * dt;
      if (next <= t_target + slack) {
        integrate_to(next, true);
        ++grid_index_;
      } else {
        integrate_to(t_target, false);
        grid_origin_ = t_target;
        grid_index_ = 0;
      }
      ++monitor_.counts().steps;
    }
  } catch (const SimulationError& e) {
    record_failure(e);
    throw;
  }
}

SimulationStatus Simulator::run_to(double t) {
  try {
    advance_to(t);
  } catch (const SimulationError&) {
    return *failure_;
  }
  return SimulationStatus{StopReason::reached_time, state_.t, {}};
}

void Simulator::integrate_to(double t_end, bool nominal) {
  events_this_step_ = 0;
  stepper_->integrate_to(*this, t_end, nominal);
}

void Simulator::evaluate_guards(const KinematicState& x, std::span<double> g,
                                std::span<double> dg) {
  // Each guard is its value minus its round-off level (the law's): a guard within a few ulps of
  // zero is zero, and zero does not fire.
  compute_stop_reactions(x);
  std::array<GuardValue, 2> values;
  for_each_contact_link(contact_table_, [&](const auto& link) {
    const auto p = static_cast<std::size_t>(link.element);
    const GuardContext context{.separation = options_.separation,
                               .reaction = stop_reaction_[p],
                               .reaction_noise = stop_noise_[p]};
    link.law.guards(kinematics(x, link), mode(p), memory_[p], context, values);
    for (std::size_t i = 0; i < values.size(); ++i) {
      const GuardValue& v = values[i];
      const std::size_t j = 2 * p + i;
      if (!v.active) {
        g[j] = kInactive;
        dg[j] = 0.0;
        continue;
      }
      g[j] = (v.hysteresis ? v.value - bias_[p] : v.value) - v.noise;
      dg[j] = v.rate;
    }
  });
}

void Simulator::compute_stop_reactions(const KinematicState& x) {
  // The force on a floor that the links must supply: f = f_S − m a_g − C u̇ − K u − m ü. Sweeping
  // each chain of locked elements from the left gives λ_out = f + λ_in.
  constexpr double kNoise = 8 * std::numeric_limits<double>::epsilon();
  if (phase_->is_unreduced()) return;  // nothing locked
  const double ground = x.ground;
  const Eigen::VectorXd& m = phase_->full_mass();
  const LinearPhase::SparseMatrix& c = phase_->full_damping();
  const LinearPhase::SparseMatrix& k = phase_->full_stiffness();
  for (std::size_t p = 0; p < config_.size(); ++p) {
    if (!is_rigid(p)) continue;
    const int l = contact_links_[p].a;
    const double load = phase_->full_constant_load()(l);
    double f = load - m(l) * (ground + x.a(l));
    double magnitude = std::abs(load) + m(l) * (std::abs(ground) + std::abs(x.a(l)));
    for (LinearPhase::SparseMatrix::InnerIterator it(c, l); it; ++it) {  // symmetric: column = row
      f -= it.value() * x.v(it.row());
      magnitude += std::abs(it.value() * x.v(it.row()));
    }
    for (LinearPhase::SparseMatrix::InnerIterator it(k, l); it; ++it) {
      f -= it.value() * x.u(it.row());
      magnitude += std::abs(it.value() * x.u(it.row()));
    }
    stop_reaction_[p] = f + link_in_[l];
    stop_noise_[p] = kNoise * (magnitude + std::abs(link_in_[l]));
    link_in_[contact_links_[p].b] = stop_reaction_[p];
  }
  for (std::size_t p = 0; p < config_.size(); ++p) {
    if (is_rigid(p)) link_in_[contact_links_[p].b] = 0.0;
  }
}

void Simulator::accept(KinematicState& next) {
  energy_.step(state_, next, config_, memory_);
  monitor_.observe_step(state_, next);
  after_accept(next);
  g_lo_ = g_hi_;
  dg_lo_ = dg_hi_;
}

void Simulator::after_accept(KinematicState& next) {
  const double h = next.t - state_.t;
  for (std::size_t p = 0; p < config_.size(); ++p) {
    if (is_rigid(p)) monitor_.observe_locked(p, h);
  }
  std::swap(state_, next);
  ++monitor_.counts().substeps;
  record_statistics();
}

void Simulator::check_finite() const {
  // Magnitudes beyond double range (an amplitude of 1e300 g, k = 1e308 with m = 1e-300, ...) turn
  // the state or the energies into ±inf and then NaN, which every comparison (peaks, the balance
  // check) silently ignores. Stop at the first such state and say where it went.
  const auto where = [&](int dof) {
    return fmt::format("frame {} floor {}", layout_.frame_of(dof) + 1, layout_.floor_of(dof) + 1);
  };
  const auto fail = [&](const std::string& what) {
    throw SimulationError(fmt::format(
        "at t = {} s {} is not finite: the input's magnitudes (accelerations, initial velocities, "
        "stiffness over mass) exceed the range of double precision",
        state_.t, what), StopReason::non_finite);
  };
  if (!std::isfinite(state_.ground)) fail(fmt::format("the ground acceleration ({})", state_.ground));
  for (int i = 0; i < layout_.size(); ++i) {
    if (!std::isfinite(state_.u(i))) fail(fmt::format("the displacement of {} ({})", where(i), state_.u(i)));
    if (!std::isfinite(state_.v(i))) fail(fmt::format("the velocity of {} ({})", where(i), state_.v(i)));
    if (!std::isfinite(state_.a(i))) fail(fmt::format("the acceleration of {} ({})", where(i), state_.a(i)));
  }
  for (int f = 0; f < model_.frame_count(); ++f) {
    const double v = storey_shear(f);
    if (!std::isfinite(v)) fail(fmt::format("the base shear of frame {} ({} N)", f + 1, v));
  }
  for_each_contact_link(contact_table_, [&](const auto& link) {
    const auto p = static_cast<std::size_t>(link.element);
    const double law_force = link.law.force(kinematics(state_, link), mode(p));
    const double force = is_rigid(p) ? law_force + stop_reaction_[p] : law_force;
    if (!std::isfinite(force)) {
      fail(fmt::format("the force of {} ({} N)", describe(contact_links_[p], layout_), force));
    }
  });
  const EnergyBalance& b = energy_.balance();
  for (const auto& [name, value] :
       {std::pair{"the input energy", b.input}, std::pair{"the kinetic energy", b.kinetic},
        std::pair{"the storey strain energy", b.storey_strain},
        std::pair{"the gap-element strain energy", b.gap_strain},
        std::pair{"the energy dissipated by the storey dashpots", b.storey_damping},
        std::pair{"the energy dissipated by the gap elements", b.gap_damping},
        std::pair{"the energy lost in impacts", b.impact_loss}}) {
    if (!std::isfinite(value)) fail(fmt::format("{} ({} J)", name, value));
  }
}

void Simulator::record_statistics() {
  check_finite();
  monitor_.observe(state_);
  for_each_contact_link(contact_table_, [&](const auto& link) {
    const auto p = static_cast<std::size_t>(link.element);
    if (!transmits_[p]) return;
    const LinkKinematics k = kinematics(state_, link);
    const double force = link.law.force(k, mode(p));
    monitor_.observe_gap(p, is_rigid(p) ? force + stop_reaction_[p] : force, link.law.shortening(k), state_.t);
  });
}

void Simulator::emit(int gap, EventKind kind, double left_before, double right_before,
                     double impulse) {
  const auto p = static_cast<std::size_t>(gap);
  const double left_after = state_.v(contact_links_[p].a);
  const double right_after = state_.v(contact_links_[p].b);
  const double before = left_before - right_before, after = left_after - right_after;
  if (++events_this_step_ > options_.max_events_per_step) {
    throw SimulationError(fmt::format(
        "more than {} events within one step at t = {} s ({}): chattering that lock_time = {} s does not "
        "suppress",
        options_.max_events_per_step, state_.t, describe(contact_links_[p], layout_), options_.lock_time),
        StopReason::event_limit);
  }
  monitor_.observe_event(p, kind, before, impulse, state_.t);
  if (on_event_) {
    on_event_(Event{state_.t, gap, kind, before, after, impulse, left_before, right_before,
                    left_after, right_after});
  }
}

void Simulator::apply_pending_events() {
  // An event can trigger others at the same instant (e.g. an impact that makes the dashpot pull):
  // apply them all before moving on. apply_events re-evaluates g_lo_, hence the copy.
  while (any_fired(g_lo_)) {
    g_work_ = g_lo_;
    apply_events(g_work_);
  }
}

void Simulator::apply_events(std::span<const double> fired) {
  impacts_.clear();
  for (std::size_t j = 0; j < fired.size(); ++j) {
    if (!(fired[j] > 0)) continue;
    const std::size_t p = j / 2;
    const int pi = static_cast<int>(p);
    const Link& link = contact_links_[p];
    const double vl = state_.v(link.a), vr = state_.v(link.b);
    const LinkKinematics k = kinematics(state_, link);
    LinkMode m = mode(p);
    const Transition transition = with_contact_law<Transition>(link, [&](const auto& law) {
      return law.on_guard(static_cast<int>(j % 2), k, m, memory_[p], options_.separation);
    });
    config_[p] = m;
    refresh_link_flags(p);  // the event handler below may ask for the element's force
    switch (transition) {
      case Transition::impact: impacts_.push_back(pi); break;
      case Transition::contact:
        bias_[p] = 0.0;
        emit(pi, EventKind::contact, vl, vr, 0.0);
        break;
      case Transition::separation:
        bias_[p] = 0.0;
        emit(pi, EventKind::separation, vl, vr, 0.0);
        break;
      case Transition::unlock:
        bias_[p] = 0.0;
        emit(pi, EventKind::unlock, vl, vr, 0.0);
        break;
    }
  }
  activate_phase();
  if (!impacts_.empty()) resolve_impacts(impacts_);
  settle_after_events();
}

double Simulator::stop_guard(std::size_t p) const {
  const Link& link = contact_links_[p];
  const LinkKinematics k = kinematics(state_, link);
  const double distance = with_contact_law<double>(
      link, [&](const auto& law) { return law.stop_distance(k, mode(p), memory_[p]); });
  return distance - bias_[p];
}

bool Simulator::stop_guard_is_active(std::size_t p) const {
  return with_contact_law<bool>(contact_links_[p], [&](const auto& law) {
    return law.traits.has_stop && law.stop_guard_is_active(mode(p));
  });
}

void Simulator::resolve_impacts(const std::vector<int>& fired) {
  Eigen::VectorXd& v = state_.v;
  const double kinetic_before = energy_.kinetic_energy(v);
  const std::size_t elements = config_.size();
  const double ground = ground_acceleration_now();

  std::vector<double> left_before(elements), right_before(elements), impulse(elements, 0.0);
  std::vector<char> involved(elements, 0);
  for (std::size_t p = 0; p < elements; ++p) {
    left_before[p] = v(contact_links_[p].a);
    right_before[p] = v(contact_links_[p].b);
  }
  for (const int p : fired) involved[static_cast<std::size_t>(p)] = 1;
  const auto closing_speed = [&](std::size_t p) {
    const double vl = v(contact_links_[p].a), vr = v(contact_links_[p].b);
    return closes(vl, vr) ? vl - vr : 0.0;
  };
  struct Lock {
    int element;
    double left_before, right_before, impulse;
  };
  std::vector<Lock> locks;

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
  const int max_sweeps = 10000 * static_cast<int>(elements);
  int sweeps = 0;
  for (;;) {
    const auto group = phase_->group_of();
    const Eigen::VectorXd& group_mass = phase_->mass();
    const auto shares_a_body = [&](std::size_t p) {
      const int gl = group[static_cast<std::size_t>(contact_links_[p].a)];
      const int gr = group[static_cast<std::size_t>(contact_links_[p].b)];
      for (std::size_t q = 0; q < elements; ++q) {
        if (!involved[q]) continue;
        const int ql = group[static_cast<std::size_t>(contact_links_[q].a)];
        const int qr = group[static_cast<std::size_t>(contact_links_[q].b)];
        if (gl == ql || gl == qr || gr == ql || gr == qr) return true;
      }
      return false;
    };
    for (;;) {
      for (; sweeps < max_sweeps; ++sweeps) {
        std::size_t worst = elements;
        double closing = 0.0;
        for (std::size_t p = 0; p < elements; ++p) {
          if (!involved[p] || is_rigid(p)) continue;
          const double w = closing_speed(p);
          if (w > closing) {
            closing = w;
            worst = p;
          }
        }
        if (worst == elements) break;
        const int l = contact_links_[worst].a, r = contact_links_[worst].b;
        const int gl = group[static_cast<std::size_t>(l)];
        const int gr = group[static_cast<std::size_t>(r)];
        const double rest = options_.rest_velocity_ratio * (std::abs(v(l)) + std::abs(v(r)));
        const double restitution =
            closing <= rest ? 0.0
                            : with_contact_law<double>(contact_links_[worst], [](const auto& law) {
                                return law.restitution();
                              });
        const ImpactOutcome o =
            restitution_impact(group_mass(gl), group_mass(gr), v(l), v(r), restitution);
        for (Eigen::Index i = 0; i < v.size(); ++i) {
          const int gi = group[static_cast<std::size_t>(i)];
          if (gi == gl) v(i) = o.v_left;
          if (gi == gr) v(i) = o.v_right;
        }
        impulse[worst] += o.impulse;
      }
      bool joined = false;
      for (std::size_t p = 0; p < elements; ++p) {
        if (involved[p]) continue;
        if (!stop_guard_is_active(p)) continue;
        const double w = closing_speed(p);
        if (!(w > 0) || !shares_a_body(p)) continue;
        const LinkKinematics k = kinematics(state_, contact_links_[p]);
        const double s_noise = with_contact_law<double>(
            contact_links_[p], [&](const auto& law) { return law.position_noise(k); });
        if (stop_guard(p) < -(w * options_.event_tolerance + s_noise)) continue;
        involved[p] = 1;
        joined = true;
      }
      if (!joined) break;
    }

    newmark_.equilibrate(*phase_, ground, state_);
    std::vector<int> locking;
    for (std::size_t p = 0; p < elements; ++p) {
      if (!involved[p] || is_rigid(p)) continue;
      const int l = contact_links_[p].a, r = contact_links_[p].b;
      const int gl = group[static_cast<std::size_t>(l)], gr = group[static_cast<std::size_t>(r)];
      if (gl == gr) continue;  // already held together through other locked links
      const double pressing = state_.a(l) - state_.a(r);
      const double opening = -(v(l) - v(r));
      if (pressing > 0 && 2.0 * opening <= pressing * options_.lock_time) {
        locking.push_back(static_cast<int>(p));
        const double ml = group_mass(gl), mr = group_mass(gr);
        locks.push_back({static_cast<int>(p), v(l), v(r), std::abs(v(l) - v(r)) * ml * mr / (ml + mr)});
      }
    }
    if (locking.empty()) break;
    for (const int p : locking) {
      const auto e = static_cast<std::size_t>(p);
      config_[e] = with_contact_law<LinkMode>(contact_links_[e],
                                              [](const auto& law) { return law.locked_mode(); });
      // The link keeps the floors where they are (on the stop, to the event tolerance).
      link_length_[e] = state_.u(contact_links_[e].a) - state_.u(contact_links_[e].b);
    }
    activate_phase();
    // Plastic merge: each new group moves with the velocity of its centre of mass.
    const auto new_group = phase_->group_of();
    const Eigen::VectorXd& m = phase_->full_mass();
    Eigen::VectorXd momentum = Eigen::VectorXd::Zero(phase_->reduced_size());
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      momentum(new_group[static_cast<std::size_t>(i)]) += m(i) * v(i);
    }
    const Eigen::VectorXd group_v = momentum.cwiseQuotient(phase_->mass());
    phase_->scatter(group_v, v, false);
  }
  energy_.add_impact_loss(kinetic_before - energy_.kinetic_energy(v));
  for (std::size_t p = 0; p < elements; ++p) {
    // A pair whose guard fired without closing (a touch at equal speeds) took no impulse: it is no
    // impact, though it may have locked.
    if (involved[p] && impulse[p] > 0) {
      emit(static_cast<int>(p), EventKind::impact, left_before[p], right_before[p], impulse[p]);
    }
  }
  for (const Lock& lock : locks) {
    emit(lock.element, EventKind::lock, lock.left_before, lock.right_before, lock.impulse);
  }
}

void Simulator::settle_after_events() {
  newmark_.equilibrate(*phase_, ground_acceleration_now(), state_);
  evaluate_guards(state_, g_lo_, dg_lo_);
  set_impact_biases();
  energy_.refresh(state_, config_, memory_);
}

void Simulator::set_impact_biases() {
  // At an impact the state is taken at the upper end of the event bracket, a hair past the stop
  // (by at most |ṡ| × tolerance). The element now moves away from the stop; offset its guard by
  // that hair so that the next impact is detected when the stop is reached again.
  for (std::size_t p = 0; p < config_.size(); ++p) {
    const std::size_t j = 2 * p;
    if (!stop_guard_is_active(p) || !(g_lo_[j] > 0)) continue;
    // Still closing: a genuine impact, applied by the caller.
    if (closes(state_.v(contact_links_[p].a), state_.v(contact_links_[p].b))) continue;
    bias_[p] += g_lo_[j];
    g_lo_[j] = 0.0;
  }
}

}  // namespace poundsim
