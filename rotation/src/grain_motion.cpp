#include "granmem/rotation/grain_motion.hpp"

#include <cmath>
#include <limits>

#include "granmem/core/error.hpp"
#include "granmem/rotation/full_rotation.hpp"
#include "granmem/rotation/single_axis_rotation.hpp"

namespace granmem {
namespace {

bool near_wall(const Eigen::Vector3d& x, const Box& box, double distance) {
  const Eigen::Vector3d upper = box.lower + box.edges;
  return ((x - box.lower).array() < distance).any() || ((upper - x).array() < distance).any();
}

Eigen::Quaterniond quaternion(const Quaternions& q, std::size_t i) {
  const auto row = static_cast<Eigen::Index>(i);
  return Eigen::Quaterniond(q(row, 0), q(row, 1), q(row, 2), q(row, 3));  // (w, x, y, z)
}

}  // namespace

Eigen::Vector3d axis_of(const RunHeader& header, const Frame& frame, std::size_t i) {
  if (header.has_axis) return frame.axis.row(static_cast<Eigen::Index>(i)).transpose();
  return cavity_axis(quaternion(frame.orientation, i));
}

void MotionOptions::validate() const {
  if (!(wall_distance >= 0) || !std::isfinite(wall_distance)) {
    throw Error("--wall-distance: expected a length >= 0");
  }
}

FrameMotion grain_motion(const RunHeader& header, const Frame& before, const Frame& after,
                         const MotionOptions& options) {
  const std::optional<Box>& box = options.box ? options.box : header.box;
  if (options.wall_distance > 0 && !box) {
    throw Error("excluding grains near the walls needs the container, and the run has no box");
  }
  const bool flags = header.has_hole_contact && options.hole_contacts != HoleContactPolicy::keep;
  auto flagged = [&](std::size_t i) {
    return flags && (before.hole_contact[i] || after.hole_contact[i]);
  };

  FrameMotion m;
  m.has_rotation = header.has_axis || header.has_orientation;
  std::vector<Eigen::Vector3d> d;
  for (std::size_t i = 0; i < header.grain_count(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    const Eigen::Vector3d x0 = before.position.row(row), x1 = after.position.row(row);
    if (!x0.allFinite() || !x1.allFinite()) continue;
    if (options.wall_distance > 0 && (near_wall(x0, *box, options.wall_distance) ||
                                      near_wall(x1, *box, options.wall_distance))) {
      continue;
    }
    if (options.hole_contacts == HoleContactPolicy::exclude && flagged(i)) continue;
    m.grain.push_back(i);
    d.push_back(x1 - x0);
  }

  const std::size_t n = m.grain.size();
  for (const Eigen::Vector3d& v : d)
    m.drift += v;
  if (n) m.drift /= double(n);
  m.displacement.resize(static_cast<Eigen::Index>(n), 3);
  m.dr.resize(n);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (m.has_rotation) {
    m.theta_axis.assign(n, nan);
    m.rot_disp.assign(n, nan);
  }
  if (header.has_orientation) {
    m.theta_full.assign(n, nan);
    m.theta_body_x.assign(n, nan);
    m.theta_body_y.assign(n, nan);
  }

  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = m.grain[k];
    const Eigen::Vector3d v = options.subtract_drift ? Eigen::Vector3d(d[k] - m.drift) : d[k];
    m.displacement.row(static_cast<Eigen::Index>(k)) = v;
    m.dr[k] = v.norm();
    if (!m.has_rotation || flagged(i)) continue;
    m.theta_axis[k] = single_axis_angle(axis_of(header, before, i), axis_of(header, after, i));
    m.rot_disp[k] = m.theta_axis[k] * header.radius[i];
    if (header.has_orientation) {
      const Eigen::Quaterniond q0 = quaternion(before.orientation, i);
      const Eigen::Quaterniond q1 = quaternion(after.orientation, i);
      m.theta_full[k] = full_rotation_angle(q0, q1);
      m.theta_body_x[k] =
          single_axis_angle(q0 * Eigen::Vector3d::UnitX(), q1 * Eigen::Vector3d::UnitX());
      m.theta_body_y[k] =
          single_axis_angle(q0 * Eigen::Vector3d::UnitY(), q1 * Eigen::Vector3d::UnitY());
    }
  }
  return m;
}

HoleContactPolicy hole_contact_policy(const std::string& text, const std::string& option) {
  if (text == "keep") return HoleContactPolicy::keep;
  if (text == "exclude-rotations") return HoleContactPolicy::exclude_rotations;
  if (text == "exclude") return HoleContactPolicy::exclude;
  throw Error(option + " '" + text + "': expected keep, exclude-rotations or exclude");
}

}  // namespace granmem
