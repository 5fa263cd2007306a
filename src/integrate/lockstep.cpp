#include "poundsim/integrate/lockstep.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "poundsim/error.hpp"
#include "poundsim/integrate/newmark.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "poundsim/model/laws/paper_gap.hpp"

#include "steppers.hpp"  // detail::may_graze

// Before a pass over the lanes whose iterations touch only their own lane's entries: tells the
// compiler they do not alias, which it cannot prove through strided pointers (step_rows).
#if defined(__clang__)
#define POUNDSIM_LANES_ARE_INDEPENDENT _Pragma("clang loop vectorize(assume_safety)")
#else
#define POUNDSIM_LANES_ARE_INDEPENDENT _Pragma("GCC ivdep")
#endif

namespace poundsim {

namespace {
constexpr int kLanes = Lockstep::kLanes;
constexpr auto kWidth = static_cast<std::size_t>(kLanes);
}  // namespace

/// The lanes' states, constants and guards as arrays over the lanes: entry i of lane l at
/// [i·kLanes + l]. Every lean lane of a batch has the same numbers of DOFs, gap elements and
/// frames (its shape, set by the first lane gathered). The phase's bands are stored at the widest
/// width (Bands::kMaxWidth), zero outside each lane's own; a step runs at the widest band among
/// the lanes gathered since the call began (width_): a narrower lane's extra terms are products
/// with zeros, and adding ±0 changes no sum here (docs/numerics.md, "the step in dense bands": no
/// sum is −0), so each lane's row is its own step's to the bit — but for an acceleration that
/// underflows to −0, whose sign the padded backward pass drops (docs/numerics.md).
class Lockstep::Batch {
 public:
  /// Whether `s`'s next grid step can be lean (lockstep.hpp), and `s` has the batch's shape.
  [[nodiscard]] bool eligible(const Simulator& s) const;
  /// Takes lane l's state, phase and guards from `s` into the arrays (eligible(s) first).
  void gather(int lane, Simulator& s);
  /// Writes lane l back into its simulator: the state, the guards, the time in contact and the
  /// steps it took.
  void scatter(int lane, Simulator& s);
  /// One lean step of every lean lane; a lane whose step is refused (a guard fired or may graze,
  /// a value is not finite) leaves the lean lanes, its state that of the step's start.
  void step_lean();

  [[nodiscard]] bool lean(int lane) const { return lean_[static_cast<std::size_t>(lane)]; }
  [[nodiscard]] bool any_lean() const {
    for (const bool b : lean_) {
      if (b) return true;
    }
    return false;
  }
  /// Lane l's lean step was refused by the last step_lean() (scatter() clears it).
  [[nodiscard]] bool refused(int lane) const { return refused_[static_cast<std::size_t>(lane)]; }
  /// Forgets the lanes, the shape and the width (the next lane gathered sets them): when every
  /// lane has been written back.
  void reset_shape() {
    shaped_ = false;
    width_ = 0;
    lean_ = {};
    refused_ = {};
    sims_ = {};
  }
  std::int64_t lean_steps = 0;

 private:
  static constexpr int kMaxBand = LinearPhase::Bands::kMaxWidth;
  static constexpr auto kPad = static_cast<std::size_t>(kMaxBand);
  static constexpr auto kRowMax = static_cast<std::size_t>(2 * kMaxBand + 1);
  void set_shape(const Simulator& s);
  template <int B>
  void step_rows();

