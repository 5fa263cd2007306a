#pragma once
/// @file
/// The structural model: a row of shear frames, left to right, with gap elements between floors
/// of neighbouring frames, and the numbering of its degrees of freedom.
///
/// The paper's system is two frames; any number ≥ 1 works (buildings in series). By default
/// frame f and f+1 are joined at corresponding floors 1..min(n_f, n_{f+1}); a model may instead
/// join the floors that stand at the same height, or any floors it lists (FloorPair): floors of
/// frames with different storey heights.
///
/// Example:
/// @code
///   Model m = make_model({make_uniform_frame(1, 1.0, 200.0, 1.414),
///                         make_uniform_frame(1, 1.0, 50.0, 0.707)},
///                        GapProperties{.gap = 0.0123, .restitution = 0.75});
///   DofLayout layout(m);   // 2 degrees of freedom
/// @endcode

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "poundsim/model/frame.hpp"
#include "poundsim/model/laws/paper_gap.hpp"
#include "poundsim/model/law.hpp"

namespace poundsim {

/// A side of a joint between two frames.
enum class Side : std::uint8_t { left, right };

/// A slab that strikes its neighbour's column between two floors (Karayannis & Favvata 2005):
/// the struck frame's floor in the pair is the floor above the point, which moves as
/// w u_above + (1 − w) u_below (model/law.hpp's ColumnPoint; below a first floor, the ground).
/// docs/model.md#slab-to-column.
struct ColumnStrike {
  Side struck = Side::right;  ///< The frame whose column is struck; the other's slab strikes it.
  double weight = 1.0;        ///< w of the struck frame's floor above the point, in (0, 1).
  [[nodiscard]] bool operator==(const ColumnStrike&) const = default;
};

/// A pair of floors a gap element joins: `left_floor` of `left_frame` and `right_floor` of the
/// frame to its right, or a slab and the point of the neighbour's column it strikes (`column`:
/// the struck side's floor is then the one above the point). 0-based.
struct FloorPair {
  int left_frame = 0;
  int left_floor = 0;
  int right_floor = 0;
  std::optional<ColumnStrike> column{};
  /// The same joint: frames, floors and struck column.
  [[nodiscard]] bool operator==(const FloorPair&) const = default;
};

/// One gap element between a floor of a frame and a floor of its right neighbour. 0-based.
struct GapElement {
  int left_frame = 0;  ///< Frame L; the right frame is L+1.
  int floor = 0;       ///< Floor index in frame L (0 = first floor above the ground).
  GapLaw law;          ///< Its law with its parameters (the paper's by default).
  /// Floor index in frame L+1; −1: the same as `floor` (corresponding floors).
  int right_floor = -1;
  /// A slab striking the neighbour's column (the struck side's floor is the one above the
  /// point); none: the element joins two floors.
  std::optional<ColumnStrike> column{};

  /// The floor of frame L+1 it joins.
  [[nodiscard]] int floor_right() const { return right_floor < 0 ? floor : right_floor; }
  /// The floors (or slab and column) it joins, as a facing pair.
  [[nodiscard]] FloorPair facing() const { return {left_frame, floor, floor_right(), column}; }

  /// δ [m]: the clear distance at rest, whatever the law.
  [[nodiscard]] double gap() const {
    return std::visit([](const auto& l) { return l.gap(); }, law);
  }
};

/// The parameters of g's law, which must be L (std::bad_variant_access otherwise).
template <class L>
[[nodiscard]] const typename L::Parameters& parameters_of(const GapElement& g) {
  return std::get<L>(g.law).parameters;
}
template <class L>
[[nodiscard]] typename L::Parameters& parameters_of(GapElement& g) {
  return std::get<L>(g.law).parameters;
}

struct Model {
  std::vector<Frame> frames;     ///< Left to right.
  std::vector<GapElement> gaps;  ///< Ordered by frame pair, then by floor.
  /// The floors that face each other across each joint, where the frames may pound (the pairs
  /// of make_model; they stay when the gap elements are taken away, free_frames); empty: the
  /// corresponding floors 1..min(n_f, n_{f+1}).
  std::vector<FloorPair> facing;

