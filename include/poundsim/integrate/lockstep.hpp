#pragma once
/// @file
/// Grid steps of several simulators at once: many small models in lockstep (docs/numerics.md).
///
/// A brute-force frequency response runs each of its points — a model under its own harmonic
/// forcing and step — through thousands of grid steps, nearly all of them plain: Newmark over
/// one step of dt, no guard firing, nothing recorded (the transient keeps neither peaks nor the
/// energy balance). Through Simulator::step() such a step pays for the loop's generality: a
/// virtual stepper, the system's guards law by law, the finiteness check of every quantity. Here
/// up to kLanes simulators (lanes) take their plain steps together, in structure-of-arrays form:
/// each DOF's state, matrices and guards are an array over the lanes, so one pass over a DOF
/// steps every lane (a release build vectorises some of these passes; docs/numerics.md measures).
///
/// A lane's step is *lean* when its simulator integrates with Newmark, records no responses and
/// meters no energy (Simulator::record_responses(false), meter_energy(false)), its current phase
/// is unreduced with bands (LinearPhase::Bands, at most 4 wide: single-storey frames apart or in
/// contact, frames of several storeys), and every tracked link is a paper's gap element
/// (PaperGap), open or in contact. The lean step is NewmarkIntegrator::step_banded's own row
/// functions (newmark.hpp), the law's guards() and the system's guard entries
/// (PoundingSystem::guard_entry), operation for operation: the same bits (docs/numerics.md, "Many
/// models in lockstep", says why a lane stepped at a wider band than its own keeps them, and the
/// one corner where it does not: an acceleration underflowing to −0). When a lean step's guard
/// fires, one may graze inside the step, or something is not finite, that lane's step is not
/// taken: its simulator takes it through step() from the same state, locating the events (or
/// naming what is not finite) as it always does. Every other step is the simulator's own step().
/// A lane's results therefore do not depend on the other lanes, on how many there are, or on the
/// threads: test Lockstep.* compares every lane to the bit with its simulator stepped alone.
///
/// The lanes' states live in the batch between the calls of step(): `step(lanes, k)` gathers each
/// lean lane, takes k grid steps and writes every lane back, so between calls each simulator is
/// exactly where k step()s would have left it (a frequency response calls it once a period, at
/// its Poincaré sections).
///
/// Example:
/// @code
///   std::array<Simulator*, 2> lanes{&a, &b};  // a.record_responses(false); a.meter_energy(false); …
///   std::array<std::exception_ptr, 2> errors;
///   Lockstep batch;
///   batch.step(lanes, 128, errors);  // each as 128 × step()
/// @endcode

#include <cstdint>
#include <exception>
#include <memory>
#include <span>

namespace poundsim {

class Simulator;

class Lockstep {
 public:
  /// The most simulators stepped together (the arrays' width: a multiple of the SIMD width).
  static constexpr int kLanes = 8;

  Lockstep();
  ~Lockstep();
  Lockstep(const Lockstep&) = delete;
  Lockstep& operator=(const Lockstep&) = delete;

  /// Advances every simulator of `lanes` (at most kLanes; null entries are skipped) by `steps`
  /// grid steps, each to the bits its step() would give. A lane whose step throws has its
  /// exception put in errors[lane] (the simulator is then failed, as after a throw of step())
  /// and is not stepped further by this call. errors has the size of lanes.
  void step(std::span<Simulator* const> lanes, int steps, std::span<std::exception_ptr> errors);

  /// The grid steps taken so far, by kind.
  struct Counts {
    std::int64_t lean = 0;     ///< in lockstep
    std::int64_t general = 0;  ///< by the simulator's own step(), events and refused lean steps included
    std::int64_t refused = 0;  ///< lean steps a guard (or a non-finite value) sent back to step()
  };
  [[nodiscard]] const Counts& counts() const;

 private:
  class Batch;
  std::unique_ptr<Batch> batch_;
  Counts counts_;
};

}  // namespace poundsim