  bool shaped_ = false;
  int dofs_ = 0, gaps_ = 0, frames_ = 0;
  int width_ = 0;  ///< the band the step runs at
  std::array<bool, kWidth> lean_{}, refused_{};
  std::array<Simulator*, kWidth> sims_{};
  std::array<std::int64_t, kWidth> taken_{}, index_{};
  // Per lane.
  std::array<double, kWidth> t_{}, ground_{}, dt_{}, half_{}, quarter_sq_{}, origin_{}, t_end_{}, ground_end_{};
  std::array<SeparationCriterion, kWidth> separation_{};
  // Per DOF and lane: the state at the step's start and end, the phase's mass, load and D⁻¹.
  std::vector<double> u_, v_, a_, u_end_, v_end_, a_end_, mass_, load_, inverse_d_;
  // The bands: per DOF kRowMax entries (r, r − kMaxBand … r + kMaxBand) of C and K; L's columns
  // −kMaxBand … n − 1, kMaxBand entries each (rows i + 1 …); −w1, −w2, y and x padded by
  // kMaxBand DOFs each side (the pads zero, never written).
  std::vector<double> damping_, stiffness_, lower_, minus_w1_, minus_w2_, y_, x_;
  // Per guard (2 a gap element) and lane: values and rates at the step's start and end.
  std::vector<double> g_lo_, rate_lo_, g_hi_, rate_hi_;
  // Per gap element and lane. Copies, not pointers: a lane's law and its State stay as they were
  // while it is lean (only events change them), and a lane not lean reads its stale copy, never
  // a simulator that may be gone.
  std::vector<PaperGap> law_;
  std::vector<PaperGap::State> law_state_;
  std::vector<LinkMode> mode_;
  std::vector<int> floor_a_, floor_b_, element_;
  std::vector<char> transmits_;
  std::vector<double> bias_, reaction_, reaction_noise_, contact_time_;
  // Per frame and lane: the first storey's DOF and linear form (ResponseMonitor::storey_shear).
  std::vector<int> first_dof_;
  std::vector<LinearForm> first_form_;
};

bool Lockstep::Batch::eligible(const Simulator& s) const {
  if (s.failure_ || s.options_.integrator != Integrator::newmark || s.recording_ || s.metering_ || s.tracking_) {
    return false;
  }
  const PoundingSystem& system = s.system_;
  if (system.has_committing_laws() || !s.smooth_first_storeys_.empty()) return false;
  if (system.tracked_count() != system.gap_count()) return false;  // a yielding storey's events
  if (shaped_ && (system.layout().size() != dofs_ || system.gap_count() != gaps_ ||
                  system.model().frame_count() != frames_)) {
    return false;
  }
  const LinearPhase& phase = *s.phase_;
  // Locked links: their guards are the stop reactions, which the kernel does not compute.
  if (!phase.is_unreduced() || phase.has_smooth_links()) return false;
  try {
    if (phase.bands_for(phase.step_solver()) == nullptr) return false;  // wide bands
  } catch (const SimulationError&) {
    return false;  // the simulator's own step fails the same way, and says so
  }
  for (const Link& link : system.tracked_links()) {
    if (!std::holds_alternative<PaperGap>(link.law) || !link.joins_floors() || link.b < 0) return false;
    if (s.contact_.rigid[static_cast<std::size_t>(link.element)] != 0) return false;
  }
  return true;
}

void Lockstep::Batch::set_shape(const Simulator& s) {
  dofs_ = s.system_.layout().size();
  gaps_ = s.system_.gap_count();
  frames_ = s.system_.model().frame_count();
  const auto n = static_cast<std::size_t>(dofs_);
  const auto per_lane = [](std::size_t count) { return count * kWidth; };
  for (auto* x : {&u_, &v_, &a_, &u_end_, &v_end_, &a_end_, &mass_, &load_, &inverse_d_}) x->assign(per_lane(n), 0.0);
  for (auto* x : {&damping_, &stiffness_}) x->assign(per_lane(n * kRowMax), 0.0);
  lower_.assign(per_lane((n + kPad) * kPad), 0.0);
  for (auto* x : {&minus_w1_, &minus_w2_, &y_, &x_}) x->assign(per_lane(n + 2 * kPad), 0.0);
  const auto guards = static_cast<std::size_t>(2 * gaps_), gaps = static_cast<std::size_t>(gaps_);
  for (auto* x : {&g_lo_, &rate_lo_, &g_hi_, &rate_hi_}) x->assign(per_lane(guards), 0.0);
  law_.assign(per_lane(gaps), PaperGap{});
  law_state_.assign(per_lane(gaps), PaperGap::State{});
  mode_.assign(per_lane(gaps), LinkMode{});
  for (auto* x : {&floor_a_, &floor_b_, &element_}) x->assign(per_lane(gaps), 0);
  transmits_.assign(per_lane(gaps), 0);
  for (auto* x : {&bias_, &reaction_, &reaction_noise_, &contact_time_}) x->assign(per_lane(gaps), 0.0);
  first_dof_.assign(per_lane(static_cast<std::size_t>(frames_)), 0);
  first_form_.assign(per_lane(static_cast<std::size_t>(frames_)), LinearForm{});
  shaped_ = true;
}

void Lockstep::Batch::gather(int lane, Simulator& s) {
  if (!shaped_) set_shape(s);
  const auto l = static_cast<std::size_t>(lane);
  sims_[l] = &s;
  lean_[l] = true;
  refused_[l] = false;
  taken_[l] = 0;
  const KinematicState& x = s.state_;
  const LinearPhase& phase = *s.phase_;
  const LinearPhase::Bands& bands = *phase.bands_for(phase.step_solver());
  width_ = std::max(width_, bands.width);
  const double tau = s.options_.dt;
  t_[l] = x.t;
  ground_[l] = x.ground;
  dt_[l] = tau;
  half_[l] = 0.5 * tau;  // as NewmarkIntegrator::step_banded computes them
  quarter_sq_[l] = 0.25 * tau * tau;
  origin_[l] = s.grid_origin_;
  index_[l] = s.grid_index_;
  separation_[l] = s.options_.separation;
  const auto n = static_cast<std::size_t>(dofs_);
  const auto b = static_cast<std::size_t>(bands.width);
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = r * kWidth + l;
    const auto dof = static_cast<Eigen::Index>(r);
    u_[i] = x.u(dof);
    v_[i] = x.v(dof);
    a_[i] = x.a(dof);
    mass_[i] = phase.mass()(dof);
    load_[i] = phase.constant_load()(dof);
    inverse_d_[i] = bands.inverse_diagonal[r];
    // Entry (r, r + d) at kMaxBand + d; the lane's own band holds |d| ≤ b.
    for (std::size_t e = 0; e < kRowMax; ++e) {
      const bool inside = e + b >= kPad && e <= kPad + b;
      const std::size_t own = r * (2 * b + 1) + (e + b - kPad);
      damping_[(r * kRowMax + e) * kWidth + l] = inside ? bands.damping[own] : 0.0;
      stiffness_[(r * kRowMax + e) * kWidth + l] = inside ? bands.stiffness[own] : 0.0;
    }
  }
  // L's column i (−kMaxBand … n − 1): rows i + 1 … i + b from the phase's bands (column i at
  // (i + b)·b there), zeros beyond.
  for (std::size_t column = 0; column < n + kPad; ++column) {
    const auto i = static_cast<std::ptrdiff_t>(column) - static_cast<std::ptrdiff_t>(kPad);
    for (std::size_t e = 0; e < kPad; ++e) {
      double value = 0.0;
      if (e < b && i >= 0) value = bands.lower[(static_cast<std::size_t>(i) + b) * b + e];
      lower_[(column * kPad + e) * kWidth + l] = value;
    }
  }
  for (std::size_t j = 0; j < 2 * static_cast<std::size_t>(gaps_); ++j) {
    g_lo_[j * kWidth + l] = s.guards_.lo[j];
    rate_lo_[j * kWidth + l] = s.guards_.rate_lo[j];
  }
  const std::span<const Link> links = s.system_.tracked_links();
  for (std::size_t p = 0; p < links.size(); ++p) {
    const Link& link = links[p];
    const auto e = static_cast<std::size_t>(link.element);
    const PaperGap& law = std::get<PaperGap>(link.law);
    const std::size_t i = p * kWidth + l;
    law_[i] = law;
    law_state_[i] = s.contact_.states.at(law, link.slot);
    mode_[i] = s.contact_.config[e];
    floor_a_[i] = link.a;
    floor_b_[i] = link.b;
    element_[i] = link.element;
    transmits_[i] = s.contact_.transmits[e];
    bias_[i] = s.contact_.bias[e];
    reaction_[i] = s.contact_.stop_reaction[e];
    reaction_noise_[i] = s.contact_.stop_noise[e];
    contact_time_[i] = s.monitor_.counts().gaps[e].contact_time;
  }
  for (int f = 0; f < frames_; ++f) {
    const std::size_t i = static_cast<std::size_t>(f) * kWidth + l;
    first_dof_[i] = s.monitor_.first_storey_dof(f);
    first_form_[i] = s.monitor_.first_storey_form(f);
  }
}

