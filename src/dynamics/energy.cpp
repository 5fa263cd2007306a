#include "poundsim/dynamics/energy.hpp"

#include <algorithm>
#include <cmath>

namespace poundsim {

EnergyMeter::EnergyMeter(const Model& model, const DofLayout& layout)
    : model_(&model), layout_(&layout) {
  const int n = layout.size();
  mass_.resize(n);
  storey_k_.resize(n);
  storey_c_.resize(n);
  below_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const Frame& f = model.frames[layout.frame_of(i)];
    const int floor = layout.floor_of(i);
    mass_(i) = f.mass[floor];
    storey_k_(i) = f.stiffness[floor];
    storey_c_(i) = f.damping[floor];
    below_[i] = layout.below(i);
  }
}

double EnergyMeter::kinetic_energy(const Eigen::VectorXd& v) const {
  return 0.5 * v.cwiseAbs2().dot(mass_);
}

void EnergyMeter::update_stored(const KinematicState& x, const ContactConfiguration& config,
                                std::span<const GapMemory> memory) {
  balance_.kinetic = kinetic_energy(x.v);
  double storey = 0.0;
  for (Eigen::Index i = 0; i < x.u.size(); ++i) {
    const int b = below_[static_cast<std::size_t>(i)];
    const double drift = x.u(i) - (b >= 0 ? x.u(b) : 0.0);
    storey += storey_k_(i) * drift * drift;
  }
  balance_.storey_strain = 0.5 * storey;
  double gap = 0.0;
  for (std::size_t p = 0; p < config.size(); ++p) {
    const GapProperties& g = model_->gaps[p].properties;
    if (config[p] == GapMode::open) {
      const double se = memory[p].free_end_shortening(x.t, g.stiffness, g.damping);
      gap += g.stiffness * se * se;
    } else {
      const double s = shortening(g, x.u(layout_->gap_left(p)), x.u(layout_->gap_right(p)));
      gap += g.stiffness * s * s;
    }
  }
  balance_.gap_strain = 0.5 * gap;
}

void EnergyMeter::start(const KinematicState& x, const ContactConfiguration& config,
                        std::span<const GapMemory> memory) {
  balance_ = EnergyBalance{};
  update_stored(x, config, memory);
  balance_.initial = balance_.kinetic + balance_.storey_strain + balance_.gap_strain;
  scale_ = std::abs(balance_.initial);
  max_residual_ = 0.0;
}

void EnergyMeter::step(const KinematicState& x0, const KinematicState& x1,
                       const ContactConfiguration& config, std::span<const GapMemory> memory) {
  const double h = x1.t - x0.t;
  // Trapezoidal work of the ground motion: −Δuᵀ M 1 (a_g0 + a_g1)/2.
  balance_.input -= 0.5 * (x0.ground + x1.ground) * (x1.u - x0.u).dot(mass_);
  double storey = 0.0;
  for (Eigen::Index i = 0; i < x1.u.size(); ++i) {
    const int b = below_[static_cast<std::size_t>(i)];
    const double rate = 0.5 * (x0.v(i) + x1.v(i) - (b >= 0 ? x0.v(b) + x1.v(b) : 0.0));
    storey += storey_c_(i) * rate * rate;
  }
  balance_.storey_damping += h * storey;
  double gap = 0.0;
  for (std::size_t p = 0; p < config.size(); ++p) {
    if (config[p] == GapMode::open) continue;
    const int l = layout_->gap_left(p), r = layout_->gap_right(p);
    const double rate = 0.5 * (x0.v(l) + x1.v(l) - x0.v(r) - x1.v(r));
    gap += model_->gaps[p].properties.damping * rate * rate;
  }
  balance_.gap_damping += h * gap;
  add_relaxation(x0, x1, config, memory);
  finish_step(x1, config, memory);
}

