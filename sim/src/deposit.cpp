#include "granmem/sim/deposit.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <memory>

#include "granmem/core/error.hpp"
#include "granmem/core/memory_budget.hpp"
#include "granmem/core/random.hpp"
#include "granmem/sim/spatial_order.hpp"

namespace granmem {

DepositProgress print_deposit_progress(std::ostream& out) {
  auto last = std::make_shared<double>(-1);
  return [&out, last](const std::string& stage, double t, double energy) {
    if (t - *last < 0.1 && t >= *last) return;  // a new stage starts again at 0
    *last = t;
    const auto flags = out.flags();
    const auto precision = out.precision();
    out << "  " << stage << ": " << std::fixed << std::setprecision(2) << t
        << " s simulated, kinetic energy per grain " << std::scientific << energy << " J\n";
    out.flags(flags);
    out.precision(precision);
  };
}

double packing_height(const Simulation& sim) {
  if (sim.container().lid.present) return sim.container().lid.z;
  const Grains& g = sim.grains();
  double top = 0;
  for (std::size_t i = 0; i < g.size(); ++i)
    top = std::max(top, g.x[i].z() + g.radius[i]);
  return top;
}

double packing_fraction(const Simulation& sim) {
  const Grains& g = sim.grains();
  const Container& c = sim.container();
  double volume = 0;
  for (double r : g.radius)
    volume += 4.0 / 3.0 * M_PI * r * r * r;
  const double box = c.size.x() * (c.size.y() - c.y_wall) * packing_height(sim);
  return box > 0 ? volume / box : 0;
}

double settle(Simulation& sim, const DepositOptions& o, const std::string& stage,
              const DepositProgress& progress) {
  const double n = double(std::max<std::size_t>(sim.grains().size(), 1));
  const auto chunk = std::max<std::int64_t>(1, std::llround(0.01 / sim.physics().dt));
  const double start = sim.time();
  sim.set_background_damping(o.settling_damping);
  while (true) {
    sim.run(chunk);
    const double energy = sim.kinetic_energy() / n;
    if (progress) progress(stage, sim.time() - start, energy);
    if (energy < o.settled_energy) break;
    if (sim.time() - start > o.max_settling_time) {
      throw Error("deposit: " + stage + " not settled after " +
                  std::to_string(o.max_settling_time) +
                  " s of simulated time (kinetic energy per grain " + std::to_string(energy) +
                  " J, wanted < " + std::to_string(o.settled_energy) + " J)");
    }
  }
  sim.set_background_damping(0);
  return sim.time() - start;
}

void DepositOptions::validate() const {
  if (grains < 1) throw Error("deposit: needs at least one grain");
  // ~2.4-3.1 KB a grain measured (docs/BENCHMARKS.md, state, neighbour lists, contacts).
  check_memory_budget(3e3 * double(grains),
                      "deposit: " + std::to_string(grains) + " grains (~3 KB each)");
  if (!(radius > 0)) throw Error("deposit: grain radius must be positive");
  if (!(polydispersity >= 0 && polydispersity < 1)) {
    throw Error("deposit: polydispersity must be in [0, 1)");
  }
  if (!(box_side > 6 * radius * (1 + polydispersity))) {
    throw Error("deposit: the box must be wider than three grains");
  }
  if (!(lid_mass >= 0)) throw Error("deposit: lid mass must be zero or positive");
}

Grains insert_grains(const DepositOptions& o, const PhysicsOptions& physics) {
  o.validate();
  const double r_max = o.radius * (1 + o.polydispersity);
  physics.validate("deposit", o.radius * (1 - o.polydispersity));

  // A loose lattice with gaps, so that random shifts never make grains overlap each other
  // or the walls: every site is at least r_max + jitter from the floor and the side walls.
  Random random(o.seed);
  const double spacing = 2.4 * r_max, jitter = 0.45 * (spacing - 2 * r_max);
  const double margin = r_max + jitter;
  const auto per_row =
      static_cast<std::int64_t>(std::floor((o.box_side - 2 * margin) / spacing)) + 1;
  Grains grains;
  for (std::int64_t k = 0; k < o.grains; ++k) {
    const std::int64_t layer = k / (per_row * per_row), in_layer = k % (per_row * per_row);
    const Eigen::Vector3d site(margin + spacing * double(in_layer % per_row),
                               margin + spacing * double(in_layer / per_row),
                               r_max + spacing * double(layer));
    // Each vector's draws are made last component first, in statements of their own
    // (normal_vector in random.hpp), so that every compiler deposits the same packing.
    const double shift_z = jitter * random.uniform();
    const double shift_y = jitter * (2 * random.uniform() - 1);
    const double shift_x = jitter * (2 * random.uniform() - 1);
    const Eigen::Vector3d shift(shift_x, shift_y, shift_z);
    const double r = o.radius * (1 + o.polydispersity * (2 * random.uniform() - 1));
    grains.add(k, site + shift, r, physics.density);
    grains.v.back() = o.insertion_speed * normal_vector(random);
    // Random orientation: a normalised Gaussian quaternion is uniform on rotations.
    const double qz = random.normal(), qy = random.normal(), qx = random.normal();
    const double qw = random.normal();
    grains.q.back() = Eigen::Quaterniond(qw, qx, qy, qz).normalized();
  }
  return grains;
}

Simulation deposit(const DepositOptions& o, const PhysicsOptions& physics, DepositSummary* summary,
                   const DepositProgress& progress) {
  return settled_packing(insert_grains(o, physics), o, physics, GrainPlacement::poured, summary,
                         progress);
}

Simulation settled_packing(Grains grains, const DepositOptions& o, const PhysicsOptions& physics,
                           GrainPlacement placement, DepositSummary* summary,
                           const DepositProgress& progress) {
  Container box;
  box.size = {o.box_side, o.box_side};

  Simulation sim(std::move(grains), box, physics);
  sim.set_threads(o.threads);
  double settling = placement == GrainPlacement::poured ? settle(sim, o, "falling", progress) : 0.0;
  DepositOptions settled = o;
  if (placement == GrainPlacement::at_rest) settled.settling_damping = o.placed_settling_damping;

  if (o.lid_mass > 0) {
    const double top = packing_height(sim);
    Lid& lid = sim.container().lid;
    lid.present = true;
    lid.mass = o.lid_mass;
    lid.z = top;  // resting on the highest grain
    lid.v = 0;
    sim.refresh_forces();
    settling += settle(sim, settled, "under the lid", progress);
  } else if (placement == GrainPlacement::at_rest) {
    settling += settle(sim, settled, "in place", progress);
  }
  sim = in_spatial_order(sim);
  if (summary) {
    summary->lid_height = packing_height(sim);
    summary->packing_fraction = packing_fraction(sim);
    summary->settling_time = settling;
    summary->contacts_per_grain = 2.0 * double(sim.contact_count()) / double(sim.grains().size());
  }
  return sim;
}

}  // namespace granmem
