#include "poundsim/model/model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>

namespace poundsim {

Model make_model(std::vector<Frame> frames, const GapLaw& defaults,
                 std::span<const GapOverride> overrides, std::span<const FloorPair> pairs) {
  Model model;
  model.frames = std::move(frames);
  if (pairs.empty()) {
    for (int f = 0; f + 1 < model.frame_count(); ++f) {
      const int shared = std::min(model.frames[f].storeys(), model.frames[f + 1].storeys());
      for (int floor = 0; floor < shared; ++floor) model.gaps.push_back({f, floor, defaults});
    }
  } else {
    for (const FloorPair& p : pairs) {
      model.gaps.push_back({.left_frame = p.left_frame, .floor = p.left_floor, .law = defaults,
                            .right_floor = p.right_floor == p.left_floor ? -1 : p.right_floor,
                            .column = p.column});
    }
    std::stable_sort(model.gaps.begin(), model.gaps.end(), [](const GapElement& a, const GapElement& b) {
      return a.left_frame != b.left_frame ? a.left_frame < b.left_frame : a.floor < b.floor;
    });
    for (const GapElement& g : model.gaps) model.facing.push_back(g.facing());
  }
  for (const GapOverride& o : overrides) {
    const auto named = [&](const GapElement& g) {
      return g.left_frame == o.left_frame && g.floor == o.floor && (o.right_floor < 0 || g.floor_right() == o.right_floor);
    };
    const auto it = std::find_if(model.gaps.begin(), model.gaps.end(), named);
    if (it == model.gaps.end()) {
      throw std::invalid_argument(
          fmt::format("no gap element between frames {} and {} at floor {}", o.left_frame + 1,
                      o.left_frame + 2, o.floor + 1));
    }
    if (std::count_if(model.gaps.begin(), model.gaps.end(), named) > 1) {
      throw std::invalid_argument(fmt::format("several gap elements between frames {} and {} at floor {}: name "
                                              "the right floor too", o.left_frame + 1, o.left_frame + 2, o.floor + 1));
    }
    it->law = o.law;
  }
  return model;
}

std::pair<ColumnPoint, ColumnPoint> column_points(const std::optional<ColumnStrike>& column, int a, int b,
                                                const DofLayout& layout) {
  std::pair<ColumnPoint, ColumnPoint> ends;
  if (!column) return ends;
  const bool left = column->struck == Side::left;
  (left ? ends.first : ends.second) = {.below = layout.below(left ? a : b), .weight = column->weight};
  return ends;
}

std::string joint_label(int left_frame, int left_floor, int right_floor, const std::optional<ColumnStrike>& column) {
  if (column && column->struck == Side::left) return fmt::format("{}_{}_{}", left_frame + 1, left_floor + 1, right_floor + 1);
  return fmt::format("{}_{}", left_frame + 1, left_floor + 1);
}

std::vector<FloorPair> floors_at_equal_heights(const std::vector<Frame>& frames) {
  std::vector<FloorPair> pairs;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    const Frame& left = frames[f];
    const Frame& right = frames[f + 1];
    double height_left = 0.0;
    for (int i = 0; i < static_cast<int>(left.storey_height.size()); ++i) {
      height_left += left.storey_height[static_cast<std::size_t>(i)];
      double height_right = 0.0;
      for (int j = 0; j < static_cast<int>(right.storey_height.size()); ++j) {
        height_right += right.storey_height[static_cast<std::size_t>(j)];
        // Heights written to different precision (3.2 and 3.2000000001) are the same floor.
        if (std::abs(height_left - height_right) <= 1e-9 * std::max(height_left, height_right)) {
          pairs.push_back({.left_frame = static_cast<int>(f), .left_floor = i, .right_floor = j});
        }
      }
    }
  }
  return pairs;
}

std::vector<FloorPair> facing_floors(const Model& model) {
  if (!model.facing.empty()) return model.facing;
  std::vector<FloorPair> pairs;
  for (int f = 0; f + 1 < model.frame_count(); ++f) {
    const int shared = std::min(model.frames[f].storeys(), model.frames[f + 1].storeys());
    for (int i = 0; i < shared; ++i) pairs.push_back({f, i, i});
  }
  return pairs;
}

