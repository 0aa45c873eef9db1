#include "granmem/core/trajectories.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/units.hpp"

namespace granmem {

Frame Frame::unknown(const RunHeader& header) {
  const auto n = static_cast<Eigen::Index>(header.grain_count());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Frame frame;
  frame.position = Vectors3::Constant(n, 3, nan);
  if (header.has_axis) frame.axis = Vectors3::Constant(n, 3, nan);
  if (header.has_orientation) frame.orientation = Quaternions::Constant(n, 4, nan);
  if (header.has_hole_contact) frame.hole_contact.assign(header.grain_count(), 0);
  if (header.has_position_error) frame.position_error = Vectors3::Constant(n, 3, nan);
  if (header.has_axis_error) frame.axis_error.assign(header.grain_count(), nan);
  return frame;
}

void check_frame(const RunHeader& header, const Frame& frame, const std::string& where) {
  const auto n = static_cast<Eigen::Index>(header.grain_count());
  auto expect = [&](bool ok, const std::string& what) {
    if (!ok) throw Error(where + ": " + what);
  };
  expect(frame.position.rows() == n, "position has " + std::to_string(frame.position.rows()) +
                                         " rows, expected " + std::to_string(n) + " grains");
  // An optional field: one row (or value) per grain where the run declares it, else none.
  auto expect_per_grain = [&](bool declared, Eigen::Index rows, const std::string& name,
                              const char* per) {
    expect(rows == (declared ? n : 0), declared ? name + " must have one " + per + " per grain"
                                                : name + " given but run has none");
  };
  const auto values = [](const auto& v) { return static_cast<Eigen::Index>(v.size()); };
  expect_per_grain(header.has_axis, frame.axis.rows(), "axis", "row");
  expect_per_grain(header.has_orientation, frame.orientation.rows(), "orientation", "row");
  expect_per_grain(header.has_hole_contact, values(frame.hole_contact), "hole_contact", "value");
  expect_per_grain(header.has_position_error, frame.position_error.rows(), "position_error", "row");
  expect_per_grain(header.has_axis_error, values(frame.axis_error), "axis_error", "value");
}

void check_header(const RunHeader& header, const std::string& where) {
  auto expect = [&](bool ok, const std::string& what) {
    if (!ok) throw Error(where + ": " + what);
  };
  expect(is_length_unit(header.length_unit),
         "length unit '" + header.length_unit + "' is not one of m, cm, mm, um, voxel");
  expect(header.radius.size() == header.grain_count(), "radius must have one value per grain");
  std::unordered_set<std::int64_t> seen;
  for (std::int64_t id : header.id)
    expect(seen.insert(id).second, "grain id " + std::to_string(id) + " appears twice");
  expect(header.sample == kSampleEndOfCycle || header.sample == kSampleFullCompression ||
             header.sample == kSampleInCycle,
         "sample '" + header.sample + "' is not one of end_of_cycle, full_compression, in_cycle");
  if (header.box) {
    expect(header.box->lower.allFinite() && header.box->edges.allFinite() &&
               (header.box->edges.array() > 0).all(),
           "box edges must be finite and positive");
  }
  if (header.voxel_size) {
    expect(header.voxel_size->allFinite() && (header.voxel_size->array() > 0).all(),
           "voxel size must be finite and positive");
  }
}

void register_to_container(Trajectories& run, const Box& container) {
  if (!container.lower.allFinite() || !(container.edges.array() > 0).all() ||
      !container.edges.allFinite()) {
    throw Error("container: its edges must be positive and finite");
  }
  for (Frame& frame : run.frames)
    frame.position.rowwise() -= container.lower.transpose();
  run.header.box = Box{Eigen::Vector3d::Zero(), container.edges};
}

namespace {

// The grains' surfaces facing each wall: per axis the low ones (x - r) and the high ones,
// negated (-(x + r)), so that the smallest of each are the nearest a wall.
struct PackingSurfaces {
  std::array<std::vector<double>, 3> low, high;
  Eigen::Vector3d lowest = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d highest = -lowest;  // the extreme surfaces
  double radius = 0;                  // the median grain's
};

PackingSurfaces first_frame_surfaces(const Trajectories& run) {
  PackingSurfaces s;
  std::vector<double> radii;
  if (run.frames.empty()) return s;
  const Frame& f = run.frames.front();
  for (Eigen::Index k = 0; k < f.position.rows(); ++k) {
    const double r = std::size_t(k) < run.header.radius.size() ? run.header.radius[std::size_t(k)]
                                                               : std::nan("");
    if (!f.position.row(k).allFinite() || !std::isfinite(r)) continue;
    radii.push_back(r);
    for (int a = 0; a < 3; ++a) {
      s.low[a].push_back(f.position(k, a) - r);
      s.high[a].push_back(-(f.position(k, a) + r));
    }
    s.lowest = s.lowest.cwiseMin(f.position.row(k).transpose() - Eigen::Vector3d::Constant(r));
    s.highest = s.highest.cwiseMax(f.position.row(k).transpose() + Eigen::Vector3d::Constant(r));
  }
  if (!radii.empty()) s.radius = median(radii);
  return s;
}

// Where one side of the packing ends (its face: the extent across the other two axes), as
// the packing's height is measured.
double end_layer(const PackingSurfaces& s, int axis, const std::vector<double>& surfaces) {
  const Eigen::Vector3d span = s.highest - s.lowest;
  return end_layer_mean(surfaces, span[(axis + 1) % 3] * span[(axis + 2) % 3], s.radius);
}

// The floor, where the bottom layer rests: the median of its grains' lowest surfaces (z - r).
// The layer is every grain whose bottom lies within a radius of the quarter layer nearest the
// floor (a stray detection below it does not move that), so the noise, alike up and down, and
// the radii's own errors cancel; the single lowest surface is a noise extreme (73 um below
// the floor on 12-pixel scans). The grains nestled less than a radius above the floor (~12 of
// a layer's ~85) lift the median by a few um; the scans' bottom grains, located ~5-10 um low,
// about offset that (measured: the floor within 3.4 um of the truth's, docs/CALIBRATION.md).
double floor_of_bottom_layer(const PackingSurfaces& s) {
  std::vector<double> bottoms = s.low[2];
  if (bottoms.empty()) return std::nan("");
  const Eigen::Vector3d span = s.highest - s.lowest;
  const double radius = std::max(s.radius, 0.0);
  const double layer_grains = radius > 0 ? span.x() * span.y() / (16 * radius * radius) : 0;
  const double rank = std::round(layer_grains);
  const std::size_t quarter =
      rank < double(bottoms.size() - 1) ? std::size_t(rank) : bottoms.size() - 1;
  std::nth_element(bottoms.begin(), bottoms.begin() + std::ptrdiff_t(quarter), bottoms.end());
  const double reference = bottoms[quarter];
  std::vector<double> layer;
  for (double z : s.low[2])
    if (z <= reference + radius) layer.push_back(z);
  return median(layer);
}

}  // namespace

Box container_from_extent(const Trajectories& run, const Eigen::Vector3d& edges) {
  const PackingSurfaces s = first_frame_surfaces(run);
  if (s.low[0].empty()) {
    throw Error("container: the first frame has no grain with a position and a radius");
  }
  // Across the walls (x, y) the packing is centred in the container: a scan's located radii
  // (small on coarse scans) and its noise move both sides alike. Along z only the floor is
  // a wall (the lid is free): there the bottom layer rests.
  Eigen::Vector3d lower;
  for (int a = 0; a < 2; ++a)
    lower[a] = (end_layer(s, a, s.low[a]) - end_layer(s, a, s.high[a]) - edges[a]) / 2;
  lower.z() = floor_of_bottom_layer(s);
  return Box{lower, edges};
}

}  // namespace granmem