EnergyMeter::Powers EnergyMeter::powers(const KinematicState& x,
                                        const ContactConfiguration& config) const {
  Powers p;
  p.input = -x.ground * x.v.dot(mass_);
  for (Eigen::Index i = 0; i < x.v.size(); ++i) {
    const int b = below_[static_cast<std::size_t>(i)];
    const double rate = x.v(i) - (b >= 0 ? x.v(b) : 0.0);
    p.storey_damping += storey_c_(i) * rate * rate;
  }
  for (std::size_t e = 0; e < config.size(); ++e) {
    if (config[e] == GapMode::open) continue;
    const double rate = x.v(layout_->gap_left(e)) - x.v(layout_->gap_right(e));
    p.gap_damping += model_->gaps[e].properties.damping * rate * rate;
  }
  return p;
}

PowerForms EnergyMeter::power_forms(const ContactConfiguration& config,
                                    std::span<const int> group_of, Eigen::Index groups) const {
  PowerForms forms{.storey_damping = Eigen::MatrixXd::Zero(groups, groups),
                   .gap_damping = Eigen::MatrixXd::Zero(groups, groups),
                   .mass = Eigen::VectorXd::Zero(groups)};
  const auto g = [&](int dof) { return static_cast<Eigen::Index>(group_of[static_cast<std::size_t>(dof)]); };
  // c (u̇_a − u̇_b)² with u̇ = T q̇ adds c to (a,a) and (b,b) and −c to (a,b), (b,a) of the groups;
  // floors of one group cancel.
  const auto add = [](Eigen::MatrixXd& form, Eigen::Index a, Eigen::Index b, double c) {
    form(a, a) += c;
    if (b < 0) return;
    form(b, b) += c;
    form(a, b) -= c;
    form(b, a) -= c;
  };
  for (Eigen::Index i = 0; i < mass_.size(); ++i) {
    forms.mass(g(static_cast<int>(i))) += mass_(i);
    const int b = below_[static_cast<std::size_t>(i)];
    add(forms.storey_damping, g(static_cast<int>(i)), b >= 0 ? g(b) : -1, storey_c_(i));
  }
  for (std::size_t e = 0; e < config.size(); ++e) {
    if (config[e] == GapMode::open) continue;
    add(forms.gap_damping, g(layout_->gap_left(e)), g(layout_->gap_right(e)),
        model_->gaps[e].properties.damping);
  }
  return forms;
}

void EnergyMeter::step_with(const KinematicState& x0, const KinematicState& x1,
                            const Powers& integrals, const ContactConfiguration& config,
                            std::span<const GapMemory> memory) {
  balance_.input += integrals.input;
  balance_.storey_damping += integrals.storey_damping;
  balance_.gap_damping += integrals.gap_damping;
  add_relaxation(x0, x1, config, memory);
  finish_step(x1, config, memory);
}

void EnergyMeter::add_relaxation(const KinematicState& x0, const KinematicState& x1,
                                 const ContactConfiguration& config,
                                 std::span<const GapMemory> memory) {
  // A relaxing element dissipates exactly what its spring releases.
  for (std::size_t p = 0; p < config.size(); ++p) {
    if (config[p] != GapMode::open || memory[p].released_shortening == 0.0) continue;
    const GapProperties& g = model_->gaps[p].properties;
    const double s0 = memory[p].free_end_shortening(x0.t, g.stiffness, g.damping);
    const double s1 = memory[p].free_end_shortening(x1.t, g.stiffness, g.damping);
    balance_.gap_damping += 0.5 * g.stiffness * (s0 * s0 - s1 * s1);
  }
}

void EnergyMeter::finish_step(const KinematicState& x1, const ContactConfiguration& config,
                              std::span<const GapMemory> memory) {
  update_stored(x1, config, memory);
  // Not std::max: it drops a NaN in its second argument, and a NaN balance must not pass.
  for (const double x : {std::abs(balance_.supplied()), balance_.accounted()}) {
    if (!(x <= scale_)) scale_ = x;
  }
  const double residual = std::abs(balance_.residual());
  if (!(residual <= max_residual_)) max_residual_ = residual;
}

double EnergyMeter::relative_residual() const {
  return scale_ > 0.0 ? std::abs(balance_.residual()) / scale_ : 0.0;
}

}  // namespace poundsim
