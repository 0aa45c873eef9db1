#include "granmem/sim/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include <omp.h>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

// Orientation q turned by the rotation vector `turn` (a sphere's w is constant over a
// step, so this is exact). For the small turns of a step, sin and cos of the half angle
// come from their series, exact to double precision below 1e-2 rad; by multiplications
// (a division costs as much as the rest of the step's integration).
GRANMEM_INLINE Eigen::Quaterniond turned(const Eigen::Quaterniond& q, const Eigen::Vector3d& turn) {
  const double angle_sq = turn.squaredNorm();
  if (angle_sq == 0) return q;
  double c, s_over_angle;  // cos(angle/2), sin(angle/2)/angle
  if (angle_sq < 1e-4) {
    const double h2 = 0.25 * angle_sq;  // (angle/2)^2
    constexpr double k2 = 1.0 / 2, k12 = 1.0 / 12, k30 = 1.0 / 30, k56 = 1.0 / 56;
    constexpr double k6 = 1.0 / 6, k20 = 1.0 / 20, k42 = 1.0 / 42, k72 = 1.0 / 72;
    c = 1 - h2 * k2 * (1 - h2 * k12 * (1 - h2 * k30 * (1 - h2 * k56)));
    s_over_angle = 0.5 * (1 - h2 * k6 * (1 - h2 * k20 * (1 - h2 * k42 * (1 - h2 * k72))));
  } else {
    const double angle = std::sqrt(angle_sq);
    c = std::cos(0.5 * angle);
    s_over_angle = std::sin(0.5 * angle) / angle;
  }
  const Eigen::Vector3d v = s_over_angle * turn;
  Eigen::Quaterniond out = Eigen::Quaterniond(c, v.x(), v.y(), v.z()) * q;
  // Back to unit length: q is a unit to rounding, and so 1/sqrt(n2) = 1 - (n2 - 1)/2 to
  // O((n2 - 1)^2) (below rounding here), without the square root and division that held
  // up the step.
  const double n2 = out.coeffs().squaredNorm();
  out.coeffs() *= std::abs(n2 - 1) < 1e-8 ? 1.5 - 0.5 * n2 : 1 / std::sqrt(n2);
  return out;
}

}  // namespace

void PhysicsOptions::validate(const std::string& where, double min_radius) const {
  contact.validate(where);
  auto require = [&](bool ok, const std::string& what) {
    if (!ok) throw Error(where + ": " + what);
  };
  require(std::isfinite(density) && density > 0, "density must be positive");
  require(std::isfinite(gravity) && gravity >= 0, "gravity must be zero or positive");
  require(std::isfinite(dt) && dt > 0, "time step must be positive");
  require(std::isfinite(skin) && skin > 0, "neighbour skin must be positive");
  require(std::isfinite(background_damping) && background_damping >= 0,
          "background damping must be zero or positive");
  require(wall.mu_s >= 0 && wall.mu_r >= 0 && wall.mu_t >= 0, "wall friction must be >= 0");
  require(min_radius > 0, "grain radius must be positive");
  // The shortest collision: two of the smallest grains (a wall, of infinite mass, gives a
  // longer one).
  const double m = 4.0 / 3.0 * M_PI * std::pow(min_radius, 3) * density;
  const double duration = contact_duration(contact.k_n, contact.restitution_n, m / 2);
  if (duration < min_steps_per_collision * dt) {
    throw Error(where + ": time step " + std::to_string(dt * 1e6) + " us resolves a collision of " +
                std::to_string(duration * 1e6) + " us (k_n " + std::to_string(contact.k_n) +
                " N/m, radius " + std::to_string(min_radius) + " m) in " +
                std::to_string(duration / dt) + " steps; it needs at least " +
                std::to_string(min_steps_per_collision) +
                ": use dt <= " + std::to_string(duration / min_steps_per_collision * 1e6) + " us");
  }
}

