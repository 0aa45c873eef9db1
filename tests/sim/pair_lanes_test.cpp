// The batched contact law against the one-pair law: every lane of evaluate_pair_lanes must
// give what ContactModel::evaluate gives for that pair alone (forces, moments and springs,
// to rounding: the two are compiled apart, Eigen's own vector code in one only), for
// contacts that stick and contacts that slip, with every combination of the rolling and
// twisting modes, unequal grains, and batches that do not fill whole vectors. And a pair's
// result must not depend, to the bit, on its place in a batch: the simulation's sums are
// the same for any thread count only if that holds.
#include <gtest/gtest.h>

#include <array>
#include <random>

#include "granmem/sim/pair_lanes.hpp"

namespace granmem {
namespace {

constexpr double kDt = 25e-6, kDensity = 1180;

struct Pair {
  Eigen::Vector3d xi, xj, vi, vj, wi, wj;
  double ri, rj, sqrt_m;
  ContactHistory before;
};

// Overlaps up to 0.2 mm, relative speeds up to 2 cm/s, spins up to 10 rad/s, springs up to
// 10 um: most sliders stick, some slip, rolling ones mostly slip.
std::vector<Pair> random_pairs(int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), r(0.002, 0.003), overlap(0, 2e-4);
  auto vec = [&](double scale) -> Eigen::Vector3d {
    return Eigen::Vector3d(u(rng), u(rng), u(rng)) * scale;
  };
  std::vector<Pair> pairs;
  for (int c = 0; c < count; ++c) {
    Pair p;
    p.ri = r(rng);
    p.rj = r(rng);
    const Eigen::Vector3d n = vec(1).normalized();
    p.xi = vec(0.05);
    p.xj = p.xi - (p.ri + p.rj - overlap(rng)) * n;
    p.vi = vec(0.01);
    p.vj = vec(0.01);
    p.wi = vec(10);
    p.wj = vec(10);
    const double mi = 4.0 / 3.0 * M_PI * std::pow(p.ri, 3) * kDensity;
    const double mj = 4.0 / 3.0 * M_PI * std::pow(p.rj, 3) * kDensity;
    p.sqrt_m = sqrt_reduced_mass(mi, mj);
    p.before.slide = vec(1e-5);
    p.before.roll = vec(1e-5);
    p.before.twist = u(rng) * 1e-5;
    if (c % 7 == 0) p.before = ContactHistory{};  // a contact that has just formed
    pairs.push_back(p);
  }
  return pairs;
}

// Lane against one-pair law: each component to 1e-9 of its vector's length (rounding,
// amplified where the tangential velocity is a small difference of large ones).
void expect_close(const double lane[3][PairLanes::kCapacity], int l, const Eigen::Vector3d& one,
                  const char* what, int index) {
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(lane[a][l], one[a], 1e-9 * one.norm() + 1e-300) << what << " of pair " << index;
}

struct Result {
  std::array<double, 16> values;  // forces, moments, springs
};

// Evaluates the pairs in batches of `batch`, checks each lane against the one-pair law and
// returns every pair's result; counts the sliding springs that slipped.
std::vector<Result> check_batches(const ContactParameters& params, int batch, int& slipping) {
  const ContactModel model(params);
  const std::vector<Pair> pairs = random_pairs(200, 7);
  std::vector<Result> results(pairs.size());
  PairLanes lanes;
  for (std::size_t first = 0; first < pairs.size(); first += batch) {
    lanes.count = 0;
    const std::size_t last = std::min(pairs.size(), first + batch);
    for (std::size_t c = first; c < last; ++c) {
      const Pair& p = pairs[c];
      lanes.add(std::uint32_t(c), p.xi, p.xj, p.vi, p.vj, p.wi, p.wj, p.ri, p.rj, p.sqrt_m,
                p.before);
    }
    evaluate_pair_lanes(model, lanes, kDt);
    EXPECT_EQ(lanes.count, int(last - first));
    for (int l = 0; l < lanes.count; ++l) {
      const int c = int(lanes.pair[l]);
      const Pair& p = pairs[c];
      const ContactGeometry g =
          sphere_contact(p.xi, p.xj, p.ri, p.rj, p.vi, p.vj, p.wi, p.wj, p.sqrt_m);
      const ContactForces one = model.evaluate(g, p.before, kDt);
      expect_close(lanes.force_on_i, l, one.force_on_i, "force", c);
      expect_close(lanes.torque_on_i, l, one.torque_on_i, "moment on i", c);
      expect_close(lanes.torque_on_j, l, one.torque_on_j, "moment on j", c);
      expect_close(lanes.slide, l, one.history.slide, "sliding spring", c);
      expect_close(lanes.roll, l, one.history.roll, "rolling spring", c);
      EXPECT_NEAR(lanes.twist[l], one.history.twist, 1e-9 * std::abs(one.history.twist) + 1e-300)
          << "twisting spring of pair " << c;
      const Eigen::Vector3d slid = onto_tangent_plane(p.before.slide, g.n) + g.v_t * kDt;
      if ((slid - one.history.slide).norm() > 1e-9 * slid.norm()) ++slipping;
      Result& r = results[c];
      for (int a = 0; a < 3; ++a) {
        r.values[a] = lanes.force_on_i[a][l];
        r.values[3 + a] = lanes.torque_on_i[a][l];
        r.values[6 + a] = lanes.torque_on_j[a][l];
        r.values[9 + a] = lanes.slide[a][l];
        r.values[12 + a] = lanes.roll[a][l];
      }
      r.values[15] = lanes.twist[l];
    }
  }
  return results;
}

void expect_same_bits(const std::vector<Result>& a, const std::vector<Result>& b) {
  for (std::size_t c = 0; c < a.size(); ++c) {
    for (std::size_t v = 0; v < a[c].values.size(); ++v)
      EXPECT_EQ(a[c].values[v], b[c].values[v]) << "value " << v << " of pair " << c;
  }
}

TEST(PairLanes, EveryLaneIsTheOnePairLawWithAllModes) {
  ContactParameters p;
  p.mu_s = 0.2;
  p.mu_r = 0.05;
  p.mu_t = 0.1;
  int slipping = 0;
  const auto full = check_batches(p, PairLanes::kCapacity, slipping);
  const auto partial = check_batches(p, 13, slipping);  // batches that end inside a vector
  expect_same_bits(full, partial);
  // The check covers both branches of the slider.
  EXPECT_GT(slipping, 20);
  EXPECT_LT(slipping, 380);
}

TEST(PairLanes, EveryLaneIsTheOnePairLawWithModesOff) {
  for (const auto& [mu_r, mu_t] : {std::pair{0.0, 0.0}, {0.05, 0.0}, {0.0, 0.1}}) {
    ContactParameters p;
    p.mu_r = mu_r;
    p.mu_t = mu_t;
    int slipping = 0;
    expect_same_bits(check_batches(p, 29, slipping), check_batches(p, 1, slipping));
    EXPECT_GT(slipping, 0) << "mu_r " << mu_r << ", mu_t " << mu_t;
  }
}

}  // namespace
}  // namespace granmem
