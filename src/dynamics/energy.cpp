#include "poundsim/dynamics/energy.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "poundsim/dynamics/link_kinematics.hpp"

namespace poundsim {

namespace {

template <class L>
LinkMode mode_in(const L& link, const ContactConfiguration& config) {
  return link.element < 0 ? LinkMode{0} : config[static_cast<std::size_t>(link.element)];
}

/// The balance term of a law's energy group: storeys or gap elements.
double& term(EnergyGroup group, double& storey, double& gap_element) {
  return group == EnergyGroup::storey ? storey : gap_element;
}

}  // namespace

EnergyMeter::EnergyMeter(const Model& model, const DofLayout& layout)
    : links_(make_links(model, layout)), element_dissipation_(static_cast<std::size_t>(model.gap_count()), 0.0) {
  const int n = layout.size();
  storey_hysteretic_.assign(static_cast<std::size_t>(n), 0.0);
  links_.for_each_law([&](auto links) {
    using L = std::decay_t<decltype(links.front().law)>;
    if constexpr (YieldingLaw<L>) has_plastic_work_ = has_plastic_work_ || !links.empty();
  });
  mass_.resize(n);
  for (int i = 0; i < n; ++i) mass_(i) = model.frames[layout.frame_of(i)].mass[layout.floor_of(i)];
  Eigen::Index tallest = 0;
  for (int f = 0; f < model.frame_count(); ++f) {
    const Frame& frame = model.frames[static_cast<std::size_t>(f)];
    if (!has_frame_damping(frame)) continue;
    FrameDashpots d{.dofs = {}, .damping = frame_damping_matrix(frame)};
    for (int i = 0; i < frame.storeys(); ++i) d.dofs.push_back(layout.dof(f, i));
    tallest = std::max<Eigen::Index>(tallest, frame.storeys());
    frame_dashpots_.push_back(std::move(d));
  }
  frame_velocity_.resize(tallest);
  frame_force_.resize(tallest);
}

double EnergyMeter::frame_damping_power(const Eigen::VectorXd& v0, const Eigen::VectorXd& v1) const {
  double power = 0.0;
  for (const FrameDashpots& d : frame_dashpots_) {
    const auto n = static_cast<Eigen::Index>(d.dofs.size());
    auto w = frame_velocity_.head(n);
    auto cw = frame_force_.head(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto dof = d.dofs[static_cast<std::size_t>(i)];
      w(i) = 0.5 * (v0(dof) + v1(dof));
    }
    cw.noalias() = d.damping * w;
    power += w.dot(cw);
  }
  return power;
}

double EnergyMeter::kinetic_energy(const Eigen::VectorXd& v) const {
  return 0.5 * v.cwiseAbs2().dot(mass_);
}

void EnergyMeter::update_stored(const KinematicState& x, const ContactConfiguration& config,
                                const LinkStates& states) {
  balance_.kinetic = kinetic_energy(x.v);
  double storey = 0.0, gap = 0.0;
  links_.for_each_law([&](auto links) {
    if (links.empty()) return;
    double sum = 0.0;  // in a register: one law's links, in link order
    for (const auto& link : links) {
      sum += link.law.stored_energy(detail::kinematics<detail::Derivatives::velocities>(x, link), mode_in(link, config),
                                    states.at(link));
    }
    term(links.front().law.traits.energy, storey, gap) += sum;
  });
  balance_.storey_strain = storey;
  balance_.gap_strain = gap;
}

void EnergyMeter::start(const KinematicState& x, const ContactConfiguration& config,
                        const LinkStates& states) {
  balance_ = EnergyBalance{};
  std::fill(element_dissipation_.begin(), element_dissipation_.end(), 0.0);
  std::fill(storey_hysteretic_.begin(), storey_hysteretic_.end(), 0.0);
  per_element_ = true;
  update_stored(x, config, states);
  balance_.initial = balance_.kinetic + balance_.storey_strain + balance_.gap_strain;
  scale_ = std::abs(balance_.initial);
  max_residual_ = 0.0;
}

void EnergyMeter::step(const KinematicState& x0, const KinematicState& x1,
                       const ContactConfiguration& config, const LinkStates& states) {
  const double h = x1.t - x0.t;
  // Trapezoidal work of the ground motion: −Δuᵀ M 1 (a_g0 + a_g1)/2.
  balance_.input -= 0.5 * (x0.ground + x1.ground) * (x1.u - x0.u).dot(mass_);
  // One pass over the links for the powers and the energies stored at x1, each summed law by
  // law in link order as update_stored sums them (the states are not changed before the step
  // ends: the same operations, hence the same bits, for one kinematics and one loop less).
  double storey = 0.0, gap = 0.0, storey_stored = 0.0, gap_stored = 0.0;
  links_.for_each_law([&](auto links) {
    if (links.empty()) return;
    double sum = 0.0, stored = 0.0;
    for (const auto& link : links) {
      const LinkKinematics k1 = detail::kinematics<detail::Derivatives::velocities>(x1, link);
      const LinkMode mode = mode_in(link, config);
      const auto& state = states.at(link);
      const double power =
          link.law.trapezoidal_power(detail::kinematics<detail::Derivatives::velocities>(x0, link), k1, mode, state);
      sum += power;
      stored += link.law.stored_energy(k1, mode, state);
      if constexpr (ContactLaw<std::decay_t<decltype(link.law)>>) {
        element_dissipation_[static_cast<std::size_t>(link.element)] += h * power;
      }
    }
    term(links.front().law.traits.energy, storey, gap) += sum;
    term(links.front().law.traits.energy, storey_stored, gap_stored) += stored;
  });
  // Dashpots that are not links: the trapezoidal rule on their power, as the links' dashpots
  // (c ū̇² with the mean velocity).
  if (!frame_dashpots_.empty()) storey += frame_damping_power(x0.v, x1.v);
  balance_.storey_damping += h * storey;
  balance_.gap_damping += h * gap;
  add_relaxation(x0, x1, config, states);
  add_plastic_work(x0, x1, config, states);
  balance_.kinetic = kinetic_energy(x1.v);
  balance_.storey_strain = storey_stored;
  balance_.gap_strain = gap_stored;
  track_residual();
}

EnergyMeter::Powers EnergyMeter::powers(const KinematicState& x, const ContactConfiguration& config,
                                        const LinkStates& states) const {
  Powers p;
  p.input = -x.ground * x.v.dot(mass_);
  links_.for_each_law([&](auto links) {
    if (links.empty()) return;
    double sum = 0.0;
    for (const auto& link : links) {
      sum += link.law.dissipated_power(detail::kinematics<detail::Derivatives::velocities>(x, link), mode_in(link, config), states.at(link));
    }
    term(links.front().law.traits.energy, p.storey_damping, p.gap_damping) += sum;
  });
  if (!frame_dashpots_.empty()) p.storey_damping += frame_damping_power(x.v, x.v);
  return p;
}

PowerForms EnergyMeter::power_forms(const ContactConfiguration& config,
                                    std::span<const int> group_of, Eigen::Index groups) const {
  PowerForms forms{.storey_damping = Eigen::MatrixXd::Zero(groups, groups),
                   .gap_damping = Eigen::MatrixXd::Zero(groups, groups),
                   .mass = Eigen::VectorXd::Zero(groups)};
  const auto g = [&](int dof) { return static_cast<Eigen::Index>(group_of[static_cast<std::size_t>(dof)]); };
  // c ḋ² with ḋ = nᵀu̇ = nᵀT q̇ adds c n_i n_j to the groups of terms i and j (c to (a,a) and (b,b),
  // −c to (a,b) and (b,a) for a link between floors); floors of one group cancel.
  const auto add = [&](Eigen::MatrixXd& form, const LinkDofs& dofs, double c) {
    const auto terms = dofs.terms();
    for (const DofTerm& t : terms) form(g(t.dof), g(t.dof)) += c * (t.coefficient * t.coefficient);
    for (std::size_t i = 0; i < terms.size(); ++i) {
      for (std::size_t j = i + 1; j < terms.size(); ++j) {
        const double cij = c * (terms[i].coefficient * terms[j].coefficient);
        form(g(terms[i].dof), g(terms[j].dof)) += cij;
        form(g(terms[j].dof), g(terms[i].dof)) += cij;
      }
    }
  };
  for (Eigen::Index i = 0; i < mass_.size(); ++i) forms.mass(g(static_cast<int>(i))) += mass_(i);
  links_.for_each_law([&](auto links) {
    for (const auto& link : links) {
      const std::optional<LinearForm> form = link.law.linear_form(mode_in(link, config));
      if (!form) continue;  // transmits nothing
      Eigen::MatrixXd& target = link.law.traits.energy == EnergyGroup::storey
                                    ? forms.storey_damping
                                    : forms.gap_damping;
      add(target, link_dofs(link), form->damping);
    }
  });
  for (const FrameDashpots& d : frame_dashpots_) {
    for (std::size_t i = 0; i < d.dofs.size(); ++i) {
      for (std::size_t j = 0; j < d.dofs.size(); ++j) {
        forms.storey_damping(g(d.dofs[i]), g(d.dofs[j])) += d.damping(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      }
    }
  }
  return forms;
}

void EnergyMeter::step_with(const KinematicState& x0, const KinematicState& x1,
                            const Powers& integrals, const ContactConfiguration& config,
                            const LinkStates& states) {
  balance_.input += integrals.input;
  balance_.storey_damping += integrals.storey_damping;
  balance_.gap_damping += integrals.gap_damping;
  per_element_ = false;
  add_relaxation(x0, x1, config, states);
  add_plastic_work(x0, x1, config, states);
  finish_step(x1, config, states);
}

void EnergyMeter::add_plastic_work(const KinematicState& x0, const KinematicState& x1,
                                   const ContactConfiguration& config, const LinkStates& states) {
  if (!has_plastic_work_) return;
  links_.for_each_law([&](auto links) {
    using L = std::decay_t<decltype(links.front().law)>;
    if constexpr (YieldingLaw<L>) {
      double sum = 0.0;
      for (const auto& link : links) {
        const double work = link.law.plastic_work(detail::kinematics<detail::Derivatives::velocities>(x0, link), detail::kinematics<detail::Derivatives::velocities>(x1, link),
                                                  mode_in(link, config), states.at(link));
        if constexpr (ContactLaw<L>) {
          // A gap element's hysteresis is its own dissipation, not a storey's.
          element_dissipation_[static_cast<std::size_t>(link.element)] += work;
        } else {
          storey_hysteretic_[static_cast<std::size_t>(link.a)] += work;
        }
        sum += work;
      }
      term(L::traits.energy, balance_.storey_hysteretic, balance_.gap_damping) += sum;
    }
  });
}

void EnergyMeter::add_relaxation(const KinematicState& x0, const KinematicState& x1,
                                 const ContactConfiguration& config,
                                 const LinkStates& states) {
  // A relaxing element dissipates exactly what its spring releases.
  links_.for_each_law([&](auto links) {
    for (const auto& link : links) {
      const double released = link.law.relaxation_release(
          mode_in(link, config), states.at(link), x0.t, x1.t);
      if (released == 0.0) continue;
      term(link.law.traits.energy, balance_.storey_damping, balance_.gap_damping) += released;
      if constexpr (ContactLaw<std::decay_t<decltype(link.law)>>) {
        element_dissipation_[static_cast<std::size_t>(link.element)] += released;
      }
    }
  });
}

void EnergyMeter::finish_step(const KinematicState& x1, const ContactConfiguration& config,
                              const LinkStates& states) {
  update_stored(x1, config, states);
  track_residual();
}

void EnergyMeter::track_residual() {
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
