#include "granmem/tracking/candidates.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "granmem/tracking/illumination.hpp"
#include "granmem/tracking/render.hpp"
#include "locate_score.hpp"

// find_candidates on rendered dense packings (the default artefacts): one candidate per
// grain, about a voxel from its centre, and, with the found grains subtracted, only those
// that were not.
namespace granmem {
namespace {

struct Scan {
  Stack stack;
  std::vector<Eigen::Vector3d> centres;  // voxels
  std::vector<bool> interior;            // not cut by the stack's border
  Eigen::Vector3d voxel_size;
};

Scan normalised_scan(std::uint32_t seed) {
  const testing::PackingScan p = testing::packing_scan(220, 0.58, 12, 1, seed);
  Table truth;
  Scan s{render_scan(p.grains, p.options, &truth), {}, {}, *p.options.voxel_size};
  IlluminationOptions light;
  light.diameter = 12;
  normalize_illumination(s.stack, light);
  for (std::size_t i = 0; i < truth.rows(); ++i) {
    s.centres.emplace_back(truth["x"].values[i], truth["y"].values[i], truth["z"].values[i]);
    s.interior.push_back(truth["edge"].values[i] == 0);
  }
  return s;
}

// The candidate nearest `c` and its distance (voxels).
double nearest(const std::vector<Eigen::Vector3d>& candidates, const Eigen::Vector3d& c) {
  double best = 1e30;
  for (const Eigen::Vector3d& x : candidates)
    best = std::min(best, (x - c).norm());
  return best;
}

TEST(Candidates, OneNearEveryGrainsCentreAndNoneTooClose) {
  const Scan s = normalised_scan(41);
  CandidateOptions o;
  o.diameter = Eigen::Vector3d::Constant(12);
  const std::vector<Eigen::Vector3d> found = find_candidates(s.stack, o);
  std::size_t interior = 0, seen = 0;
  for (std::size_t i = 0; i < s.centres.size(); ++i) {
    if (!s.interior[i]) continue;
    ++interior;
    seen += nearest(found, s.centres[i]) < 1.5;  // "to about a voxel"
  }
  EXPECT_GT(interior, 50u);
  EXPECT_GE(double(seen), 0.97 * double(interior)) << seen << " of " << interior;
  for (std::size_t a = 0; a < found.size(); ++a)
    for (std::size_t b = a + 1; b < found.size(); ++b)
      EXPECT_GE((found[a] - found[b]).norm(), o.min_separation * 12) << a << ", " << b;
  // Each candidate away from the border is a grain: none far from every grain's centre
  // (at the border, a grain cut by it peaks where its cut face is).
  const Eigen::Vector3d last(double(s.stack.nx - 1), double(s.stack.ny - 1),
                             double(s.stack.nz - 1));
  for (const Eigen::Vector3d& c : found) {
    if ((c.array() < 6).any() || ((last - c).array() < 6).any()) continue;
    EXPECT_LT(nearest(s.centres, c), 1.5) << c.transpose();
  }
}

TEST(Candidates, WithTheFoundGrainsSubtractedTheHiddenOnesRemain) {
  const Scan s = normalised_scan(42);
  CandidateOptions o;
  o.diameter = Eigen::Vector3d::Constant(12);
  // Every grain "found" but every eighth interior one, drawn as the fits would have it.
  std::vector<HoledSphere> found;
  std::vector<Eigen::Vector3d> hidden;
  for (std::size_t i = 0, k = 0; i < s.centres.size(); ++i) {
    if (s.interior[i] && k++ % 8 == 0) {
      hidden.push_back(s.centres[i]);
      continue;
    }
    HoledSphere g;
    g.centre = s.centres[i].cwiseProduct(s.voxel_size);
    g.radius = 6 * s.voxel_size.x();
    g.blur = 0.7 * s.voxel_size.x();
    g.hole = 0;  // the candidates' grain fraction is read without the hole
    found.push_back(g);
  }
  const std::vector<Eigen::Vector3d> left = find_candidates(s.stack, o, &found, s.voxel_size);
  std::size_t recovered = 0;
  for (const Eigen::Vector3d& c : hidden)
    recovered += nearest(left, c) < 2.0;
  EXPECT_GE(double(recovered), 0.9 * double(hidden.size())) << recovered << " of " << hidden.size();
  // Nothing where a found grain explains the scan.
  std::size_t elsewhere = 0;
  for (const Eigen::Vector3d& c : left)
    elsewhere += nearest(hidden, c) >= 2.0;
  EXPECT_LE(elsewhere, hidden.size() / 4) << elsewhere << " candidates where grains were found";
}

}  // namespace
}  // namespace granmem