void Lockstep::Batch::scatter(int lane, Simulator& s) {
  const auto l = static_cast<std::size_t>(lane);
  lean_[l] = false;
  refused_[l] = false;
  KinematicState& x = s.state_;
  for (std::size_t r = 0; r < static_cast<std::size_t>(dofs_); ++r) {
    const std::size_t i = r * kWidth + l;
    const auto dof = static_cast<Eigen::Index>(r);
    x.u(dof) = u_[i];
    x.v(dof) = v_[i];
    x.a(dof) = a_[i];
  }
  x.t = t_[l];
  x.ground = ground_[l];
  for (std::size_t j = 0; j < 2 * static_cast<std::size_t>(gaps_); ++j) {
    s.guards_.lo[j] = g_lo_[j * kWidth + l];
    s.guards_.rate_lo[j] = rate_lo_[j * kWidth + l];
  }
  // What Simulator::advance_to and Loop::after_accept count for each step; an accepted step
  // starts with no event (integrate_to).
  for (std::size_t p = 0; p < static_cast<std::size_t>(gaps_); ++p) {
    const std::size_t i = p * kWidth + l;
    s.monitor_.counts().gaps[static_cast<std::size_t>(element_[i])].contact_time = contact_time_[i];
  }
  s.grid_index_ = index_[l];
  s.monitor_.counts().steps += taken_[l];
  s.monitor_.counts().substeps += taken_[l];
  if (taken_[l] > 0) s.events_this_step_ = 0;
  lean_steps += taken_[l];
  taken_[l] = 0;
  sims_[l] = nullptr;
}