Simulation::Simulation(Grains grains, Container container, PhysicsOptions physics)
    : grains_(std::move(grains)),
      container_(container),
      physics_(physics),
      grain_contact_(physics.contact),
      wall_contact_(physics.contact, physics.wall.mu_s, physics.wall.mu_r, physics.wall.mu_t),
      neighbors_(physics.skin) {
  const double r_min =
      grains_.size() ? *std::min_element(grains_.radius.begin(), grains_.radius.end()) : 1.0;
  physics_.validate("simulation", r_min);
  set_threads(0);
  by_id_.resize(grains_.size());
  std::iota(by_id_.begin(), by_id_.end(), std::size_t{0});
  std::sort(by_id_.begin(), by_id_.end(),
            [&](std::size_t a, std::size_t b) { return grains_.id[a] < grains_.id[b]; });
  rank_.resize(grains_.size());
  for (std::size_t r = 0; r < by_id_.size(); ++r)
    rank_[by_id_[r]] = std::uint32_t(r);
  if (!grains_.mass.empty() && std::all_of(grains_.mass.begin(), grains_.mass.end(),
                                           [&](double m) { return m == grains_.mass.front(); })) {
    uniform_sqrt_reduced_mass_ = sqrt_reduced_mass(grains_.mass.front(), grains_.mass.front());
  }
  sqrt_mass_.resize(grains_.size());
  for (std::size_t i = 0; i < grains_.size(); ++i)
    sqrt_mass_[i] = std::sqrt(grains_.mass[i]);
  wall_history_.assign(grains_.size(), {});
  wall_force_on_grain_.assign(grains_.size(), {});
  wall_touch_.assign(grains_.size(), 0);
  wall_remembered_.assign(grains_.size(), 0);
  rebuild_neighbors();
  refresh_forces();
}

void Simulation::set_threads(int threads) {
  // Threads pay for their barriers only with enough grains each (and a thread spinning at a
  // barrier on a busy core can stall a small run for a whole time slice).
  threads_ = threads > 0
                 ? threads
                 : std::clamp(int(grains_.size() / kGrainsPerThread), 1, omp_get_max_threads());
  neighbors_.set_threads(threads_);
  wall_touchers_.assign(std::size_t(threads_), {});
}

int Simulation::threads_on_own_cores(std::size_t grains, int cores) {
  return std::clamp(int(grains / kGrainsPerOwnCore), 1, std::max(1, cores));
}

void Simulation::rebuild_neighbors() {
  NeighborList next(physics_.skin);
  next.set_threads(threads_);
  next.build(grains_);
  pair_history_ = next.carry(neighbors_, pair_history_, grains_.id, ContactHistory{});
  touching_ = next.carry(neighbors_, touching_, grains_.id, std::uint8_t{0});
  neighbors_ = std::move(next);
  ++neighbor_builds_;
  pair_force_.resize(neighbors_.pair_count());
  active_.assign(neighbors_.pair_count(), 0);
}

void Simulation::refresh_forces() {
  compute_forces(false);
}

GRANMEM_INLINE bool Simulation::touching(std::size_t i, std::uint32_t k, bool commit) {
  const Grains& g = grains_;
  const std::uint32_t j = neighbors_.partner()[k];
  const double reach = g.radius[i] + g.radius[j];
  if ((g.x[i] - g.x[j]).squaredNorm() < reach * reach) return true;
  active_[k] = 0;
  if (commit && touching_[k]) {
    touching_[k] = 0;
    pair_history_[k] = ContactHistory{};  // the contact broke: forget its springs
  }
  return false;
}

std::uint32_t Simulation::first_outgoing(std::size_t i, Share s) const {
  const auto& partner = neighbors_.partner();
  // Partners are sorted by id: those of another share are the last ones.
  std::uint32_t k = neighbors_.end(i);
  if (s.last == grains_.size()) return k;  // the last share
  while (k > neighbors_.begin(i) && rank_[partner[k - 1]] >= s.last)
    --k;
  return k;
}

GRANMEM_INLINE void Simulation::add_pair(PairLanes& lanes, std::uint32_t k, std::size_t i,
                                         std::uint32_t j) const {
  const Grains& g = grains_;
  const double sqrt_m = uniform_sqrt_reduced_mass_ > 0 ? uniform_sqrt_reduced_mass_
                                                       : sqrt_reduced_mass(g.mass[i], g.mass[j]);
  lanes.add(k, g.x[i], g.x[j], g.v[i], g.v[j], g.w[i], g.w[j], g.radius[i], g.radius[j], sqrt_m,
            pair_history_[k]);
}

