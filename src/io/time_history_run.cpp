#include "poundsim/io/time_history_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <numbers>
#include <type_traits>

#include <fmt/format.h>

#include "poundsim/analysis/channels.hpp"
#include "poundsim/error.hpp"
#include "poundsim/io/json_fields.hpp"
#include "poundsim/io/output_files.hpp"
#include "poundsim/io/table.hpp"
#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/units.hpp"

namespace poundsim::io {

namespace {
using nlohmann::json;

json peak(const Peak& p) { return json{{"value", p.value}, {"time", p.time}}; }

/// a / b, or null when b is 0 (nothing to compare with).
json ratio(double a, double b) { return b > 0 ? json(a / b) : json(); }

/// Where a slab strikes its neighbour's column: the struck frame, the floors around the point
/// (0: the ground) and the weight of the floor above.
json struck_column_json(const ColumnStrike& c, int left_frame, int left_floor, int right_floor) {
  const bool left = c.struck == Side::left;
  const int above = (left ? left_floor : right_floor) + 1;
  return {{"frame", left_frame + (left ? 1 : 2)}, {"floors", {above - 1, above}}, {"weight_of_floor_above", c.weight}};
}

json describe_model(const RunInput& input) {
  json frames = json::array();
  for (const Frame& f : input.model.frames) {
    const Eigen::VectorXd w = natural_frequencies(f);
    json frame{{"name", f.name},
               {"storeys", f.storeys()},
               {"mass_kg", f.mass},
               {"stiffness_N_m", f.stiffness},
               {"damping_Ns_m", f.damping},
               {"weight_N", weight(f)},
               {"natural_frequencies_rad_s", std::vector<double>(w.begin(), w.end())}};
    // Damping besides the storey dashpots, and the ratio it gives each mode, when there is some.
    if (!f.ground_damping.empty()) frame["ground_damping_Ns_m"] = f.ground_damping;
    if (!f.modal_damping_ratios.empty()) frame["modal_damping_ratios"] = f.modal_damping_ratios;
    if (has_frame_damping(f)) {
      const Eigen::VectorXd zeta = modal_damping_ratios(f);
      frame["damping_ratio_of_each_mode"] = std::vector<double>(zeta.begin(), zeta.end());
    }
    // A storey law other than the linear one, with its parameters per storey.
    if (!is_default(f.storey_law)) frame["storey_law"] = key_of(f.storey_law);
    for_each_storey_parameter(f.storey_law, [&](const auto& field, const std::vector<double>& values) {
      frame[name_with_unit(field)] = values;
    });
    frames.push_back(std::move(frame));
  }
  json gaps = json::array();
  for (const GapElement& g : input.model.gaps) {
    json element{{"frames", {g.left_frame + 1, g.left_frame + 2}}, {"floor", g.floor + 1}};
    if (g.floor_right() != g.floor) element["right_floor"] = g.floor_right() + 1;
    if (g.column) element["struck_column"] = struck_column_json(*g.column, g.left_frame, g.floor, g.floor_right());
    std::visit(
        [&](const auto& law) {
          if (!is_default(g.law)) element["law"] = law.key;
          write_with_units(element, law.parameters);
          if constexpr (std::is_same_v<std::decay_t<decltype(law)>, Impact>) {
            // Muthukumar's derivation: the OpenSees parameters the run used.
            if (law.parameters.stiffness > 0.0) {
              element["derived"] = {{"k1_N_m", law.k1()}, {"k2_N_m", law.k2()},
                                    {"yield_penetration_m", law.yield_penetration()},
                                    {"target_dissipation_J", law.parameters.target_dissipation()}};
            }
          }
        },
        g.law);
    gaps.push_back(std::move(element));
  }
  json model{{"frames", frames}, {"gap_elements", gaps}};
  if (input.dimensionless) {
    const DimensionlessParameters& d = *input.dimensionless;
    model["dimensionless"] = fields_json(d);
  }
  return model;
}

json describe_excitation(const ExcitationInfo& info) {
  json e{{"kind", info.kind}, {"omega1_rad_s", info.omega1}};
  if (info.kind == "harmonic") {
    e["amplitude_g"] = info.amplitude_g;
    e["amplitude_m_s2"] = info.amplitude_g * standard_gravity;
    e["omega_rad_s"] = info.omega;
    e["frequency_hz"] = info.omega / (2 * std::numbers::pi);
    e["ratio"] = info.omega / info.omega1;
  } else if (info.kind == "record") {
    e["file"] = info.record_samples.empty() ? json(info.record_file.string()) : json();  // null: samples
    e["format"] = info.record_format;
    e["description"] = info.record_description;
    e["units"] = info.record_units;
    e["points"] = info.record_points;
    e["dt_s"] = info.record_dt;
    e["duration_s"] = info.record_duration;
    e["pga_file_g"] = info.record_pga_file_g;
    e["scale"] = info.record_scale;
    e["pga_g"] = info.record_pga_g;
  }
  return e;
}
}  // namespace


namespace {
/// Whether some frame's storeys follow a law other than the linear storey: their columns and
/// keys (storey forces, hysteretic energy) appear only then, so the outputs of linear frames
/// stay as they were.
bool has_inelastic_storeys(const Model& model) {
  for (const Frame& frame : model.frames) {
    if (!is_default(frame.storey_law)) return true;
  }
  return false;
}
}  // namespace

std::string dof_label(const DofLayout& layout, int dof) {
  return fmt::format("{}_{}", layout.frame_of(dof) + 1, layout.floor_of(dof) + 1);
}

int TimeHistoryResult::impacts() const {
  int n = 0;
  for (const GapResponse& g : statistics.gaps) n += g.impacts;
  return n;
}

double TimeHistoryResult::max_gap_force() const {
  double m = 0;
  for (const GapResponse& g : statistics.gaps) m = std::max(m, g.force.value);
  return m;
}

double TimeHistoryResult::max_impact_impulse() const {
  double m = 0;
  for (const GapResponse& g : statistics.gaps) m = std::max(m, g.impulse.value);
  return m;
}

std::optional<std::string> energy_warning(const TimeHistoryResult& r) {
  const DofLayout layout(r.model);
  bool smooth = false;
  for (const Link& link : make_links(r.model, layout)) smooth = smooth || link.traits().newton;
  return energy_balance_warning(r.max_relative_residual, r.options.integrator, smooth);
}

namespace {
/// Each frame's largest interstorey drift (by drift ratio when the frame has storey heights):
/// its storey, its ratio to the height, and the free frame's drift there.
std::string drift_lines(const TimeHistoryResult& r) {
  std::string text;
  for (int f = 0; f < r.model.frame_count(); ++f) {
    const Frame& frame = r.model.frames[static_cast<std::size_t>(f)];
    const auto height = [&](int i) { return frame.storey_height.empty() ? 1.0 : frame.storey_height[static_cast<std::size_t>(i)]; };
    const auto drift = [&](int i) { return r.statistics.floors[static_cast<std::size_t>(r.layout.dof(f, i))].drift.value; };
    int worst = 0;
    for (int i = 1; i < frame.storeys(); ++i) {
      if (drift(i) / height(i) > drift(worst) / height(worst)) worst = i;
    }
    text += fmt::format("  frame {}: peak interstorey drift {:.4g} mm at storey {}", f + 1, 1e3 * drift(worst), worst + 1);
    if (!frame.storey_height.empty()) text += fmt::format(" ({:.3g} % of its height)", 100 * drift(worst) / height(worst));
    if (r.free) {
      text += fmt::format(", free {:.4g} mm", 1e3 * r.free->floors[static_cast<std::size_t>(r.layout.dof(f, worst))].drift.value);
    }
    text += "\n";
  }
  return text;
}

/// At each joint, the widest separation its floors need to avoid contact (from the free
/// responses), with the code rules at that floor.
std::string separation_lines(const TimeHistoryResult& r) {
  std::string text;
  const std::vector<FloorSeparation> all = separations(r);
  for (int f = 0; f + 1 < r.model.frame_count(); ++f) {
    const FloorSeparation* widest = nullptr;
    for (const FloorSeparation& s : all) {
      if (s.neighbour->left_frame == f && (widest == nullptr || s.min_gap > widest->min_gap)) widest = &s;
    }
    if (widest == nullptr) continue;
    text += fmt::format("  joint {}–{}: separation to avoid contact {:.4g} mm (floor {}); absolute sum {:.4g}, SRSS "
                        "{:.4g}, DDC {:.4g} mm\n",
                        f + 1, f + 2, 1e3 * widest->min_gap, widest->neighbour->floor + 1, 1e3 * widest->absolute_sum,
                        1e3 * widest->srss, 1e3 * widest->ddc);
  }
  return text;
}
/// Each frame's peak absolute floor acceleration (with the free frame's), and what the rigid
/// impacts did to the floors when the accelerations leave them out.
std::string acceleration_lines(const TimeHistoryResult& r) {
  std::string text;
  const ResponseStatistics& st = r.statistics;
  const ResponseStatistics* free = r.free ? &*r.free : nullptr;
  Peak jump;
  int jump_frame = 0, jump_floor = 0;
  for (int f = 0; f < r.model.frame_count(); ++f) {
    Peak a, free_a;
    int at = 0;
    for (int i = 0; i < r.model.frames[static_cast<std::size_t>(f)].storeys(); ++i) {
      const auto d = static_cast<std::size_t>(r.layout.dof(f, i));
      const Peak p = st.floors[d].absolute_acceleration_with_impacts();
      if (p.value > a.value) {
        a = p;
        at = i;
      }
      if (free != nullptr) free_a.value = std::max(free_a.value, free->floors[d].absolute_acceleration.value);
      if (st.floors[d].velocity_jump.value > jump.value) {
        jump = st.floors[d].velocity_jump;
        jump_frame = f;
        jump_floor = i;
      }
    }
    text += fmt::format("  frame {}: peak floor acceleration {:.4g} g at floor {}", f + 1, a.value / standard_gravity,
                        at + 1);
    text += free != nullptr ? fmt::format(", free {:.4g} g\n", free_a.value / standard_gravity) : "\n";
  }
  if (jump.value > 0) {
    const double tau = r.options.impact_duration;
    text += tau > 0 ? fmt::format("  rigid impacts: largest floor velocity jump {:.4g} m/s (frame {}, floor {}), in "
                                  "the accelerations as half-sine pulses of {:.4g} ms\n",
                                  jump.value, jump_frame + 1, jump_floor + 1, 1e3 * tau)
                    : fmt::format("  rigid impacts: largest floor velocity jump {:.4g} m/s (frame {}, floor {}), not "
                                  "in the accelerations (analysis.impact_duration spreads it over a pulse)\n",
                                  jump.value, jump_frame + 1, jump_floor + 1);
  }
  return text;
}
}  // namespace

std::string report(const TimeHistoryResult& r, const std::filesystem::path& out_dir) {
  std::string text = fmt::format("poundsim {}: {} ({} s simulated, {} steps, {} events, {:.3f} s)\n",
                                 POUNDSIM_VERSION, r.input.source.string(), r.end_time, r.statistics.steps,
                                 r.statistics.events, r.run_time);
  const double weight1 = reference_weight(r.model);
  for (int f = 0; f < r.model.frame_count(); ++f) {
    const Peak& v = r.statistics.base_shear[static_cast<std::size_t>(f)];
    text += fmt::format("  frame {}: peak base shear {:.6g} N (V/W1 = {:.4f}) at t = {:.4f} s\n", f + 1, v.value,
                        v.value / weight1, v.time);
  }
  text += drift_lines(r);
  text += acceleration_lines(r);
  text += separation_lines(r);
  text += fmt::format("  impacts {}, max gap force {:.6g} N, max impact impulse {:.6g} N·s\n", r.impacts(),
                      r.max_gap_force(), r.max_impact_impulse());
  text += fmt::format("  energy: input {:.6g} J, relative balance residual {:.2e}\n", r.energy.input,
                      r.max_relative_residual);
  if (const std::optional<std::string> warning = energy_warning(r)) text += fmt::format("  warning: {}\n", *warning);
  text += fmt::format("  wrote {}/history.csv, events.csv, summary.json, input.toml\n", out_dir.string());
  return text;
}

namespace {
/// What the storey below floor DOF `dof` of a frame with an inelastic storey law did: its yield
/// drift, ductility demand (peak drift ÷ yield drift), drift at the end, hysteretic energy and
/// yield excursions.
json storey_response(const TimeHistoryResult& result, const std::vector<Link>& links, int dof) {
  const Link& link = links[static_cast<std::size_t>(dof)];
  const double yield_drift = std::visit(
      [](const auto& law) {
        if constexpr (requires { law.yield_drift(); }) {
          return law.yield_drift();
        } else {
          return 0.0;
        }
      },
      link.law);
  const FloorResponse& r = result.statistics.floors[static_cast<std::size_t>(dof)];
  return json{{"law", link.traits().name},
              {"yield_drift_m", yield_drift > 0 ? json(yield_drift) : json()},
              {"ductility", yield_drift > 0 ? json(r.drift.value / yield_drift) : json()},
              {"residual_drift_m", result.final_drift[static_cast<std::size_t>(dof)]},
              {"hysteretic_energy_J", result.storey_hysteretic[static_cast<std::size_t>(dof)]},
              {"yield_excursions", r.yield_excursions}};
}
}  // namespace

std::vector<FloorSeparation> separations(const TimeHistoryResult& result) {
  if (!result.free) return {};
  return poundsim::separations(result.model, result.layout, *result.free);
}

namespace {

/// The peaks of each floor (with the free frames' and the amplification when they ran).
json floor_peaks_json(const TimeHistoryResult& result) {
  const DofLayout& layout = result.layout;
  const ResponseStatistics& st = result.statistics;
  const ResponseStatistics* free = result.free ? &*result.free : nullptr;
  const Model& model = result.model;
  json floors = json::array();
  const std::vector<Link> links = make_links(model, layout);
  const bool rigid_impacts = model.has_rigid_impacts();
  for (int f = 0; f < model.frame_count(); ++f) {
    for (int i = 0; i < model.frames[f].storeys(); ++i) {
      const FloorResponse& r = st.floors[static_cast<std::size_t>(layout.dof(f, i))];
      json entry{{"frame", f + 1},
                 {"floor", i + 1},
                 {"displacement_m", peak(r.displacement)},
                 {"velocity_m_s", peak(r.velocity)},
                 {"acceleration_m_s2", peak(r.acceleration_with_impacts())},
                 {"absolute_acceleration_m_s2", peak(r.absolute_acceleration_with_impacts())},
                 {"interstorey_drift_m", peak(r.drift)}};
      if (rigid_impacts) entry["velocity_jump_m_s"] = peak(r.velocity_jump);
      const auto& heights = model.frames[f].storey_height;
      entry["interstorey_drift_ratio"] = heights.empty() ? json() : json(r.drift.value / heights[static_cast<std::size_t>(i)]);
      if (free != nullptr) {
        // The free model numbers its DOFs like the interacting one (same frames).
        const FloorResponse& q = free->floors[static_cast<std::size_t>(layout.dof(f, i))];
        entry["free"] = {{"displacement_m", q.displacement.value},
                         {"absolute_acceleration_m_s2", q.absolute_acceleration.value},
                         {"interstorey_drift_m", q.drift.value},
                         {"interstorey_drift_ratio", heights.empty() ? json() : json(q.drift.value / heights[static_cast<std::size_t>(i)])}};
        entry["amplification"] = {{"displacement", ratio(r.displacement.value, q.displacement.value)},
                                  {"absolute_acceleration",
                                   ratio(r.absolute_acceleration_with_impacts().value, q.absolute_acceleration.value)},
                                  {"interstorey_drift", ratio(r.drift.value, q.drift.value)}};
      }
      if (!is_default(model.frames[f].storey_law)) entry["storey"] = storey_response(result, links, layout.dof(f, i));
      floors.push_back(std::move(entry));
    }
  }
  return floors;
}

/// The peak base shear of each frame, over the first frame's weight and its own.
json base_shears_json(const TimeHistoryResult& result) {
  const Model& model = result.model;
  const ResponseStatistics* free = result.free ? &*result.free : nullptr;
  const double weight1 = reference_weight(model);
  json shears = json::array();
  for (int f = 0; f < model.frame_count(); ++f) {
    const Peak& p = result.statistics.base_shear[static_cast<std::size_t>(f)];
    json entry{{"frame", f + 1},
               {"value_N", p.value},
               {"time", p.time},
               {"over_frame1_weight", p.value / weight1},
               {"over_own_weight", p.value / weight(model.frames[f])}};
    if (free != nullptr) {
      const double v = free->base_shear[static_cast<std::size_t>(f)].value;
      entry["free_value_N"] = v;
      entry["amplification"] = ratio(p.value, v);
    }
    shears.push_back(std::move(entry));
  }
  return shears;
}

/// One neighbour's separation distance: the smallest gap that avoids contact, beside the code rules.
json separation_json(const TimeHistoryResult& result, const FloorSeparation& sep) {
  const Model& model = result.model;
  const NeighbourResponse& nb = *sep.neighbour;
  const int f = nb.left_frame, i = nb.floor;
  const json same_levels = sep.srss_same_levels ? json(*sep.srss_same_levels) : json(nullptr);
  json rules{{"absolute_sum_m", sep.absolute_sum}, {"srss_m", sep.srss}, {"srss_same_floor_levels_m", same_levels},
             {"ddc_m", sep.ddc}};
  json over{{"absolute_sum", ratio(sep.absolute_sum, sep.min_gap)}, {"srss", ratio(sep.srss, sep.min_gap)},
            {"srss_same_floor_levels", sep.srss_same_levels ? json(ratio(*sep.srss_same_levels, sep.min_gap)) : json(nullptr)},
            {"ddc", ratio(sep.ddc, sep.min_gap)}};
  json entry{{"frames", {f + 1, f + 2}}, {"floor", i + 1},
             {"min_gap_m", sep.min_gap}, {"min_gap_time_s", nb.max_approach_time},
             {"free_peak_displacement_m", {sep.left_peak, sep.right_peak}},
             {"ddc_correlation", sep.correlation},
             {"rules", rules},
             {"rule_over_min_gap", over}};
  if (nb.right_floor != i) entry["right_floor"] = nb.right_floor + 1;
  if (nb.column) entry["struck_column"] = struck_column_json(*nb.column, f, i, nb.right_floor);
  for (int p = 0; p < model.gap_count(); ++p) {
    const GapElement& g = model.gaps[static_cast<std::size_t>(p)];
    if (g.facing() == FloorPair{f, i, nb.right_floor, nb.column}) {
      const GapResponse& gr = result.statistics.gaps[static_cast<std::size_t>(p)];
      entry["gap_m"] = g.gap();
      entry["gap_over_min_gap"] = ratio(g.gap(), sep.min_gap);
      entry["contact"] = gr.contacts + gr.impacts + gr.locks > 0;
    }
  }
  return entry;
}

/// One gap element's counts and peaks; `min_gap` is its neighbour's separation distance, if known.
json gap_element_json(const TimeHistoryResult& result, int p, std::optional<double> min_gap) {
  const GapResponse& g = result.statistics.gaps[static_cast<std::size_t>(p)];
  const GapElement& e = result.model.gaps[static_cast<std::size_t>(p)];
  json entry{{"frames", {e.left_frame + 1, e.left_frame + 2}},
             {"floor", e.floor + 1},
             {"contacts", g.contacts},
             {"separations", g.separations},
             {"impacts", g.impacts},
             {"locks", g.locks},
             {"unlocks", g.unlocks},
             {"max_force_N", peak(g.force)},
             {"max_impact_velocity_m_s", peak(g.impact_velocity)},
             {"max_impulse_Ns", peak(g.impulse)},
             {"max_shortening_m", peak(g.shortening)},
             {"locked_time_s", g.locked_time},
             {"contact_time_s", g.contact_time},
             {"completed_contacts", g.completed_contacts},
             {"longest_contact_s", peak(g.longest_contact)}};
  if (e.floor_right() != e.floor) entry["right_floor"] = e.floor_right() + 1;
  if (e.column) entry["struck_column"] = struck_column_json(*e.column, e.left_frame, e.floor, e.floor_right());
  // The restitution the law achieved, contact by contact (none without a completed contact),
  // and what it dissipated (the exact integrator gives the total only, energy.gap_damping_J).
  entry["effective_restitution"] =
      g.restitution_samples > 0
          ? json{{"mean", g.mean_restitution()}, {"min", g.min_restitution}, {"max", g.max_restitution}}
          : json(nullptr);
  entry["dissipated_J"] = result.element_dissipation.empty()
                              ? json(nullptr)
                              : json(result.element_dissipation[static_cast<std::size_t>(p)]);
  if (min_gap) entry["min_gap_m"] = *min_gap;
  return entry;
}

/// The gap elements, each with its neighbour's separation distance when the free frames ran.
json gap_elements_json(const TimeHistoryResult& result, const std::vector<double>& min_gap) {
  const ResponseStatistics& st = result.statistics;
  json gaps = json::array();
  for (int p = 0; p < result.model.gap_count(); ++p) {
    const GapElement& e = result.model.gaps[static_cast<std::size_t>(p)];
    std::optional<double> gap;
    if (result.free) {
      for (std::size_t k = 0; k < st.neighbours.size(); ++k) {
        const NeighbourResponse& nb = st.neighbours[k];
        if (e.facing() == FloorPair{nb.left_frame, nb.floor, nb.right_floor, nb.column}) gap = min_gap[k];
      }
    }
    gaps.push_back(gap_element_json(result, p, gap));
  }
  return gaps;
}

/// The energy balance at the end of the run.
json energy_json(const TimeHistoryResult& result) {
  const EnergyBalance& e = result.energy;
  json energy{{"initial_J", e.initial},
              {"input_J", e.input},
              {"kinetic_J", e.kinetic},
              {"storey_strain_J", e.storey_strain},
              {"gap_strain_J", e.gap_strain},
              {"storey_damping_J", e.storey_damping},
              {"gap_damping_J", e.gap_damping},
              {"impact_loss_J", e.impact_loss},
              {"residual_J", e.residual()},
              {"relative_residual", result.relative_residual},
              {"max_relative_residual", result.max_relative_residual},
              {"warn_above", EnergyBalanceCheck{}.warn_above}};
  const std::optional<std::string> warning = energy_warning(result);
  energy["warning"] = warning ? json(*warning) : json();
  if (has_inelastic_storeys(result.model)) energy["storey_hysteretic_J"] = e.storey_hysteretic;
  return energy;
}

/// The analysis that ran: integrator, steps and tolerances.
json analysis_json(const TimeHistoryResult& result) {
  const RunInput& input = result.input;
  const TimeHistoryOptions& o = result.options;
  json analysis{{"kind", to_string(input.analysis.kind)},
                {"integrator", std::string(to_string(input.analysis.options.integrator))},
                {"duration_s", input.analysis.duration},
                {"dt_s", o.dt},
                {"output_dt_s", input.analysis.output_dt},
                {"event_tolerance_s", o.event_tolerance},
                {"lock_time_s", o.lock_time},
                {"separation", to_string(o.separation)}};
  if (result.model.has_rigid_impacts()) {
    // Whether the peak accelerations contain the rigid impacts: they do when spread over a pulse,
    // or when no floor's velocity jumped.
    double jump = 0;
    for (const FloorResponse& f : result.statistics.floors) jump = std::max(jump, f.velocity_jump.value);
    analysis["impact_duration_s"] = o.impact_duration > 0 ? json(o.impact_duration) : json();
    analysis["accelerations_include_impacts"] = o.impact_duration > 0 || jump == 0;
  }
  return analysis;
}

}  // namespace

json to_json(const TimeHistoryResult& result) {
  const RunInput& input = result.input;
  const ResponseStatistics& st = result.statistics;
  json separation = json::array();
  std::vector<double> min_gap(st.neighbours.size(), 0.0);
  for (const FloorSeparation& sep : separations(result)) {
    min_gap[sep.index] = sep.min_gap;
    separation.push_back(separation_json(result, sep));
  }
  double max_impact_velocity = 0;
  for (int p = 0; p < result.model.gap_count(); ++p) {
    max_impact_velocity = std::max(max_impact_velocity, st.gaps[static_cast<std::size_t>(p)].impact_velocity.value);
  }
  return json{{"poundsim_version", POUNDSIM_VERSION},
              {"input", input.source.string()},
              {"title", input.title},
              {"analysis", analysis_json(result)},
              {"model", describe_model(input)},
              {"excitation", describe_excitation(input.excitation_info)},
              {"end_time_s", result.end_time},
              {"peaks", {{"floors", floor_peaks_json(result)}, {"base_shear", base_shears_json(result)}}},
              {"separation", separation},
              {"gap_elements", gap_elements_json(result, min_gap)},
              {"impacts", result.impacts()},
              {"max_gap_force_N", result.max_gap_force()},
              {"max_impact_impulse_Ns", result.max_impact_impulse()},
              {"max_impact_velocity_m_s", max_impact_velocity},
              {"energy", energy_json(result)},
              {"counts",
               {{"steps", st.steps},
                {"substeps", st.substeps},
                {"guard_evaluations", st.guard_evaluations},
                {"events", st.events},
                {"phases_factorised", st.phases_factorised},
                {"newton_steps", st.newton_steps},
                {"newton_iterations", st.newton_iterations}}},
              {"run_time_s", result.run_time}};
}

FreeRunMemo& process_free_runs() {
  static FreeRunMemo memo(64);
  return memo;
}

TimeHistoryResult analyse_run(const RunInput& input, const TimeHistoryObserver& observer) {
  const auto start = std::chrono::steady_clock::now();
  const TimeHistoryProblem problem{.model = input.model,
                                   .excitation = input.excitation,
                                   .options = input.analysis.options,
                                   .initial = input.initial,
                                   .duration = input.analysis.duration,
                                   .output_dt = input.analysis.output_dt};
  // read_input bounds the rows by analysis.max_steps; an input built otherwise is checked here.
  const double row_count = output_instants(problem.duration, problem.output_dt);
  if (!(row_count >= 0 && row_count <= input.analysis.max_steps)) {
    throw InputError(fmt::format("{}: analysis.output_dt: {} s over the duration {} s makes {} rows, more than "
                                 "analysis.max_steps = {}", input.source.string(), problem.output_dt,
                                 problem.duration, row_count, input.analysis.max_steps));
  }
  std::optional<TimeHistoryAnalysis> analysis;
  try {
    analysis.emplace(analyse_time_history(problem, observer, &process_free_runs()));
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", input.source.string(), e.what()));
  }
  return {std::move(*analysis), input, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
}

TimeHistoryResult run_time_history(const RunInput& input, const std::filesystem::path& out_dir) {
  const Model& model = input.model;
  const DofLayout layout(model);

  OutputTransaction out(out_dir);
  CsvWriter history(out.open("history.csv"));
  CsvWriter events(out.open("events.csv"));

  // The channels [output] chose (the default ones without it), in the model's order.
  const HistoryChannels channels(model, input.channels);
  std::vector<CsvColumn> history_columns{{"t_s", "s"}};
  for (const Channel& c : channels.channels()) history_columns.push_back({c.column(), std::string(c.unit)});
  for (const CsvColumn& c : history_columns) history.text(c.title);
  history.end_row();
  write_csv_metadata(out, "history.csv", history_columns);
  std::vector<double> row(channels.size());

  // The right floor, when an element joins floors of different numbers (floor and right_floor
  // then name it, a struck column by the floor above the point).
  const bool right_floors = std::any_of(model.gaps.begin(), model.gaps.end(), [](const GapElement& g) {
    return g.floor_right() != g.floor || g.column.has_value();
  });
  std::vector<CsvColumn> event_columns{
      {"t_s", "s"}, {"frame_left", "", "integer"}, {"frame_right", "", "integer"}, {"floor", "", "integer"}};
  if (right_floors) event_columns.push_back({"right_floor", "", "integer"});
  event_columns.insert(event_columns.end(), {{"kind", "", "string"},
                                             {"relative_velocity_before_m_s", "m/s"},
                                             {"relative_velocity_after_m_s", "m/s"},
                                             {"impulse_Ns", "N·s"}});
  for (const CsvColumn& c : event_columns) events.text(c.title);
  events.end_row();
  write_csv_metadata(out, "events.csv", event_columns);
  TimeHistoryObserver observer;
  observer.on_event = [&](const Event& e) {
    const GapElement& g = model.gaps[static_cast<std::size_t>(e.gap)];
    events.number(e.time).integer(g.left_frame + 1).integer(g.left_frame + 2).integer(g.floor + 1);
    if (right_floors) events.integer(g.floor_right() + 1);
    events.text(to_string(e.kind)).number(e.rate_before).number(e.rate_after).number(e.impulse).end_row();
  };
  observer.on_output = [&](const Simulator& sim) {
    history.number(sim.state().t);
    channels.sample(sim, row);
    for (const double value : row) history.number(value);
    history.end_row();
  };
  const TimeHistoryResult result = analyse_run(input, observer);
  out.write_json("summary.json", to_json(result));
  out.open("input.toml").text(to_toml(input));
  out.commit();
  return result;
}

}  // namespace poundsim::io