// Flattened: each law's guards(), the excitation's a_g and the rows are inlined into the loops
// over the lanes (libm's sine stays a call).
template <int B>
[[gnu::flatten]] void Lockstep::Batch::step_rows() {
  // Plain pointers, restrict: stores into the arrays cannot change the vectors' own pointers, and
  // the passes over the lanes compile to straight-line (or vector) code. The passes of the rows
  // are marked POUNDSIM_LANES_ARE_INDEPENDENT (GCC's `ivdep`): a lane reads and writes only its
  // own entries (r·S + l), which GCC cannot prove through the rows' strided pointers, and it left
  // these passes scalar (-fopt-info-vec: "complicated access pattern"). Vectorised across lanes,
  // each lane's operations stay in their order: the same bits (a Fig. 2c response, release:
  // 704 → 662 M instructions).
  constexpr std::ptrdiff_t S = kLanes;
  const auto n = static_cast<std::ptrdiff_t>(dofs_);
  const double* __restrict dt = dt_.data();
  const double* __restrict half = half_.data();
  const double* __restrict quarter_sq = quarter_sq_.data();
  const double* __restrict ground_end = ground_end_.data();
  const double* __restrict u = u_.data();
  const double* __restrict v = v_.data();
  const double* __restrict a = a_.data();
  const double* __restrict mass = mass_.data();
  const double* __restrict load = load_.data();
  const double* __restrict inverse_d = inverse_d_.data();
  double* __restrict u_end = u_end_.data();
  double* __restrict v_end = v_end_.data();
  double* __restrict a_end = a_end_.data();
  if constexpr (B == 0) {
    // No lane couples a DOF to another: each row's whole step in one pass (its step_banded<0>).
    const double* __restrict c = damping_.data() + kPad * kWidth;  // the diagonal entries
    const double* __restrict k = stiffness_.data() + kPad * kWidth;
    for (std::ptrdiff_t r = 0; r < n; ++r) {
      POUNDSIM_LANES_ARE_INDEPENDENT
      for (std::ptrdiff_t l = 0; l < S; ++l) {
        const std::ptrdiff_t i = r * S + l, row = r * static_cast<std::ptrdiff_t>(kRowMax) * S + l;
        const DiagonalRowStep end = newmark_diagonal_row(u[i], v[i], a[i], dt[l], half[l], quarter_sq[l], load[i],
                                                         ground_end[l], mass[i], c[row], k[row], inverse_d[i]);
        u_end[i] = end.u;
        v_end[i] = end.v;
        a_end[i] = end.a;
      }
    }
    return;
  }
  // step_banded<B>'s passes over the rows, every lane at once.
  double* __restrict minus_w1 = minus_w1_.data() + kPad * kWidth;
  double* __restrict minus_w2 = minus_w2_.data() + kPad * kWidth;
  double* __restrict y = y_.data() + kPad * kWidth;
  double* __restrict x = x_.data() + kPad * kWidth;
  for (std::ptrdiff_t r = 0; r < n; ++r) {
    for (std::ptrdiff_t l = 0; l < S; ++l) {
      const std::ptrdiff_t i = r * S + l;
      const NewmarkPredictors w = newmark_predictors(u[i], v[i], a[i], dt[l], half[l], quarter_sq[l]);
      minus_w1[i] = w.minus_w1;
      minus_w2[i] = w.minus_w2;
    }
  }
  // Row r's entries (r, r − B) … (r, r + B) start kMaxBand − B into its kRowMax; L's column 0 is
  // kMaxBand columns in.
  const double* __restrict c = damping_.data() + (kPad - static_cast<std::size_t>(B)) * kWidth;
  const double* __restrict k = stiffness_.data() + (kPad - static_cast<std::size_t>(B)) * kWidth;
  const double* __restrict lower = lower_.data() + kPad * kPad * kWidth;
  for (std::ptrdiff_t r = 0; r < n; ++r) {
    POUNDSIM_LANES_ARE_INDEPENDENT
    for (std::ptrdiff_t l = 0; l < S; ++l) {
      const std::ptrdiff_t i = r * S + l, row = r * static_cast<std::ptrdiff_t>(kRowMax) * S + l;
      y[i] = banded_forward_row<B, S, kMaxBand>(load[i], ground_end[l], mass[i], c + row, k + row, minus_w1 + l,
                                                minus_w2 + l, y + l, lower + l, r);
      x[i] = inverse_d[i] * y[i];
    }
  }
  for (std::ptrdiff_t r = n - 1; r >= 0; --r) {
    POUNDSIM_LANES_ARE_INDEPENDENT
    for (std::ptrdiff_t l = 0; l < S; ++l) {
      const std::ptrdiff_t i = r * S + l;
      x[i] = banded_backward_row<B, S, kMaxBand>(x + l, lower + l, r);
      const DiagonalRowStep end = newmark_end(minus_w2[i], v[i], a[i], half[l], quarter_sq[l], x[i]);
      u_end[i] = end.u;
      v_end[i] = end.v;
      a_end[i] = end.a;
    }
  }
}