void Simulation::evaluate_outgoing(Share s, bool commit, PairLanes& lanes) {
  const auto& partner = neighbors_.partner();
  auto store = [&] {
    evaluate_lanes(lanes, commit);
    for (int l = 0; l < lanes.count; ++l) {
      PairForce& f = pair_force_[lanes.pair[l]];
      for (int a = 0; a < 3; ++a) {
        f.force_on_i[a] = lanes.force_on_i[a][l];
        f.torque_on_i[a] = lanes.torque_on_i[a][l];
        f.torque_on_j[a] = lanes.torque_on_j[a][l];
      }
    }
    lanes.count = 0;
  };
  for (std::size_t r = s.first; r < s.last; ++r) {
    const std::size_t i = by_id_[r];
    for (std::uint32_t k = first_outgoing(i, s); k < neighbors_.end(i); ++k) {
      if (!touching(i, k, commit)) continue;
      add_pair(lanes, k, i, partner[k]);
      if (lanes.full()) store();
    }
  }
  store();
}

void Simulation::evaluate_lanes(PairLanes& lanes, bool commit) {
  evaluate_pair_lanes(grain_contact_, lanes, physics_.dt);
  for (int l = 0; l < lanes.count; ++l) {
    const std::uint32_t k = lanes.pair[l];
    active_[k] = 1;
    if (commit) {
      pair_history_[k] = lanes.history(l);
      touching_[k] = 1;
    }
  }
}

// Field by field: a whole record built on the stack and copied stalls on the copy.
GRANMEM_INLINE void Simulation::wait_for_lanes(std::vector<PendingGrain>& pending, std::size_t r,
                                               std::uint32_t outgoing, int first_lane) {
  PendingGrain& p = pending.emplace_back();
  p.rank = std::uint32_t(r);
  p.outgoing = outgoing;
  p.first_lane = p.last_lane = first_lane;
  p.complete = false;
}

// The springs of the walls grain i touched at the last step, whose sum comes a batch later:
// these lines are read for a fifth of the grains only, too sparsely for the hardware to
// fetch them ahead.
GRANMEM_INLINE void Simulation::prefetch_wall_springs(std::size_t i) const {
  for (std::uint8_t walls = wall_remembered_[i]; walls != 0; walls &= std::uint8_t(walls - 1)) {
    const ContactHistory* h = &wall_history_[i][__builtin_ctz(walls)];
    __builtin_prefetch(h);
    __builtin_prefetch(reinterpret_cast<const char*>(h + 1) - 1);
  }
}

GRANMEM_INLINE void Simulation::add_walls(std::size_t i, const Planes& planes, bool commit,
                                          Eigen::Vector3d& f, Eigen::Vector3d& t) {
  const Grains& g = grains_;
  std::uint8_t touch = 0;
  const std::uint8_t remembered = wall_remembered_[i];
  for (int w = 0; w < planes.count; ++w) {
    const Container::Plane& p = planes.plane[w];
    const double distance = p.normal.dot(g.x[i]) - p.offset;
    ContactHistory& history = wall_history_[i][w];
    if (distance >= g.radius[i]) {
      // Forget a broken contact's springs (only where there are some: this loop runs for
      // every grain and wall each step).
      if (commit && (remembered & (1u << w))) history = ContactHistory{};
      continue;
    }
    const ContactGeometry geometry =
        wall_contact(distance, p.normal, g.radius[i], g.v[i], g.w[i], sqrt_mass_[i], p.velocity);
    const ContactForces c = wall_contact_.evaluate(geometry, history, physics_.dt);
    if (commit) history = c.history;
    f += c.force_on_i;
    t += c.torque_on_i;
    wall_force_on_grain_[i][w] = -c.force_on_i;
    touch |= std::uint8_t(1u << w);
  }
  wall_touch_[i] = touch;
  if (commit) wall_remembered_[i] = touch;
}

Simulation::Share Simulation::share(int thread, int threads) const {
  const std::size_t n = grains_.size();
  return {n * std::size_t(thread) / std::size_t(threads),
          n * std::size_t(thread + 1) / std::size_t(threads)};
}

