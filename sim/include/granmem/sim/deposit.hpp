#pragma once

#include <cstdint>
#include <functional>
#include <ostream>
#include <string>

#include "granmem/core/random.hpp"
#include "granmem/sim/simulation.hpp"

namespace granmem {

// Preparing a packing: grains inserted without overlap on a loose jittered lattice in the
// (tall) box, falling and settling under gravity, then the lid placed on top and the
// packing settled again; the settled grains are relabelled in spatial order
// (in_spatial_order: neighbours get near ids). A seed makes it reproducible.
struct DepositOptions {
  std::int64_t grains = 2000;
  double radius = 0.0025;     // m (0.5 cm grains)
  double polydispersity = 0;  // radii uniform in radius * [1 - p, 1 + p]
  double box_side = 0.15;     // m, square box
  double lid_mass = 1.0;      // kg; 0: no lid
  std::uint64_t seed = 1;
  double insertion_speed = 0.05;  // rms random velocity at insertion, m/s
  // Settled when the kinetic energy per grain is below this, J.
  double settled_energy = 1e-13;
  double settling_damping = 5.0;  // background drag rate while settling, 1/s
  // The drag rate while a packing placed where a frame has it settles (GrainPlacement::at_rest),
  // 1/s. A scan's locating errors (~0.002 d) exceed its contacts' overlaps (~5e-4 d under the
  // paper's lid): released under the pouring drag, the overlaps kick the grains as a tap
  // would, and the placed packing settles a cycle's compaction denser than its frame (133 um
  // lower on 2,500 grains); at this drag it keeps its frame's height within ~10 um, from
  // exact frames and scans alike (docs/CALIBRATION.md, "The placed packing tapped by its own
  // settle").
  double placed_settling_damping = 1000;
  double max_settling_time = 10;  // s, per stage; not settled by then is an error
  int threads = 0;  // of its simulation: Simulation::set_threads (0: by the number of grains)

  // Throws Error for no grains, more grains than half this machine's memory holds, a
  // radius or polydispersity out of range, a box narrower than three grains, a negative lid.
  void validate() const;
};

struct DepositSummary {
  double lid_height = 0;  // m
  double packing_fraction = 0;
  double settling_time = 0;  // simulated, s
  double contacts_per_grain = 0;
};

// Progress of a long stage: simulated time, kinetic energy per grain.
using DepositProgress = std::function<void(const std::string& stage, double time, double energy)>;

// A progress callback that prints each stage's simulated time and kinetic energy per grain
// to `out`, every 0.1 s of simulated time.
DepositProgress print_deposit_progress(std::ostream& out);

Simulation deposit(const DepositOptions& options, const PhysicsOptions& physics,
                   DepositSummary* summary = nullptr, const DepositProgress& progress = {});

// Where settled_packing()'s grains come from: inserted loose above the floor (deposit()),
// or at rest where a frame has them (placed_packing.hpp), already packed.
enum class GrainPlacement { poured, at_rest };

// deposit()'s stages from `grains` already in the box: poured grains settled under gravity,
// then the lid placed on the highest grain and settled again; grains at rest in a packing
// get the lid at once (settled without it, a packing placed with no contact forces would
// first spread and sag under its own weight, then be pressed again) and settle under
// options.placed_settling_damping. The grains are relabelled in spatial order.
Simulation settled_packing(Grains grains, const DepositOptions& options,
                           const PhysicsOptions& physics, GrainPlacement placement,
                           DepositSummary* summary = nullptr, const DepositProgress& progress = {});

// Runs `sim` under the settling drag of `options` until the kinetic energy per grain is
// below options.settled_energy (deposit()'s stages); returns the simulated time it took.
// Throws Error if that takes longer than options.max_settling_time.
double settle(Simulation& sim, const DepositOptions& options, const std::string& stage,
              const DepositProgress& progress = {});

// The grains as deposit() inserts them, before anything moves: positions on the jittered
// lattice, radii, random velocities and orientations drawn from `options.seed`. deposit()
// starts from exactly these, so other codes can be started from the same state.
// Throws Error for the options and physics deposit() rejects.
Grains insert_grains(const DepositOptions& options, const PhysicsOptions& physics);

// Volume fraction of grains under the lid (or under the highest grain top without one),
// between the driven wall and the far wall.
double packing_fraction(const Simulation& sim);
// Top of the packing: the lid, or the highest grain top.
double packing_height(const Simulation& sim);

}  // namespace granmem
