#include "poundsim/integrate/response_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <type_traits>
#include <utility>

#include "hermite_cubic.hpp"
#include "poundsim/integrate/bracketed_roots.hpp"
#include "poundsim/dynamics/link_kinematics.hpp"

namespace poundsim {

namespace {
/// The approach of a facing pair, u_L − u_R of its points, and its rate. `AtFloors`
/// (std::true_type when every pair of the model joins floors, which the loops of every step test
/// once) reads the floors directly; otherwise a column point is interpolated.
template <class AtFloors, class Points>
[[gnu::always_inline]] inline double approach(AtFloors, const KinematicState& x, const Points& p) {
  if constexpr (AtFloors::value) {
    return x.u(p.a) - x.u(p.b);
  } else {
    const LinkKinematics k = detail::kinematics<detail::Derivatives::velocities>(x, p);
    return k.ua - k.ub;
  }
}
template <class AtFloors, class Points>
[[gnu::always_inline]] inline double approach_rate(AtFloors, const KinematicState& x, const Points& p) {
  if constexpr (AtFloors::value) {
    return x.v(p.a) - x.v(p.b);
  } else {
    const LinkKinematics k = detail::kinematics<detail::Derivatives::velocities>(x, p);
    return k.va - k.vb;
  }
}
/// Calls f(std::true_type) when every facing pair joins floors, f(std::false_type) otherwise.
template <class F>
void with_facing(bool at_floors, F&& f) {
  if (at_floors) {
    f(std::true_type{});
  } else {
    f(std::false_type{});
  }
}
}  // namespace

ResponseMonitor::ResponseMonitor(const Model& model, const DofLayout& layout, std::vector<LinearForm> first_storey)
    : layout_(layout), first_storey_(std::move(first_storey)) {
  stats_.floors.resize(static_cast<std::size_t>(layout_.size()));
  for (const FloorPair& p : facing_floors(model)) {
    stats_.neighbours.push_back(NeighbourResponse{p.left_frame, p.left_floor, p.right_floor, p.column});
    FacingPoints points{.a = layout_.dof(p.left_frame, p.left_floor), .b = layout_.dof(p.left_frame + 1, p.right_floor)};
    std::tie(points.a_column, points.b_column) = column_points(p.column, points.a, points.b, layout_);
    facing_.push_back(points);
    facing_at_floors_ = facing_at_floors_ && points.joins_floors();
  }
  for (int f = 0; f < model.frame_count(); ++f) first_storey_dofs_.push_back(layout_.dof(f, 0));
  stats_.base_shear.resize(static_cast<std::size_t>(model.frame_count()));
  stats_.storey_shear.resize(static_cast<std::size_t>(model.frame_count()));
  stats_.gaps.resize(static_cast<std::size_t>(model.gap_count()));
  contact_start_.assign(static_cast<std::size_t>(model.gap_count()), std::numeric_limits<double>::quiet_NaN());
  contact_closing_.assign(static_cast<std::size_t>(model.gap_count()), 0.0);
  node_.resize(layout_.size());
  plastic_at_yield_.assign(static_cast<std::size_t>(layout_.size()), std::numeric_limits<double>::quiet_NaN());
}

void ResponseMonitor::reset() {
  stats_.steps = stats_.substeps = stats_.guard_evaluations = stats_.grazing_checks = stats_.events =
      stats_.phases_factorised = 0;
  stats_.newton_steps = stats_.newton_iterations = 0;
  for (FloorResponse& f : stats_.floors) f = FloorResponse{};
  for (Peak& p : stats_.base_shear) p = Peak{};
  for (Peak& p : stats_.storey_shear) p = Peak{};
  for (GapResponse& g : stats_.gaps) g = GapResponse{};
  for (NeighbourResponse& nb : stats_.neighbours) nb = NeighbourResponse{nb.left_frame, nb.floor, nb.right_floor, nb.column};
}

void ResponseMonitor::observe(const KinematicState& x) {
  // At every accepted state: plain arrays.
  const double t = x.t, ground = x.ground;
  const double *u = x.u.data(), *v = x.v.data(), *acc = x.a.data();
  FloorResponse* floors = stats_.floors.data();
  for (int i = 0, n = layout_.size(); i < n; ++i) {
    FloorResponse& fr = floors[i];
    fr.displacement.update(u[i], t);
    fr.velocity.update(v[i], t);
    fr.acceleration.update(acc[i], t);
    fr.absolute_acceleration.update(acc[i] + ground, t);
    const int b = layout_.below(i);
    if (b >= 0) fr.drift.update(u[i] - u[b], t);  // a first storey's: statistics()
  }
  for (int f = 0; f < static_cast<int>(first_storey_.size()); ++f) {
    stats_.base_shear[static_cast<std::size_t>(f)].update(base_shear(x, f), t);
    stats_.storey_shear[static_cast<std::size_t>(f)].update(storey_shear(x, f), t);
  }
  with_facing(facing_at_floors_, [&](auto at_floors) {
    for (std::size_t k = 0; k < stats_.neighbours.size(); ++k) {
      stats_.neighbours[k].update(approach(at_floors, x, facing_[k]), t);
    }
  });
}

void ResponseMonitor::observe_velocity_jumps(const Eigen::VectorXd& v_before, const Eigen::VectorXd& a_before,
                                             const KinematicState& x) {
  // A half-sine pulse of duration τ whose area is Δu̇ peaks at π Δu̇ / (2τ); it acts over the
  // impact's instant, on the acceleration the floor has on either side of it.
  constexpr double half_sine_peak = 1.5707963267948966;  // π/2
  const double t = x.t, ground = x.ground;
  FloorResponse* floors = stats_.floors.data();
  for (Eigen::Index i = 0; i < x.v.size(); ++i) {
    const double jump = x.v(i) - v_before(i);
    if (jump == 0.0) continue;
    FloorResponse& fr = floors[i];
    fr.velocity_jump.update(jump, t);
    if (!(impact_duration_ > 0)) continue;
    const double pulse = half_sine_peak * jump / impact_duration_;
    for (const double a : {a_before(i), x.a(i)}) {
      fr.impact_acceleration.update(a + pulse, t);
      fr.impact_absolute_acceleration.update(a + ground + pulse, t);
    }
  }
}

void ResponseMonitor::observe_event(std::size_t p, EventKind kind, double closing_velocity, double impulse,
                                    double t) {
  ++stats_.events;
  GapResponse& gr = stats_.gaps[p];
  switch (kind) {
    case EventKind::contact:
      ++gr.contacts;
      contact_start_[p] = t;
      contact_closing_[p] = closing_velocity;
      break;
    case EventKind::separation: {
      ++gr.separations;
      // A contact that began while this monitor watched (or before a reset) ends here.
      if (!std::isnan(contact_start_[p])) {
        ++gr.completed_contacts;
        gr.longest_contact.update(t - contact_start_[p], t);
        if (contact_closing_[p] > 0) {
          const double e = -closing_velocity / contact_closing_[p];
          ++gr.restitution_samples;
          gr.restitution_sum += e;
          gr.min_restitution = std::min(gr.min_restitution, e);
          gr.max_restitution = std::max(gr.max_restitution, e);
        }
      }
      contact_start_[p] = std::numeric_limits<double>::quiet_NaN();
      break;
    }
    case EventKind::impact:
      ++gr.impacts;
      gr.impact_velocity.update(closing_velocity, t);
      gr.impulse.update(impulse, t);
      break;
    case EventKind::lock:
      ++gr.locks;
      gr.impulse.update(impulse, t);
      break;
    case EventKind::unlock: ++gr.unlocks; break;
    case EventKind::yield:
    case EventKind::unload: break;  // a storey's (observe_storey_event)
  }
}

void ResponseMonitor::observe_step(const KinematicState& a, const KinematicState& b) {
  const double t0 = a.t, h = b.t - t0;
  if (!(h > 0)) return;
  const auto refine = [&](Peak& peak, double q0, double r0, double q1, double r1) {
    if (!(r0 * r1 < 0)) return;
    const detail::HermiteCubic cubic(q0, r0, q1, r1, h);
    for (const double theta : cubic.critical_points()) {
      if (theta > 0 && theta < 1) peak.update(cubic(theta), t0 + theta * h);
    }
  };
  const double *ua = a.u.data(), *va = a.v.data(), *ub = b.u.data(), *vb = b.v.data();
  FloorResponse* floors = stats_.floors.data();
  for (int i = 0, n = layout_.size(); i < n; ++i) {
    FloorResponse& fr = floors[i];
    refine(fr.displacement, ua[i], va[i], ub[i], vb[i]);
    const int below = layout_.below(i);
    if (below >= 0) refine(fr.drift, ua[i] - ua[below], va[i] - va[below], ub[i] - ub[below], vb[i] - vb[below]);
  }
  with_facing(facing_at_floors_, [&](auto at_floors) {
    for (std::size_t k = 0; k < stats_.neighbours.size(); ++k) {
      // A signed maximum: where u_L − u_R stops growing inside the step.
      const double r0 = approach_rate(at_floors, a, facing_[k]), r1 = approach_rate(at_floors, b, facing_[k]);
      if (!(r0 > 0 && r1 < 0)) continue;
      const detail::HermiteCubic cubic(approach(at_floors, a, facing_[k]), r0, approach(at_floors, b, facing_[k]), r1, h);
      for (const double theta : cubic.critical_points()) {
        if (theta > 0 && theta < 1) stats_.neighbours[k].update(cubic(theta), t0 + theta * h);
      }
    }
  });
  for (std::size_t f = 0; f < first_storey_.size(); ++f) {
    const int d = first_storey_dofs_[f];
    const LinearForm& storey = first_storey_[f];
    const double k = storey.stiffness, c = storey.damping, f0 = storey.force_at_zero;
    refine(stats_.base_shear[f], k * a.u(d) + f0, k * a.v(d), k * b.u(d) + f0, k * b.v(d));
    // The shear's rate, k u̇ + c ü, has no f₀.
    refine(stats_.storey_shear[f], storey.force(a.u(d), a.v(d)), k * a.v(d) + c * a.a(d), storey.force(b.u(d), b.v(d)),
           k * b.v(d) + c * b.a(d));
  }
}

void ResponseMonitor::observe_step(const KinematicState& from, const KinematicState& to, double origin,
                                   DenseOutput& trajectory) {
  // Extrema of a floor displacement (and of the base shear k u₁) or of a drift between samples
  // lie where its rate changes sign: find that instant on the trajectory.
  const double t0 = origin;
  // `needs_acceleration`: the rate reads ü (the storey shear's); the others read u̇ alone, which
  // the trajectory gives for half the work. The rate changes sign once in [a, b]: the Illinois
  // method (bracketed_roots.hpp) finds where to the 1e-12 of the time the bisection it replaced
  // went to, in ~7 evaluations of the trajectory instead of ~40. node_ is left at the root found
  // (the peaks read u, u̇ and t, which motion_at and state_at give alike).
  const auto extremum = [&](auto rate, double a, double b, double ra, double rb, bool needs_acceleration) {
    int evaluations = 0;
    const double x = detail::illinois_root(
        [&](double s) {
          if (needs_acceleration) {
            trajectory.state_at(s, node_);
          } else {
            trajectory.motion_at(s, node_);
          }
          return rate(node_);
        },
        a, b, ra, rb, 1e-12 * std::max(1.0, b + t0), evaluations);
    if (evaluations == 0) trajectory.motion_at(x, node_);
  };
  const double a = from.t - t0, b = to.t - t0;
  for (std::size_t k = 0; k < stats_.neighbours.size(); ++k) {
    const FacingPoints& points = facing_[k];
    const auto rate = [&points](const KinematicState& x) { return approach_rate(std::false_type{}, x, points); };
    const double ra = rate(from), rb = rate(to);
    if (!(ra > 0 && rb < 0)) continue;
    extremum(rate, a, b, ra, rb, false);
    stats_.neighbours[k].update(approach(std::false_type{}, node_, points), node_.t);
  }
  for (int i = 0; i < layout_.size(); ++i) {
    FloorResponse& fr = stats_.floors[static_cast<std::size_t>(i)];
    const double va = from.v(i), vb = to.v(i);
    const bool first = layout_.floor_of(i) == 0;
    const auto f = static_cast<std::size_t>(layout_.frame_of(i));
    if (va * vb < 0) {
      extremum([i](const KinematicState& x) { return x.v(i); }, a, b, va, vb, false);
      fr.displacement.update(node_.u(i), node_.t);
      if (first) stats_.base_shear[f].update(base_shear(node_, static_cast<int>(f)), node_.t);
    }
    if (first) {
      const double k = first_storey_[f].stiffness, c = first_storey_[f].damping;
      const double sa = k * va + c * from.a(i), sb = k * vb + c * to.a(i);
      if (sa * sb < 0) {
        extremum([i, k, c](const KinematicState& x) { return k * x.v(i) + c * x.a(i); }, a, b, sa, sb, true);
        stats_.storey_shear[f].update(storey_shear(node_, static_cast<int>(f)), node_.t);
      }
    }
    const int below = layout_.below(i);
    if (below < 0) continue;
    const double da = va - from.v(below), db = vb - to.v(below);
    if (da * db < 0) {
      extremum([i, below](const KinematicState& x) { return x.v(i) - x.v(below); }, a, b, da, db, false);
      fr.drift.update(node_.u(i) - node_.u(below), node_.t);
    }
  }
}

}  // namespace poundsim