[[gnu::flatten]] void Lockstep::Batch::step_lean() {
  const auto dofs = static_cast<std::size_t>(dofs_), guards = 2 * static_cast<std::size_t>(gaps_);
  const double* __restrict dt = dt_.data();
  double* __restrict t_end = t_end_.data();
  double* __restrict ground_end = ground_end_.data();
  double* __restrict u = u_.data();
  double* __restrict v = v_.data();
  double* __restrict a = a_.data();
  const double* __restrict u_end = u_end_.data();
  const double* __restrict v_end = v_end_.data();
  const double* __restrict a_end = a_end_.data();
  double* __restrict g_lo = g_lo_.data();
  double* __restrict rate_lo = rate_lo_.data();
  double* __restrict g_hi = g_hi_.data();
  double* __restrict rate_hi = rate_hi_.data();

  // The grid time and the ground's acceleration at the step's end, lane by lane: the
  // excitation's own function (Simulator::advance_to's next grid time; NewmarkStepper's trial
  // step asks a_g at the state's time + τ).
  for (std::size_t l = 0; l < kWidth; ++l) {
    t_end[l] = origin_[l] + static_cast<double>(index_[l] + 1) * dt[l];
    if (lean_[l]) ground_end[l] = sims_[l]->system_.ground_acceleration(t_[l] + dt[l]);
  }
  // Every lane steps from here to the choice of which steps are taken: the lanes not lean hold
  // stale finite values and copies of their laws, and nothing reads what they compute.
  switch (width_) {
    case 0: step_rows<0>(); break;
    case 1: step_rows<1>(); break;
    case 2: step_rows<2>(); break;
    case 3: step_rows<3>(); break;
    default: step_rows<4>(); break;
  }
  static_assert(kMaxBand == 4);
  // The guards at the step's end: each element's law and the system's entries, as
  // PoundingSystem::evaluate_guards writes them for an unreduced phase; and the forces of the
  // elements in contact, whose finiteness Loop::all_finite checks.
  alignas(64) std::array<double, kWidth> poison{};
  std::array<GuardValue, 2> values;
  for (std::size_t p = 0; p < static_cast<std::size_t>(gaps_); ++p) {
    for (std::size_t l = 0; l < kWidth; ++l) {
      const std::size_t i = p * kWidth + l;
      const auto fa = static_cast<std::size_t>(floor_a_[i]) * kWidth + l;
      const auto fb = static_cast<std::size_t>(floor_b_[i]) * kWidth + l;
      const LinkKinematics k{.ua = u_end[fa], .ub = u_end[fb], .va = v_end[fa], .vb = v_end[fb],
                             .aa = a_end[fa], .ab = a_end[fb], .t = t_end[l]};
      const GuardContext context{.separation = separation_[l], .reaction = reaction_[i],
                                 .reaction_noise = reaction_noise_[i]};
      law_[i].guards(k, mode_[i], law_state_[i], context, values);
      const auto j = 2 * static_cast<std::size_t>(element_[i]);
      PoundingSystem::guard_entry(values[0], bias_[i], g_hi[j * kWidth + l], rate_hi[j * kWidth + l]);
      PoundingSystem::guard_entry(values[1], bias_[i], g_hi[(j + 1) * kWidth + l], rate_hi[(j + 1) * kWidth + l]);
      if (transmits_[i] != 0) poison[l] += law_[i].force(k, mode_[i], law_state_[i]) * 0.0;
    }
  }
  // A guard that fired or may graze (NewmarkStepper's scan_guards), or a value that is not finite
  // (Loop::all_finite: x·0 is NaN exactly then), refuses a lane's step. Lane by lane in arrays:
  // passes of kLanes without branches.
  alignas(64) std::array<std::int64_t, kWidth> refuse{};
  for (std::size_t l = 0; l < kWidth; ++l) poison[l] += ground_end[l] * 0.0;
  for (std::size_t j = 0; j < guards; ++j) {
    const std::size_t o = j * kWidth;
    for (std::size_t l = 0; l < kWidth; ++l) {
      const double lo = g_lo[o + l], hi = g_hi[o + l];
      refuse[l] |= static_cast<std::int64_t>(hi > 0.0) |
                   static_cast<std::int64_t>(detail::may_graze(lo, hi, rate_lo[o + l], rate_hi[o + l]));
    }
  }
  for (std::size_t r = 0; r < dofs; ++r) {
    const std::size_t o = r * kWidth;
    for (std::size_t l = 0; l < kWidth; ++l) poison[l] += (u_end[o + l] * 0.0 + v_end[o + l] * 0.0) + a_end[o + l] * 0.0;
  }
  for (std::size_t f = 0; f < static_cast<std::size_t>(frames_); ++f) {
    const std::size_t o = f * kWidth;
    for (std::size_t l = 0; l < kWidth; ++l) {
      const std::size_t d = static_cast<std::size_t>(first_dof_[o + l]) * kWidth + l;
      const LinearForm& storey = first_form_[o + l];
      poison[l] += storey.force(u_end[d], v_end[d]) * 0.0;
    }
  }
  // The lean lanes whose step stands take it: its end becomes the start, and an element in
  // contact adds the step to its time in contact (Loop::after_accept: the end's time less the
  // start's).
  alignas(64) std::array<double, kWidth> take{};
  for (std::size_t l = 0; l < kWidth; ++l) {
    if (!lean_[l]) continue;
    if (refuse[l] != 0 || poison[l] != 0.0) {
      lean_[l] = false;
      refused_[l] = true;
      continue;
    }
    take[l] = 1.0;
    const double h = t_end[l] - t_[l];
    for (std::size_t p = 0; p < static_cast<std::size_t>(gaps_); ++p) {
      if (transmits_[p * kWidth + l] != 0) contact_time_[p * kWidth + l] += h;
    }
    t_[l] = t_end[l];
    ground_[l] = ground_end[l];
    ++index_[l];
    ++taken_[l];
  }
  for (std::size_t r = 0; r < dofs; ++r) {
    const std::size_t o = r * kWidth;
    for (std::size_t l = 0; l < kWidth; ++l) {
      const bool keep = take[l] != 0.0;
      u[o + l] = keep ? u_end[o + l] : u[o + l];
      v[o + l] = keep ? v_end[o + l] : v[o + l];
      a[o + l] = keep ? a_end[o + l] : a[o + l];
    }
  }
  for (std::size_t j = 0; j < guards; ++j) {
    const std::size_t o = j * kWidth;
    for (std::size_t l = 0; l < kWidth; ++l) {
      const bool keep = take[l] != 0.0;
      g_lo[o + l] = keep ? g_hi[o + l] : g_lo[o + l];
      rate_lo[o + l] = keep ? rate_hi[o + l] : rate_lo[o + l];
    }
  }
}

