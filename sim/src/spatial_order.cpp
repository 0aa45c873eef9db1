#include "granmem/sim/spatial_order.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <tuple>
#include <unordered_map>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

// Grain indices in the order of layers (z), rows (y) and x, in cells one mean diameter
// high and deep; ties by id.
std::vector<std::size_t> layer_order(const Grains& g) {
  const std::size_t n = g.size();
  const double cell = 2 * std::accumulate(g.radius.begin(), g.radius.end(), 0.0) /
                      double(std::max<std::size_t>(n, 1));
  auto key = [&](std::size_t i) {
    return std::make_tuple(std::floor(g.x[i].z() / cell), std::floor(g.x[i].y() / cell), g.x[i].x(),
                           g.id[i]);
  };
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  return order;
}

}  // namespace

Simulation in_spatial_order(const Simulation& sim) {
  const Grains& g = sim.grains();
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (!g.x[i].allFinite()) {  // no order to sort by (and NaN keys would break the sort)
      throw Error("spatial order: grain " + std::to_string(g.id[i]) + " has no finite position");
    }
  }
  const std::vector<std::size_t> order = layer_order(g);
  Grains out;
  std::unordered_map<std::int64_t, std::int64_t> new_id;
  std::vector<std::array<ContactHistory, kWallCount>> walls;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    new_id[g.id[i]] = std::int64_t(k);
    out.id.push_back(std::int64_t(k));
    out.radius.push_back(g.radius[i]);
    out.mass.push_back(g.mass[i]);
    out.inv_mass.push_back(g.inv_mass[i]);
    out.inv_inertia.push_back(g.inv_inertia[i]);
    out.x.push_back(g.x[i]);
    out.v.push_back(g.v[i]);
    out.w.push_back(g.w[i]);
    out.q.push_back(g.q[i]);
    out.force.push_back(g.force[i]);
    out.torque.push_back(g.torque[i]);
    walls.push_back(sim.wall_histories()[i]);
  }
  // A pair is owned by its grain of smaller id. Where relabelling swaps the two, the
  // normal and the tangential velocity of i over j change sign, and so does the sliding
  // spring; the rolling and twisting velocities (odd in both w and n) do not.
  std::vector<Simulation::PairRecord> pairs = sim.pair_histories();
  for (Simulation::PairRecord& p : pairs) {
    p.id_a = new_id.at(p.id_a);
    p.id_b = new_id.at(p.id_b);
    if (p.id_a > p.id_b) {
      std::swap(p.id_a, p.id_b);
      p.history.slide = -p.history.slide;
    }
  }
  const std::vector<Eigen::Vector3d> force = out.force, torque = out.torque;
  Simulation next(std::move(out), sim.container(), sim.physics());
  next.set_threads(sim.threads());
  next.restore(sim.time(), sim.step_count(), pairs, std::move(walls), sim.wall_loads());
  // The forces of the last step, as they were: the next half kick uses them.
  next.grains().force = force;
  next.grains().torque = torque;
  next.container().lid.force = sim.container().lid.force;
  return next;
}

}  // namespace granmem