void Simulation::start_sums(Share s) {
  const Eigen::Vector3d gravity(0, 0, -physics_.gravity);
  const double drag = physics_.background_damping;
  Grains& g = grains_;
  for (std::size_t r = s.first; r < s.last; ++r) {
    const std::size_t i = by_id_[r];
    g.force[i] = g.mass[i] * gravity;
    g.torque[i] = Eigen::Vector3d::Zero();
    if (drag > 0) {
      g.force[i] -= drag * g.mass[i] * g.v[i];
      g.torque[i] -= drag / g.inv_inertia[i] * g.w[i];
    }
  }
}

void Simulation::add_incoming(Share s) {
  const auto& incoming = neighbors_.incoming();
  const auto& owner = neighbors_.owner();
  Grains& g = grains_;
  for (std::size_t r = s.first; r < s.last; ++r) {
    const std::size_t j = by_id_[r];
    // Owners are sorted by id: those of another share are the first ones.
    for (std::uint32_t e = neighbors_.incoming_begin(j); e < neighbors_.incoming_end(j); ++e) {
      const std::uint32_t k = incoming[e];
      if (rank_[owner[k]] >= s.first) break;
      if (!active_[k]) continue;
      g.force[j] -= pair_force_[k].force_on_i;
      g.torque[j] += pair_force_[k].torque_on_j;
    }
  }
}

Simulation::Pass Simulation::pass(bool commit, bool drift) const {
  Pass p{commit, drift && commit, {}, false};
  p.planes.count = container_.lid.present ? kWallCount : kWallCount - 1;
  for (int w = 0; w < p.planes.count; ++w)
    p.planes.plane[w] = container_.plane(static_cast<Wall>(w));
  return p;
}

void Simulation::finish_sums(Share s, Pass& pass, PairLanes& lanes) {
  const auto& partner = neighbors_.partner();
  std::vector<PendingGrain> pending;
  pending.reserve(kPendingGrains + 1);
  for (std::size_t r = s.first; r < s.last; ++r) {
    const std::size_t i = by_id_[r];
    const std::uint32_t outgoing = first_outgoing(i, s);
    wait_for_lanes(pending, r, outgoing, lanes.count);
    prefetch_wall_springs(i);
    for (std::uint32_t k = neighbors_.begin(i); k < outgoing; ++k) {
      if (!touching(i, k, pass.commit)) continue;
      add_pair(lanes, k, i, partner[k]);
      if (lanes.full()) {
        pending.back().last_lane = lanes.count;
        sum_pending(pass, lanes, pending);
        wait_for_lanes(pending, r, outgoing, 0);
      }
    }
    pending.back().last_lane = lanes.count;
    pending.back().complete = true;
    if (pending.size() >= kPendingGrains) sum_pending(pass, lanes, pending);
  }
  sum_pending(pass, lanes, pending);
}

void Simulation::sum_pending(Pass& pass, PairLanes& lanes, std::vector<PendingGrain>& pending) {
  evaluate_lanes(lanes, pass.commit);
  Grains& g = grains_;
  const auto& partner = neighbors_.partner();
  for (const PendingGrain& p : pending) {
    const std::size_t i = by_id_[p.rank];
    // Every pair of smaller owner id has been added to grain i: its own come next, in
    // partner-id order, each reaction added at once to its partner.
    Eigen::Vector3d f = g.force[i], t = g.torque[i];
    for (int l = p.first_lane; l < p.last_lane; ++l) {
      const std::uint32_t j = partner[lanes.pair[l]];
      // As vectors, as f and t are used after: a vector read of what was stored by
      // components stalls.
      const Eigen::Vector3d force(lanes.force_on_i[0][l], lanes.force_on_i[1][l],
                                  lanes.force_on_i[2][l]);
      f += force;
      t += Eigen::Vector3d(lanes.torque_on_i[0][l], lanes.torque_on_i[1][l],
                           lanes.torque_on_i[2][l]);
      g.force[j] -= force;
      g.torque[j] += Eigen::Vector3d(lanes.torque_on_j[0][l], lanes.torque_on_j[1][l],
                                     lanes.torque_on_j[2][l]);
    }
    if (p.complete) finish_grain(i, p, pass, f, t);
    g.force[i] = f;
    g.torque[i] = t;
  }
  lanes.count = 0;
  pending.clear();
}

