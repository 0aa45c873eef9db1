#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "granmem/sim/contact_model.hpp"
#include "granmem/sim/container.hpp"
#include "granmem/sim/grains.hpp"
#include "granmem/sim/neighbor_list.hpp"
#include "granmem/sim/pair_lanes.hpp"

namespace granmem {

// Friction of grains on the container's walls and lid (same law as between grains).
struct WallFriction {
  double mu_s = 0.2;
  double mu_r = 0.01;
  double mu_t = 0.001;
};

// The physics and numerics of a run, SI units. Defaults: the paper's table.
struct PhysicsOptions {
  ContactParameters contact;
  WallFriction wall;
  double density = 1180.0;  // acrylic, kg/m^3
  double gravity = 9.81;    // m/s^2, along -z
  double dt = 25e-6;        // s
  double skin = 5e-4;       // neighbour-list skin, m
  // Drag -rate m v and -rate I w on every grain (and -rate M v on the lid), 1/s. Only to
  // speed up settling; 0 while driven.
  double background_damping = 0;
  // Fewest time steps a collision must last; see validate().
  double min_steps_per_collision = 10;

  // Throws Error naming `where` for unphysical values, and for a time step that resolves
  // the shortest collision between grains of these radii in fewer than
  // min_steps_per_collision steps (the explicit integration would be inaccurate).
  void validate(const std::string& where, double min_radius) const;
};

// Forces the grains exert on the walls at the last step.
struct WallLoads {
  // Zeros, set explicitly: `{}` leaves Eigen's vectors uninitialised.
  std::array<Eigen::Vector3d, kWallCount> force = [] {
    std::array<Eigen::Vector3d, kWallCount> f;
    f.fill(Eigen::Vector3d::Zero());
    return f;
  }();
  std::array<int, kWallCount> contacts{};
};

// A soft-sphere DEM of grains in the container: velocity Verlet for positions, angular
// velocities and orientations, forces from ContactModel between grains and against walls,
// gravity, and the lid's motion along z. Forces on a grain are summed over its contacts in
// the order of the partners' ids, so results do not depend on the thread count, on when
// the neighbour list is rebuilt, or on the grains' order in memory.
class Simulation {
 public:
  Simulation(Grains grains, Container container, PhysicsOptions physics);

  // The driven wall's position and velocity at time t, asked once a step after time() and
  // step_count() have advanced to the step's end; default: at rest where it is.
  using WallMotion = std::function<std::pair<double, double>(double t)>;
  void set_wall_motion(WallMotion motion) { wall_motion_ = std::move(motion); }

  // Steps of velocity Verlet. Between two steps of one run() the grains are in mid-step
  // (the next step's first half is done in the force pass); after it they are at its end,
  // and run(n) gives the same state, bit for bit, as n calls of step().
  void step() { run(1); }
  void run(std::int64_t steps);

  // OpenMP threads: 0 (the default) uses one per 2,500 grains, up to omp_get_max_threads(),
  // since smaller shares do not pay for a thread's barriers; a positive count is used as is.
  // Results are the same for any count.
  void set_threads(int threads);
  int threads() const { return threads_; }
  // Threads for `grains` on `cores` that nothing else uses (a run pool's): one per 1,000
  // grains, up to the cores; with no busy core to stall a barrier, 1,000 grains on two
  // threads already run 1.8x faster than on one (docs/BENCHMARKS.md).
  static int threads_on_own_cores(std::size_t grains, int cores);

  double time() const { return time_; }
  std::int64_t step_count() const { return step_count_; }
  // Neighbour lists built so far (one when constructed, one each time a grain has moved
  // half the skin since the last).
  std::int64_t neighbor_builds() const { return neighbor_builds_; }
  const Grains& grains() const { return grains_; }
  Grains& grains() { return grains_; }
  const Container& container() const { return container_; }
  Container& container() { return container_; }
  const PhysicsOptions& physics() const { return physics_; }
  void set_background_damping(double rate) { physics_.background_damping = rate; }
  const WallLoads& wall_loads() const { return wall_loads_; }
  // Grain-grain contacts at the last step.
  std::size_t contact_count() const;
  // Of the grains and the lid.
  double kinetic_energy() const {
    const Lid& lid = container_.lid;
    return grains_.kinetic_energy() + (lid.present ? 0.5 * lid.mass * lid.v * lid.v : 0.0);
  }

  // Contact history, for checkpoints: every touching grain pair as (id, id, history), and
  // each grain's history against each wall.
  struct PairRecord {
    std::int64_t id_a, id_b;
    ContactHistory history;
  };
  std::vector<PairRecord> pair_histories() const;
  const std::vector<std::array<ContactHistory, kWallCount>>& wall_histories() const {
    return wall_history_;
  }
  // Restores a checkpoint's state: time, step, the histories above, and the wall loads of
  // the last step.
  void restore(double time, std::int64_t steps, const std::vector<PairRecord>& pairs,
               std::vector<std::array<ContactHistory, kWallCount>> walls, const WallLoads& loads);
  // Sets the forces and torques for the first half-kick without touching any history;
  // called by the constructor, and after grains or walls are moved by hand.
  void refresh_forces();