void validate(const Model& model) {
  if (model.frames.empty()) throw std::invalid_argument("the model has no frames");
  for (int f = 0; f < model.frame_count(); ++f) {
    try {
      validate(model.frames[f]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("frame {}: {}", f + 1, e.what()));
    }
  }
  const std::vector<FloorPair> facing = facing_floors(model);
  for (std::size_t k = 0; k < model.gaps.size(); ++k) {
    const GapElement& g = model.gaps[k];
    const std::string what = describe(g);
    if (g.left_frame < 0 || g.left_frame + 1 >= model.frame_count() || g.floor < 0 ||
        g.floor >= model.frames[g.left_frame].storeys() || g.floor_right() < 0 ||
        g.floor_right() >= model.frames[g.left_frame + 1].storeys()) {
      throw std::invalid_argument(what + ": no such floors");
    }
    if (g.column) {
      if (!(g.column->weight > 0.0 && g.column->weight < 1.0)) {
        throw std::invalid_argument(fmt::format("{}: the weight of the floor above the struck point must be in "
                                                "(0, 1) (got {})", what, g.column->weight));
      }
      const LawTraits& traits = std::visit([](const auto& law) -> const LawTraits& { return law.traits; }, g.law);
      if (traits.has_stop) {
        throw std::invalid_argument(fmt::format(
            "{}: {} has a stop, whose impacts and locking act between two floors; a slab that strikes a column "
            "takes a contact law without one (kelvin_voigt, hertz, hertzdamp, jankowski, impact)", what, traits.name));
      }
    }
    // A floor meets its neighbour at one place: one element per floor and side (a struck
    // column's side has no floor there: several slabs may strike one storey's column).
    const auto slab = [](const GapElement& e, Side side) {
      return !e.column || e.column->struck != side;
    };
    for (std::size_t q = 0; q < k; ++q) {
      const GapElement& o = model.gaps[q];
      if (o.left_frame != g.left_frame) continue;
      if ((slab(o, Side::left) && slab(g, Side::left) && o.floor == g.floor) ||
          (slab(o, Side::right) && slab(g, Side::right) && o.floor_right() == g.floor_right()) ||
          (o.floor == g.floor && o.floor_right() == g.floor_right())) {  // the outputs' names
        throw std::invalid_argument(what + ": a floor of it already has a gap element on that side");
      }
    }
    // The monitor follows the facing pairs: an element between other floors than corresponding
    // ones, or at a column, must be one of them.
    if (std::find(facing.begin(), facing.end(), g.facing()) == facing.end()) {
      throw std::invalid_argument(what + ": not among the model's facing floors (Model::facing)");
    }
    std::visit([&](const auto& law) { validate_fields(law.parameters, what); }, g.law);
  }
}

DofLayout::DofLayout(const Model& model) {
  const int frames = model.frame_count();
  dof_.resize(static_cast<std::size_t>(frames));
  int levels = 0;
  for (int f = 0; f < frames; ++f) {
    dof_[f].resize(static_cast<std::size_t>(model.frames[f].storeys()));
    levels = std::max(levels, model.frames[f].storeys());
  }
  for (int level = 0; level < levels; ++level) {
    for (int f = 0; f < frames; ++f) {
      if (level < model.frames[f].storeys()) {
        dof_[f][level] = static_cast<int>(frame_of_.size());
        frame_of_.push_back(f);
        floor_of_.push_back(level);
        below_.push_back(level == 0 ? -1 : dof_[f][level - 1]);
      }
    }
  }
  for (const GapElement& g : model.gaps) {
    gap_left_.push_back(dof_.at(g.left_frame).at(g.floor));
    gap_right_.push_back(dof_.at(g.left_frame + 1).at(g.floor_right()));
  }
}

namespace {
/// "floor 3 of frame 1", or "the column of frame 2 between floors 2 and 3" (the point below floor
/// `floor`, 0-based).
std::string end_name(int frame, int floor, bool column) {
  if (!column) return fmt::format("floor {} of frame {}", floor + 1, frame + 1);
  return floor == 0 ? fmt::format("the column of frame {} between the ground and floor 1", frame + 1)
                    : fmt::format("the column of frame {} between floors {} and {}", frame + 1, floor, floor + 1);
}
}  // namespace

std::string describe(const GapElement& g) {
  if (g.column) {
    const bool left_struck = g.column->struck == Side::left;
    return fmt::format("gap element between {} and {}", end_name(g.left_frame, g.floor, left_struck),
                       end_name(g.left_frame + 1, g.floor_right(), !left_struck));
  }
  return g.floor_right() == g.floor
             ? fmt::format("gap element between frames {} and {} at floor {}", g.left_frame + 1, g.left_frame + 2,
                           g.floor + 1)
             : fmt::format("gap element between floor {} of frame {} and floor {} of frame {}", g.floor + 1,
                           g.left_frame + 1, g.floor_right() + 1, g.left_frame + 2);
}