  [[nodiscard]] int frame_count() const { return static_cast<int>(frames.size()); }
  [[nodiscard]] int gap_count() const { return static_cast<int>(gaps.size()); }
  /// Whether an impact can be rigid: a gap element has the paper's law, which collides when it
  /// reaches its stop (bare pounding at once), its floors' velocities jumping.
  [[nodiscard]] bool has_rigid_impacts() const {
    for (const GapElement& g : gaps) {
      if (std::holds_alternative<PaperGap>(g.law)) return true;
    }
    return false;
  }
};

/// Per-element override of the default gap-element law, for (left frame, floor), 0-based.
struct GapOverride {
  int left_frame = 0;
  int floor = 0;
  GapLaw law;
  /// The element's floor in frame L+1, which tells apart elements that share the left floor (a
  /// slab of frame L+1 striking frame L's column below a floor that also strikes); −1: the one
  /// element at `floor`.
  int right_floor = -1;
};

/// How the outputs name the element (or facing pair) at `left_floor` of `left_frame`: "1_5",
/// frames and floors from 1, by its left frame and floor — and "1_5_4", with its right floor,
/// when its left end is a struck column (another element may then have that floor on its left).
[[nodiscard]] std::string joint_label(int left_frame, int left_floor, int right_floor,
                                      const std::optional<ColumnStrike>& column);

/// Builds the model with an element at every pair of corresponding floors — or, when `pairs`
/// is given, at exactly those pairs (ordered by frame pair, then floor) — all with `defaults`
/// except those listed in `overrides` (named by their left frame and floor, and right floor when
/// that is needed). Throws std::invalid_argument for an override that names no element or
/// several.
Model make_model(std::vector<Frame> frames, const GapLaw& defaults,
                 std::span<const GapOverride> overrides = {}, std::span<const FloorPair> pairs = {});

/// The pairs of floors of neighbouring frames that stand at the same height above the ground
/// (Frame::storey_height, to 1e-9 relative), every frame pair in turn. Frames without storey
/// heights pair no floors.
std::vector<FloorPair> floors_at_equal_heights(const std::vector<Frame>& frames);

/// The floors facing each other across the joints (Model::facing, or the corresponding floors).
std::vector<FloorPair> facing_floors(const Model& model);


/// Throws std::invalid_argument naming the frame, element and field of the first problem.
void validate(const Model& model);

/// Numbering of the degrees of freedom (floor displacements).
///
/// The DOFs are interleaved level by level: all frames' first floors, then all second floors, and
/// so on, frames left to right within a level. A storey then couples DOFs at most F apart and a gap
/// element couples neighbours, so every system matrix is banded with bandwidth ≤ F (the number of
/// frames) whatever the number of storeys: factorisations and solves cost O(N·F²) and O(N·F).
class DofLayout {
 public:
  /// The model's elements must join existing floors (validate(model)); std::out_of_range if not.
  explicit DofLayout(const Model& model);

  [[nodiscard]] int size() const { return static_cast<int>(frame_of_.size()); }
  [[nodiscard]] int frame_count() const { return static_cast<int>(dof_.size()); }
  [[nodiscard]] int storeys(int frame) const { return static_cast<int>(dof_[frame].size()); }
  /// DOF of `floor` (0-based) of `frame` (0-based).
  [[nodiscard]] int dof(int frame, int floor) const { return dof_[frame][floor]; }
  [[nodiscard]] int frame_of(int dof) const { return frame_of_[dof]; }
  [[nodiscard]] int floor_of(int dof) const { return floor_of_[dof]; }
  /// DOF of the floor below, or −1 for a first floor (kept: the peaks read it at every step).
  [[nodiscard]] int below(int dof) const { return below_[dof]; }
  /// DOF of the left floor of gap element `gap` (Model::gaps order).
  [[nodiscard]] int gap_left(std::size_t gap) const { return gap_left_[gap]; }
  /// DOF of the right floor of gap element `gap`.
  [[nodiscard]] int gap_right(std::size_t gap) const { return gap_right_[gap]; }

 private:
  std::vector<std::vector<int>> dof_;
  std::vector<int> frame_of_;
  std::vector<int> floor_of_;
  std::vector<int> below_;
  std::vector<int> gap_left_, gap_right_;
};

/// Every storey and gap element of `model` as a link with its law: the storeys first, one per
/// DOF in the layout's numbering (the storey below that floor, with its frame's storey law),
/// then the gap elements in Model::gaps order (each with its GapLaw). Assembly and energy sums
/// follow this order. The links with modes (Link::element ≥ 0) are the gap elements, numbered
/// as in Model::gaps, then the storeys whose law is tracked, numbered from gap_count() up in DOF
/// order.
std::vector<Link> make_links(const Model& model, const DofLayout& layout);

/// The ends of a link between the DOFs a (left) and b (right) of a facing pair: at the floors, or
/// the struck side's at the column point below its floor (`column`).
[[nodiscard]] std::pair<ColumnPoint, ColumnPoint> column_points(const std::optional<ColumnStrike>& column, int a, int b,
                                                                const DofLayout& layout);

/// The link as messages name it, from its floors and its law: "storey 2 of frame 1 (linear
/// storey)", "the paper's gap element between frames 1 and 2 at floor 3". Frames and floors from 1.
[[nodiscard]] std::string describe(const Link& link, const DofLayout& layout);
/// "gap element between frames 1 and 2 at floor 3", "… between floor 4 of frame 1 and the column
/// of frame 2 between floors 3 and 4": how messages name a gap element.
[[nodiscard]] std::string describe(const GapElement& gap);

/// The mode of `link` in the contact configuration `config` (untracked storeys have one mode, 0).
[[nodiscard]] inline LinkMode mode_of(const Link& link, const ContactConfiguration& config) {
  return link.element < 0 ? LinkMode{0} : config[static_cast<std::size_t>(link.element)];
}

}  // namespace poundsim