// Grain i's sum is made once its pairs beyond the share and its walls are added; nothing
// later in the pass reads its position or velocity (its partners in the share have larger
// ids, and those in other shares were evaluated before the barrier).
GRANMEM_INLINE void Simulation::finish_grain(std::size_t i, const PendingGrain& p, Pass& pass,
                                             Eigen::Vector3d& f, Eigen::Vector3d& t) {
  for (std::uint32_t k = p.outgoing; k < neighbors_.end(i); ++k) {
    if (!active_[k]) continue;
    f += pair_force_[k].force_on_i;
    t += pair_force_[k].torque_on_i;
  }
  add_walls(i, pass.planes, pass.commit, f, t);
  if (wall_touch_[i]) pass.wall_touchers->push_back(p.rank);
  if (!pass.commit) return;
  half_kick(i, f, t);  // the step's second half kick, while the grain is at hand
  if (!pass.drift) return;
  half_kick(i, f, t);  // and the next step's first half
  if (drift(i)) pass.moved_too_far = true;
}

GRANMEM_INLINE void Simulation::half_kick(std::size_t i, const Eigen::Vector3d& force,
                                          const Eigen::Vector3d& torque) {
  Grains& g = grains_;
  const double half_dt = 0.5 * physics_.dt;
  g.v[i] += half_dt * g.inv_mass[i] * force;
  g.w[i] += half_dt * g.inv_inertia[i] * torque;
}

GRANMEM_INLINE bool Simulation::drift(std::size_t i) {
  Grains& g = grains_;
  const double dt = physics_.dt;
  g.x[i] += dt * g.v[i];
  g.q[i] = turned(g.q[i], g.w[i] * dt);
  return neighbors_.moved_too_far(g.x[i], i);
}

// Each grain's forces are summed in the order of its partners' ids: gravity and drag, the
// pairs it is partner of (owners of smaller id, in id order), then its own pairs (partners
// of larger id, in id order), then the walls. Grains are walked in id order, each thread
// over one share of consecutive ids: their touching pairs fill a batch of lanes
// (pair_lanes.hpp); when it is full the law runs on it and the waiting grains' sums are
// made from it, each reaction added at once to its partner (no pair force is stored);
// across shares, the pairs are evaluated first and their reactions added before the
// share's own (their owners' ids are smaller than any in the share).
bool Simulation::compute_forces(bool commit, bool drift) {
  bool moved_too_far = false;
  for (auto& touchers : wall_touchers_)
    touchers.clear();
#pragma omp parallel num_threads(threads_) reduction(|| : moved_too_far)
  {
    const int threads = omp_get_num_threads();
    const int thread = omp_get_thread_num();
    const Share s = share(thread, threads);
    Pass p = pass(commit, drift);
    p.wall_touchers = &wall_touchers_[std::size_t(thread)];
    PairLanes lanes;
    start_sums(s);
    if (threads > 1) {
      evaluate_outgoing(s, commit, lanes);
#pragma omp barrier
      add_incoming(s);
    }
    finish_sums(s, p, lanes);
    moved_too_far = p.moved_too_far;
  }
  sum_wall_loads();
  return moved_too_far;
}

void Simulation::sum_wall_loads() {
  const int walls = container_.lid.present ? kWallCount : kWallCount - 1;
  // Loads on the walls, summed in the order of grain ids (the lid's motion depends on them):
  // the shares' lists of grains at a wall, in share order.
  wall_loads_ = WallLoads{};
  for (const auto& touchers : wall_touchers_) {
    for (std::uint32_t r : touchers) {
      const std::size_t i = by_id_[r];
      for (int w = 0; w < walls; ++w) {
        if (wall_touch_[i] & (1u << w)) {
          wall_loads_.force[w] += wall_force_on_grain_[i][w];
          ++wall_loads_.contacts[w];
        }
      }
    }
  }
  Lid& lid = container_.lid;
  if (lid.present) {
    lid.force = wall_loads_.force[int(Wall::lid)].z() - lid.mass * physics_.gravity -
                physics_.background_damping * lid.mass * lid.v;
  }
}

bool Simulation::kick_and_drift_all() {
  Grains& g = grains_;
  const std::size_t n = g.size();
  bool moved_too_far = false;
#pragma omp parallel for schedule(static) reduction(|| : moved_too_far) num_threads(threads_)
  for (std::size_t i = 0; i < n; ++i) {
    half_kick(i, g.force[i], g.torque[i]);
    if (drift(i)) moved_too_far = true;
  }
  return moved_too_far;
}

