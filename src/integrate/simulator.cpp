#include "poundsim/integrate/simulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "../dynamics/contact_links.hpp"
#include "hermite_cubic.hpp"
#include "steppers.hpp"
#include "tangent_flow.hpp"
#include "poundsim/error.hpp"

namespace poundsim {

using detail::for_each_contact_link;
using detail::kinematics;

namespace {

/// The linear form of each frame's first storey (its law's, on the ground): V = k u₁ is its
/// spring force, k u₁ + c u̇₁ its whole force.
std::vector<LinearForm> first_storey_forms(const Model& model, const DofLayout& layout) {
  std::vector<LinearForm> forms(static_cast<std::size_t>(model.frame_count()));
  for (const Link& link : make_links(model, layout)) {
    if (link.b < 0) {  // a first storey (a yielding one's is set with each phase, Loop::activate_phase)
      forms[static_cast<std::size_t>(layout.frame_of(link.a))] = link.linear_form(0).value_or(LinearForm{});
    }
  }
  return forms;
}
/// The system after its inputs are validated, in the order a user fixes them: the model, the
/// options, the excitation.
PoundingSystem validated_system(Model model, Excitation excitation, const TimeHistoryOptions& options) {
  validate(model);
  options.validate();
  validate(excitation);
  return {std::move(model), std::move(excitation), options.event_rules()};
}

}  // namespace

std::string_view to_string(EventKind kind) {
  switch (kind) {
    case EventKind::contact: return "contact";
    case EventKind::separation: return "separation";
    case EventKind::impact: return "impact";
    case EventKind::lock: return "lock";
    case EventKind::unlock: return "unlock";
    case EventKind::yield: return "yield";
    case EventKind::unload: return "unload";
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


namespace detail {

/// The loop as the system's event handler: it owns the phases and the monitors.
class Loop::Events final : public EventHandler {
 public:
  explicit Events(Loop& loop) : loop_(loop) {}
  // The system applies events to the loop's own contact state (Loop::apply_pending_events), so
  // the phase of `contact` is the loop's current one.
  LinearPhase& activate(const ContactState& /*contact*/) override { return loop_.activate_phase(); }
  void on_event(const KinematicState& /*x: the loop's state*/, int gap, EventKind kind, double left_before,
                double right_before, double impulse) override {
    loop_.emit(gap, kind, left_before, right_before, impulse);
  }
  void on_impact_loss(double loss) override { loop_.energy_.add_impact_loss(loss); }
  void on_pair_impact(std::span<const int> group, int left, int right, double mass_left, double mass_right,
                      double restitution) override {
    if (TangentFlow* tangent = loop_.tangent()) tangent->pair_impact(group, left, right, mass_left, mass_right, restitution);
  }
  void on_merge(std::span<const int> group, const Eigen::VectorXd& floor_mass,
                const Eigen::VectorXd& group_mass) override {
    if (TangentFlow* tangent = loop_.tangent()) tangent->merge(group, floor_mass, group_mass);
  }

 private:
  Loop& loop_;
};

Loop::Loop(PoundingSystem system, const TimeHistoryOptions& options)
    : system_(std::move(system)),
      options_(options),
      energy_(system_.model(), system_.layout()),
      monitor_(system_.model(), system_.layout(), first_storey_forms(system_.model(), system_.layout())),
      events_(std::make_unique<Events>(*this)) {
  state_.resize(system_.layout().size());
  v_before_events_.resize(system_.layout().size());
  a_before_events_.resize(system_.layout().size());
  monitor_.set_impact_duration(options_.impact_duration);
  for (const Link& link : system_.links()) {
    if (link.element >= 0 && link.b < 0 && link.smooth_in(0)) {
      smooth_first_storeys_.push_back(system_.layout().frame_of(link.a));
    }
  }
  for (auto* g : {&guards_.lo, &guards_.hi, &guards_.work, &guards_.rate_lo, &guards_.rate_hi, &guards_.rate_work}) {
    g->assign(2 * static_cast<std::size_t>(system_.tracked_count()), 0.0);
  }
}

Loop::~Loop() = default;

}  // namespace detail

Simulator::Simulator(Model model, Excitation excitation, TimeHistoryOptions options,
                     const InitialConditions& initial)
    : Loop(validated_system(std::move(model), std::move(excitation), options), options) {
  const Model& model_ = system_.model();
  const DofLayout& layout_ = system_.layout();
  const int n = layout_.size();
  const int tracked = system_.tracked_count();

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

  if (const IntegratorSupport support = supports(options_.integrator, system_.links(), layout_); !support) {
    throw std::invalid_argument(support.reason);
  }
  if (options_.integrator == Integrator::exact) {
    stepper_ = std::make_unique<detail::ExactStepper>(n, tracked);
  } else {
    stepper_ = std::make_unique<detail::NewmarkStepper>(n, tracked);
  }
  contact_ = system_.initial_contact(state_);
  // An initial drift loads a Bouc–Wen storey monotonically from rest.
  if (system_.has_committing_laws()) system_.commit_states(state_, contact_);
  settle_state();
  record_statistics();
}

void Simulator::settle_state() {
  activate_phase();
  system_.refresh_flags(contact_);  // events refresh them through the system (EventHandler)
  system_.equilibrate(*phase_, state_, contact_);
  evaluate_guards(state_, guards_.lo, guards_.rate_lo);
  apply_pending_events();
  energy_.start(state_, contact_.config, contact_.states);
  events_this_step_ = 0;
}

void Simulator::restart(Excitation excitation, double dt) {
  throw_if_failed();  // a failed simulation has no state to continue from
  validate(excitation);
  TimeHistoryOptions options = options_;
  options.dt = dt;
  options.validate();
  options_ = options;
  system_.set_excitation(std::move(excitation));
  // Shift the clock to 0; the laws keep their times (a free end's release) relative to it.
  contact_.states.shift_clock(state_.t);
  state_.t = 0.0;
  grid_origin_ = 0.0;
  grid_index_ = 0;
  // Newmark's phases are factorised for the old step; the exact integrator's do not depend on it.
  if (options_.integrator != Integrator::exact) {
    phases_.clear();
    stepper_->phases_cleared();
  }
  start_afresh();
}

void Simulator::start_afresh() {
  try {
    settle_state();
  } catch (const SimulationError& e) {
    record_failure(e);
    throw;
  }
  reset_statistics();
  if (tracking_) tangent_->reset(state_.t);
}

void Simulator::reset_state(const Eigen::VectorXd& u, const Eigen::VectorXd& v) {
  const int n = system_.layout().size();
  if (u.size() != n || v.size() != n) {
    throw std::invalid_argument(fmt::format("reset_state: {} displacements and {} velocities given, the model has {} floors",
                                            u.size(), v.size(), n));
  }
  if (!u.allFinite() || !v.allFinite()) throw std::invalid_argument("reset_state: a displacement or velocity is not finite");
  failure_.reset();
  state_.t = 0.0;
  state_.u = u;
  state_.v = v;
  state_.a.setZero();
  grid_origin_ = 0.0;
  grid_index_ = 0;
  contact_ = system_.initial_contact(state_);
  if (system_.has_committing_laws()) system_.commit_states(state_, contact_);
  start_afresh();
}

void Simulator::track_sensitivity(bool track) {
  if (!track) {
    tracking_ = false;
    return;
  }
  if (options_.integrator != Integrator::exact) {
    throw std::invalid_argument("the sensitivities of the state (periodic orbits) need integrator = \"exact\"");
  }
  if (!tangent_) tangent_ = std::make_unique<detail::TangentFlow>(system_.layout().size());
  tracking_ = true;
  tangent_->reset(state_.t);
  stepper_->tangent_restarted(*this);
}

Eigen::Ref<const Eigen::MatrixXd> Simulator::sensitivity() {
  if (!tracking_) throw std::logic_error("sensitivity(): track_sensitivity() was not called");
  tangent_->propagate_to(state_.t);
  return tangent_->sensitivity();
}

void Simulator::track_frequency_sensitivity(bool track) {
  if (track) {
    if (!tracking_) throw std::invalid_argument("track_frequency_sensitivity: track_sensitivity() first");
    if (!std::holds_alternative<HarmonicExcitation>(system_.excitation())) {
      throw std::invalid_argument("the sensitivity to the forcing frequency needs a harmonic excitation");
    }
  }
  if (tangent_ && tangent_->tracks_frequency() != track) {
    tangent_->track_frequency(track);
    tangent_->reset(state_.t);
    if (tracking_) stepper_->tangent_restarted(*this);
  }
}

Eigen::Ref<const Eigen::VectorXd> Simulator::frequency_sensitivity() {
  if (!tracking_ || !tangent_->tracks_frequency()) {
    throw std::logic_error("frequency_sensitivity(): track_frequency_sensitivity() was not called");
  }
  tangent_->propagate_to(state_.t);
  return tangent_->frequency_sensitivity();
}

double Simulator::least_transversality() const { return tracking_ ? tangent_->least_transversality() : 1.0; }

void Simulator::reset_statistics() {
  monitor_.reset();
  record_statistics();
}

Simulator::~Simulator() = default;

double Simulator::ground_acceleration_now() const { return system_.ground_acceleration(state_.t); }

double Simulator::shortening(int p) const { return system_.shortening(state_, p); }

double Simulator::gap_force(int p) const { return system_.gap_force(state_, contact_, p); }

double Simulator::storey_drift(int dof) const { return Loop::storey_drift(dof); }

double Simulator::storey_force(int dof) const { return restoring_force(dof); }

namespace detail {
double Loop::storey_drift(int dof) const {
  const int below = system_.layout().below(dof);
  return state_.u(dof) - (below >= 0 ? state_.u(below) : 0.0);
}

std::optional<Loop::FirstStoreyForces> Loop::smooth_first_storey(int f) const {
  if (std::find(smooth_first_storeys_.begin(), smooth_first_storeys_.end(), f) == smooth_first_storeys_.end()) {
    return std::nullopt;
  }
  const int dof = system_.layout().dof(f, 0);
  const double spring = restoring_force(dof);
  return FirstStoreyForces{spring, spring + system_.model().frames[static_cast<std::size_t>(f)].damping[0] * state_.v(dof)};
}

double Loop::restoring_force(int dof) const {
  // make_links puts the storeys first, one per DOF.
  const Link& link = system_.links()[static_cast<std::size_t>(dof)];
  const LinkMode mode = mode_of(link, contact_.config);
  const double drift = storey_drift(dof);
  return std::visit(
      [&](const auto& law) -> double {
        using L = std::decay_t<decltype(law)>;
        if constexpr (ContactLaw<L>) {
          throw std::logic_error("restoring_force: a gap element's link");
        } else {
          return law.restoring_force(drift, mode, contact_.states.at(law, link.slot));
        }
      },
      link.law);
}
}  // namespace detail

double Simulator::base_shear(int f) const {
  if (const auto smooth = smooth_first_storey(f)) return smooth->base_shear;
  return monitor_.base_shear(state_, f);
}

double Simulator::storey_shear(int f) const {
  if (const auto smooth = smooth_first_storey(f)) return smooth->storey_shear;
  return monitor_.storey_shear(state_, f);
}

namespace detail {

LinearPhase& Loop::activate_phase() {
  stepper_->phase_changed();
  auto it = phases_.find(contact_.config);
  if (it == phases_.end()) {
    if (phases_.size() >= options_.phase_cache_size) {
      phases_.clear();
      stepper_->phases_cleared();
    }
    auto phase = std::make_unique<LinearPhase>(system_.model(), system_.layout(), contact_.config, options_.dt);
    ++monitor_.counts().phases_factorised;
    it = phases_.emplace(contact_.config, std::move(phase)).first;
  }
  phase_ = it->second.get();
  if (phase_->has_state_loads()) phase_->set_law_states(contact_.states);
  if (!phase_->is_unreduced()) phase_->set_link_lengths(contact_.link_length);
  // A yielding first storey's form changes with its mode and plastic drift: the base shear's.
  for (const Link& link : system_.tracked_links().subspan(static_cast<std::size_t>(system_.gap_count()))) {
    if (link.b < 0) {
      monitor_.set_first_storey(system_.layout().frame_of(link.a),
                                system_.linear_form(link, contact_).value_or(LinearForm{}));
    }
  }
  return *phase_;
}

}  // namespace detail

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

namespace detail {

void Loop::accept(KinematicState& next) {
  if (recording_) {
    if (metering_) energy_.step(state_, next, contact_.config, contact_.states);
    monitor_.observe_step(state_, next);
  }
  after_accept(next);
  // The end's guards become the start's. A swap, not a copy: the stepper evaluates every guard
  // into hi again before it reads it (entries no law writes stay 0 in every buffer).
  std::swap(guards_.lo, guards_.hi);
  std::swap(guards_.rate_lo, guards_.rate_hi);
}

void Loop::after_accept(KinematicState& next) {
  const double h = next.t - state_.t;
  for (std::size_t p = 0; p < static_cast<std::size_t>(system_.gap_count()); ++p) {
    if (contact_.transmits[p] != 0) monitor_.observe_in_contact(p, h);
    if (contact_.rigid[p] != 0) monitor_.observe_locked(p, h);
  }
  // The laws that follow the motion (a Bouc–Wen storey's z) take the accepted state as theirs.
  if (system_.has_committing_laws()) system_.commit_states(next, contact_);
  swap(state_, next);
  ++monitor_.counts().substeps;
  record_statistics();
}

bool Loop::all_finite() const {
  // This runs at every accepted state: x·0 is NaN exactly when x is ±∞ or NaN, so a sum of such
  // products is ±0 unless something is not finite. Its order does not matter, hence u, v and a
  // in chains of their own, and plain loops (check_finite names the culprit, in its order).
  const Eigen::Index n = state_.u.size();
  const double *u = state_.u.data(), *v = state_.v.data(), *a = state_.a.data();
  double pu = state_.ground * 0.0, pv = 0.0, pa = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    pu += u[i] * 0.0;
    pv += v[i] * 0.0;
    pa += a[i] * 0.0;
  }
  double poison = (pu + pv) + (pa + monitor_.storey_shear_poison(state_));
  for_each_contact_link(system_.contact_table(), [&](const auto& link) {
    if (contact_.transmits[static_cast<std::size_t>(link.element)] == 0) return;
    poison += PoundingSystem::gap_force(state_, contact_, link) * 0.0;
  });
  if (metering_) {
    const EnergyBalance& b = energy_.balance();
    poison += ((b.input * 0.0 + b.kinetic * 0.0) + (b.storey_strain * 0.0 + b.gap_strain * 0.0)) +
              ((b.storey_damping * 0.0 + b.gap_damping * 0.0) + (b.impact_loss * 0.0 + b.storey_hysteretic * 0.0));
  }
  return poison == 0.0;
}

void Loop::check_finite() const {
  // Magnitudes beyond double range (an amplitude of 1e300 g, k = 1e308 with m = 1e-300, ...) turn
  // the state or the energies into ±inf and then NaN, which every comparison (peaks, the balance
  // check) silently ignores. Stop at the first such state and say where it went.
  const DofLayout& layout_ = system_.layout();
  const auto where = [&](int dof) {
    return fmt::format("frame {} floor {}", layout_.frame_of(dof) + 1, layout_.floor_of(dof) + 1);
  };
  // Every quantity checked, listed once: check(value, unit, what), what() naming it. all_finite()
  // is the fast pass over the same quantities: a quantity added here goes there too.
  const auto each_quantity = [&](auto&& check) {
    check(state_.ground, "", [] { return std::string("the ground acceleration"); });
    const double *u = state_.u.data(), *v = state_.v.data(), *a = state_.a.data();
    for (int i = 0; i < layout_.size(); ++i) {
      check(u[i], "", [&] { return "the displacement of " + where(i); });
      check(v[i], "", [&] { return "the velocity of " + where(i); });
      check(a[i], "", [&] { return "the acceleration of " + where(i); });
    }
    for (int f = 0; f < system_.model().frame_count(); ++f) {
      check(monitor_.storey_shear(state_, f), " N", [f] { return fmt::format("the base shear of frame {}", f + 1); });
    }
    for_each_contact_link(system_.contact_table(), [&](const auto& link) {
      // A link that transmits nothing in its mode (an open gap element) has no force to check.
      if (contact_.transmits[static_cast<std::size_t>(link.element)] == 0) return;
      check(PoundingSystem::gap_force(state_, contact_, link), " N", [&] {
        return "the force of " + describe(system_.contact_links()[static_cast<std::size_t>(link.element)], layout_);
      });
    });
    // The balance only while it is kept: a simulator that meters no energy (a free run, a
    // frequency response's transient) reports none, and its terms stop changing but for the
    // impact losses of events, which nothing reads.
    if (!metering_) return;
    const EnergyBalance& b = energy_.balance();
    const auto energy = [&](double value, const char* name) { check(value, " J", [name] { return std::string(name); }); };
    energy(b.input, "the input energy");
    energy(b.kinetic, "the kinetic energy");
    energy(b.storey_strain, "the storey strain energy");
    energy(b.gap_strain, "the gap-element strain energy");
    energy(b.storey_damping, "the energy dissipated by the storey dashpots");
    energy(b.gap_damping, "the energy dissipated by the gap elements");
    energy(b.impact_loss, "the energy lost in impacts");
    energy(b.storey_hysteretic, "the hysteretic energy of the storeys");
  };
  if (all_finite()) return;  // the common case, in one pass; all_finite() checks the same quantities
  each_quantity([&](double x, std::string_view unit, const auto& what) {
    if (std::isfinite(x)) return;
    throw SimulationError(fmt::format(
        "at t = {} s {} ({}{}) is not finite: the input's magnitudes (accelerations, initial velocities, "
        "stiffness over mass) exceed the range of double precision",
        state_.t, what(), x, unit), StopReason::non_finite);
  });
}

void Loop::record_statistics() {
  check_finite();
  if (!recording_) return;  // the counts go on (observe_event); the peaks wait for reset_statistics
  monitor_.observe(state_);
  for (const int f : smooth_first_storeys_) {
    const FirstStoreyForces forces = *smooth_first_storey(f);
    monitor_.observe_first_storey(f, forces.base_shear, forces.storey_shear, state_.t);
  }
  // Law by law (no dispatch per element): this runs at every accepted state.
  for_each_contact_link(system_.contact_table(), [&](const auto& link) {
    const auto p = static_cast<std::size_t>(link.element);
    if (contact_.transmits[p] == 0) return;
    monitor_.observe_gap(p, PoundingSystem::gap_force(state_, contact_, link),
                         link.law.shortening(kinematics(state_, link)), state_.t);
  });
}

void Loop::emit(int gap, EventKind kind, double left_before, double right_before,
                     double impulse) {
  const auto p = static_cast<std::size_t>(gap);
  const Link& link = system_.tracked_links()[p];
  const bool storey = gap >= system_.gap_count();  // a storey yields or unloads
  if (++events_this_step_ > options_.max_events_per_step) {
    throw SimulationError(
        fmt::format("more than {} events within one step at t = {} s ({}){}", options_.max_events_per_step, state_.t,
                    describe(link, system_.layout()),
                    storey ? "" : fmt::format(": chattering that lock_time = {} s does not suppress", options_.lock_time)),
        StopReason::event_limit);
  }
  if (storey) {
    // Its plastic drift, and the round-off level of a drift of its size.
    double plastic = std::numeric_limits<double>::quiet_NaN(), round_off = 0.0;
    std::visit(
        [&](const auto& law) {
          using L = std::decay_t<decltype(law)>;
          if constexpr (requires(const typename L::State& s) { s.plastic_drift; law.yield_drift(); }) {
            const LinkKinematics k = detail::kinematics(state_, link);
            plastic = contact_.states.at(law, link.slot).plastic_drift;
            round_off = 64 * std::numeric_limits<double>::epsilon() *
                        (std::abs(k.ua) + std::abs(k.ub) + std::abs(plastic) + law.yield_drift());
          }
        },
        link.law);
    monitor_.observe_storey_event(link.a, kind, plastic, round_off);
    return;
  }
  const LinkKinematics after_event = detail::kinematics(state_, link);  // at a column point, its velocity
  const double left_after = after_event.va;
  const double right_after = after_event.vb;
  const double before = left_before - right_before, after = left_after - right_after;
  monitor_.observe_event(p, kind, before, impulse, state_.t);
  if (on_event_) {
    on_event_(Event{state_.t, gap, kind, before, after, impulse, left_before, right_before,
                    left_after, right_after});
  }
}

void Loop::apply_pending_events() {
  // An event can trigger others at the same instant (e.g. an impact that makes the dashpot pull):
  // apply them all before moving on. The system re-evaluates g_lo_, hence the copy.
  bool applied = false;
  const bool watching = recording_ && any_fired(guards_.lo);
  if (watching) {
    v_before_events_ = state_.v;
    a_before_events_ = state_.a;
  }
  while (any_fired(guards_.lo)) {
    guards_.work = guards_.lo;
    phase_ = &system_.apply_events(guards_.work, state_, contact_, *phase_, guards_.lo, guards_.rate_lo, *events_);
    energy_.refresh(state_, contact_.config, contact_.states);
    applied = true;
  }
  // The events changed the state (velocities, merged floors, accelerations) after accept()
  // checked and observed it: a step starts only from a finite state, and the peaks include the
  // state just after the events (a storey shear k u + c u̇ jumps with an impact's velocities).
  if (!applied) return;
  record_statistics();
  if (watching) monitor_.observe_velocity_jumps(v_before_events_, a_before_events_, state_);
}

}  // namespace detail
}  // namespace poundsim