 private:
  // Forces and torques at the current positions. With `commit`, a step's: contact
  // histories are stored and the grains get the second half kick; with `drift` too, each
  // grain then gets the first half of the next step as soon as its sum is made (its
  // position is not read again in the pass). Returns whether a grain drifted beyond the
  // neighbour list's reach.
  bool compute_forces(bool commit, bool drift = false);
  // The first half of a step for every grain (half kick, drift, turn); the same return.
  bool kick_and_drift_all();
  void half_kick(std::size_t i, const Eigen::Vector3d& force, const Eigen::Vector3d& torque);
  bool drift(std::size_t i);  // whether grain i left the neighbour list's reach
  // The lid's and the drive's part of a step, between two force passes.
  void advance_walls();
  void rebuild_neighbors();

  struct PairForce {
    Eigen::Vector3d force_on_i, torque_on_i, torque_on_j;
  };
  // A thread's grains: positions [first, last) of the grains in id order.
  struct Share {
    std::size_t first, last;
  };
  Share share(int thread, int threads) const;
  // The stages of compute_forces, over one share.
  void start_sums(Share s);
  void add_incoming(Share s);
  struct Planes {
    std::array<Container::Plane, kWallCount> plane;
    int count;
  };
  // What a pass does beyond the sums (see compute_forces), and what it found.
  struct Pass {
    bool commit, drift;
    Planes planes;
    bool moved_too_far = false;
    std::vector<std::uint32_t>* wall_touchers = nullptr;  // the share's, in id order
  };
  Pass pass(bool commit, bool drift) const;
  void finish_sums(Share s, Pass& pass, PairLanes& lanes);
  void sum_wall_loads();
  // Pair k, owned by grain i: whether its grains overlap. One that does not forgets its
  // springs (with `commit`).
  bool touching(std::size_t i, std::uint32_t k, bool commit);
  // Grain i's first pair whose partner is beyond share s (its pairs are sorted by id).
  std::uint32_t first_outgoing(std::size_t i, Share s) const;
  // Pair k between grains i and j into the next lane.
  void add_pair(PairLanes& lanes, std::uint32_t k, std::size_t i, std::uint32_t j) const;
  // The touching pairs whose partner is beyond share s, evaluated into pair_force_.
  void evaluate_outgoing(Share s, bool commit, PairLanes& lanes);
  // The law on a batch of lanes; the springs and contact flags of its pairs stored.
  void evaluate_lanes(PairLanes& lanes, bool commit);

  // A grain of the share whose sum waits for a batch of lanes: its pairs in the share are
  // lanes [first_lane, last_lane); `complete` once they all are (a grain with more touching
  // pairs than a batch holds is summed over several).
  struct PendingGrain {
    std::uint32_t rank, outgoing;  // position in id order; first pair beyond the share
    int first_lane, last_lane;
    bool complete;
  };
  // Evaluates the batch and makes the pending grains' sums in id order: a grain's pairs in
  // the share, each reaction added at once to its partner, then (complete grains) its
  // pairs beyond the share, its walls and what the pass does with a finished grain.
  void sum_pending(Pass& pass, PairLanes& lanes, std::vector<PendingGrain>& pending);
  void finish_grain(std::size_t i, const PendingGrain& p, Pass& pass, Eigen::Vector3d& f,
                    Eigen::Vector3d& t);
  // Grain at rank r waits for the batch, its pairs from lane first_lane on.
  static void wait_for_lanes(std::vector<PendingGrain>& pending, std::size_t r,
                             std::uint32_t outgoing, int first_lane);
  void prefetch_wall_springs(std::size_t i) const;
  void add_walls(std::size_t i, const Planes& planes, bool commit, Eigen::Vector3d& f,
                 Eigen::Vector3d& t);

  Grains grains_;
  Container container_;
  PhysicsOptions physics_;
  ContactModel grain_contact_, wall_contact_;
  WallMotion wall_motion_;
  NeighborList neighbors_;
  std::vector<ContactHistory> pair_history_;
  std::vector<std::uint8_t> touching_;  // the pair has a committed contact history
  std::vector<std::uint8_t> active_;    // the pair overlaps at the last force evaluation
  std::vector<PairForce> pair_force_;   // of the pairs whose grains are in two shares
  std::vector<std::array<ContactHistory, kWallCount>> wall_history_;
  std::vector<std::array<Eigen::Vector3d, kWallCount>> wall_force_on_grain_;
  std::vector<std::uint8_t> wall_touch_;  // bit w: grain touches wall w
  // Per share (thread), the ranks of its grains that touch a wall at the last force
  // evaluation, in id order: the wall loads are summed over these alone.
  std::vector<std::vector<std::uint32_t>> wall_touchers_;
  std::vector<std::uint8_t> wall_remembered_;  // bit w: a committed history against wall w
  WallLoads wall_loads_;
  std::vector<std::size_t> by_id_;   // grain indices in increasing id
  std::vector<std::uint32_t> rank_;  // each grain's position in by_id_
  std::vector<double> sqrt_mass_;    // for the wall contacts' dashpots
  static constexpr std::size_t kGrainsPerThread = 2500;
  static constexpr std::size_t kGrainsPerOwnCore = 1000;
  static constexpr std::size_t kPendingGrains = 128;  // most grains waiting for one batch
  int threads_ = 1;
  double uniform_sqrt_reduced_mass_ = 0;  // > 0 when every grain has the same mass
  double time_ = 0;
  std::int64_t step_count_ = 0;
  std::int64_t neighbor_builds_ = 0;
};

}  // namespace granmem