void Simulation::advance_walls() {
  const double dt = physics_.dt;
  Lid& lid = container_.lid;
  if (lid.present) {
    lid.v += 0.5 * dt * lid.force / lid.mass;
    lid.z += dt * lid.v;
  }
  time_ += dt;
  ++step_count_;
  if (wall_motion_) {
    std::tie(container_.y_wall, container_.y_wall_velocity) = wall_motion_(time_);
  }
}

// Each step: the grains' first half (half kick, drift, turn), the lid's and the drive's,
// a new neighbour list if a grain left its reach, the force pass with the grains' second
// half kick, the lid's. Within a run the next step's first half for the grains is done in
// the force pass, which saves a pass over every grain.
void Simulation::run(std::int64_t steps) {
  if (steps <= 0) return;
  bool stale = kick_and_drift_all();
  for (std::int64_t s = 0; s < steps; ++s) {
    advance_walls();
    if (stale) rebuild_neighbors();
    stale = compute_forces(true, s + 1 < steps);
    Lid& lid = container_.lid;
    if (lid.present) lid.v += 0.5 * physics_.dt * lid.force / lid.mass;
  }
}

std::size_t Simulation::contact_count() const {
  std::size_t c = 0;
  for (std::uint8_t t : active_)
    c += t;
  return c;
}

std::vector<Simulation::PairRecord> Simulation::pair_histories() const {
  std::vector<PairRecord> out;
  const auto& owner = neighbors_.owner();
  const auto& partner = neighbors_.partner();
  for (std::size_t k = 0; k < partner.size(); ++k) {
    if (touching_[k]) {
      out.push_back({grains_.id[owner[k]], grains_.id[partner[k]], pair_history_[k]});
    }
  }
  return out;
}

void Simulation::restore(double time, std::int64_t steps, const std::vector<PairRecord>& pairs,
                         std::vector<std::array<ContactHistory, kWallCount>> walls,
                         const WallLoads& loads) {
  if (walls.size() != grains_.size()) {
    throw Error("checkpoint: wall histories for " + std::to_string(walls.size()) +
                " grains, the state has " + std::to_string(grains_.size()));
  }
  time_ = time;
  step_count_ = steps;
  wall_history_ = std::move(walls);
  for (std::size_t i = 0; i < grains_.size(); ++i) {
    wall_remembered_[i] = 0;
    for (int w = 0; w < kWallCount; ++w) {
      const ContactHistory& h = wall_history_[i][w];
      const bool kept = h.slide.squaredNorm() > 0 || h.roll.squaredNorm() > 0 || h.twist != 0;
      if (kept) wall_remembered_[i] |= std::uint8_t(1u << w);
    }
  }
  std::unordered_map<std::int64_t, std::uint32_t> index;
  for (std::size_t i = 0; i < grains_.size(); ++i)
    index[grains_.id[i]] = std::uint32_t(i);
  neighbors_ = NeighborList(physics_.skin);
  neighbors_.set_threads(threads_);
  rebuild_neighbors();
  std::fill(pair_history_.begin(), pair_history_.end(), ContactHistory{});
  std::fill(touching_.begin(), touching_.end(), 0);
  const auto& partner = neighbors_.partner();
  for (const PairRecord& p : pairs) {
    const auto a = index.find(p.id_a), b = index.find(p.id_b);
    if (a == index.end() || b == index.end()) {
      throw Error("checkpoint: contact between unknown grains " + std::to_string(p.id_a) + " and " +
                  std::to_string(p.id_b));
    }
    const std::uint32_t i = a->second;
    bool found = false;
    for (std::uint32_t k = neighbors_.begin(i); k < neighbors_.end(i); ++k) {
      if (partner[k] == b->second) {
        pair_history_[k] = p.history;
        touching_[k] = 1;
        found = true;
      }
    }
    if (!found) {
      throw Error("checkpoint: grains " + std::to_string(p.id_a) + " and " +
                  std::to_string(p.id_b) + " are in contact but not neighbours");
    }
  }
  // Histories are committed every step, so the pairs that have one are those that touched
  // at the last step.
  active_ = touching_;
  wall_loads_ = loads;
}

}  // namespace granmem