Lockstep::Lockstep() : batch_(std::make_unique<Batch>()) {}
Lockstep::~Lockstep() = default;

const Lockstep::Counts& Lockstep::counts() const { return counts_; }

void Lockstep::step(std::span<Simulator* const> lanes, int steps, std::span<std::exception_ptr> errors) {
  if (lanes.size() > kWidth) {
    throw std::invalid_argument(fmt::format("Lockstep::step: {} simulators, at most {}", lanes.size(), kLanes));
  }
  if (errors.size() != lanes.size()) {
    throw std::invalid_argument(fmt::format("Lockstep::step: {} errors for {} simulators", errors.size(), lanes.size()));
  }
  Batch& batch = *batch_;
  std::array<bool, kWidth> skipped{};
  batch.reset_shape();  // every lane was written back at the end of the last call
  // Whatever escapes (an allocation that fails while a lane is gathered), the lean lanes go back
  // to their simulators first: each is then where its own step()s would have left it.
  const auto write_back = [&] {
    for (std::size_t l = 0; l < lanes.size(); ++l) {
      const int lane = static_cast<int>(l);
      if (batch.lean(lane) || batch.refused(lane)) batch.scatter(lane, *lanes[l]);
    }
  };
  try {
    for (std::size_t l = 0; l < lanes.size(); ++l) {
      skipped[l] = lanes[l] == nullptr || errors[l] != nullptr;
      if (!skipped[l] && batch.eligible(*lanes[l])) batch.gather(static_cast<int>(l), *lanes[l]);
    }
    for (int s = 0; s < steps; ++s) {
      if (batch.any_lean()) batch.step_lean();
      for (std::size_t l = 0; l < lanes.size(); ++l) {
        const int lane = static_cast<int>(l);
        if (skipped[l] || batch.lean(lane)) continue;
        Simulator& sim = *lanes[l];
        if (batch.refused(lane)) {  // its simulator takes this step from the same state
          batch.scatter(lane, sim);
          ++counts_.refused;
        }
        try {
          sim.step();
        } catch (...) {
          errors[l] = std::current_exception();
          skipped[l] = true;
          continue;
        }
        ++counts_.general;
        // The batch's shape stays as it is within a call: a lane still to be written back (refused
        // beside this one) holds its state in the arrays.
        if (batch.eligible(sim)) batch.gather(lane, sim);
      }
    }
  } catch (...) {
    write_back();
    counts_.lean = batch.lean_steps;
    throw;
  }
  write_back();
  counts_.lean = batch.lean_steps;
}

}  // namespace poundsim