std::string describe(const Link& link, const DofLayout& layout) {
  const int frame = layout.frame_of(link.a), floor = layout.floor_of(link.a);
  if (link.b < 0 || layout.frame_of(link.b) == frame) {
    return fmt::format("storey {} of frame {} ({})", floor + 1, frame + 1, link.traits().name);
  }
  if (!link.joins_floors()) {
    return fmt::format("{} between {} and {}", link.traits().name,
                       end_name(frame, floor, !link.a_column.at_floor()),
                       end_name(layout.frame_of(link.b), layout.floor_of(link.b), !link.b_column.at_floor()));
  }
  if (layout.floor_of(link.b) != floor) {
    return fmt::format("{} between floor {} of frame {} and floor {} of frame {}", link.traits().name, floor + 1,
                       frame + 1, layout.floor_of(link.b) + 1, layout.frame_of(link.b) + 1);
  }
  return fmt::format("{} between frames {} and {} at floor {}", link.traits().name, frame + 1,
                     layout.frame_of(link.b) + 1, floor + 1);
}

std::vector<Link> make_links(const Model& model, const DofLayout& layout) {
  std::vector<Link> links;
  links.reserve(static_cast<std::size_t>(layout.size() + model.gap_count()));
  int tracked_storeys = 0;
  for (int i = 0; i < layout.size(); ++i) {
    const Frame& frame = model.frames[layout.frame_of(i)];
    const int floor = layout.floor_of(i);
    links.push_back({.a = i,
                     .b = layout.below(i),
                     .law = std::visit(
                         [&](const auto& law) -> Law {
                           using L = typename std::decay_t<decltype(law)>::Law;
                           const auto f = static_cast<std::size_t>(floor);
                           return L::make(frame.stiffness[f], frame.damping[f],
                                          law.values.empty() ? typename L::Parameters{} : law.values[f]);
                         },
                         frame.storey_law)});
    // A storey whose law has modes (or a smooth force) is tracked after the gap elements.
    if (std::visit([](const auto& law) { return TrackedLaw<std::decay_t<decltype(law)>>; }, links.back().law)) {
      links.back().element = model.gap_count() + tracked_storeys++;
    }
  }
  const auto mass = [&](int dof) {
    return model.frames[static_cast<std::size_t>(layout.frame_of(dof))].mass[static_cast<std::size_t>(layout.floor_of(dof))];
  };
  // A column point's mass for a dashpot tuned to the masses: the mass an impulse J there meets,
  // 1/m = w²/m_above + (1 − w)²/m_below (the ground below a first floor is immovable).
  const auto point_mass = [&](int dof, const ColumnPoint& point) {
    if (point.at_floor()) return mass(dof);
    const double w = point.weight;
    return 1.0 / (w * w / mass(dof) + (point.below >= 0 ? (1 - w) * (1 - w) / mass(point.below) : 0.0));
  };
  for (int p = 0; p < model.gap_count(); ++p) {
    const GapElement& g = model.gaps[static_cast<std::size_t>(p)];
    const int a = layout.gap_left(p), b = layout.gap_right(p);
    // Not a structured binding: clang 14 (the fuzz build) cannot capture one in the lambda below.
    ColumnPoint a_column, b_column;
    std::tie(a_column, b_column) = column_points(g.column, a, b, layout);
    links.push_back({.a = a,
                     .b = b,
                     .law = std::visit(
                         [&](auto law) -> Law {
                           // A law whose parameters depend on the floors it joins (a dashpot tuned
                           // to their reduced mass) is bound to them here.
                           if constexpr (requires { law.bind_masses(1.0, 1.0); }) {
                             law.bind_masses(point_mass(a, a_column), point_mass(b, b_column));
                           }
                           return law;
                         },
                         g.law),
                     .element = p,
                     .a_column = a_column,
                     .b_column = b_column});
  }
  // Each link's index among its law's links: where LinkStates keeps its state.
  std::array<int, std::variant_size_v<Law>> next_slot{};
  for (Link& link : links) link.slot = next_slot[link.law.index()]++;
  return links;
}

}  // namespace poundsim
