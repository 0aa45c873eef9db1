#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "granmem/core/trajectories.hpp"

namespace granmem {

// What to do with grains that touch a neighbour through their hole: the hole locks on the
// neighbour, so the paper drops them from the experimental rotation statistics (their
// translations are unaffected).
enum class HoleContactPolicy { keep, exclude_rotations, exclude };
// "keep", "exclude-rotations" or "exclude" (Error naming `option` otherwise).
HoleContactPolicy hole_contact_policy(const std::string& text, const std::string& option);

struct MotionOptions {
  // Remove the rigid drift of the packing: the mean displacement of the analysed grains.
  bool subtract_drift = false;
  // Leave out grains whose centre lies within this distance of a face of the container
  // (in the run's length unit), in either frame. 0 keeps every grain.
  double wall_distance = 0;
  // The container for `wall_distance`; default the run's box.
  std::optional<Box> box;
  HoleContactPolicy hole_contacts = HoleContactPolicy::keep;

  // Throws Error for a wall distance that is not a length >= 0.
  void validate() const;
};

// How the grains moved between two frames: one entry per grain seen in both and kept
// by the options, in grain order.
struct FrameMotion {
  std::vector<std::size_t> grain;  // grain index (into RunHeader::id)
  Vectors3 displacement;           // after drift removal, if asked
  std::vector<double> dr;          // |displacement|
  std::vector<double> theta_axis;  // single-axis rotation, rad; NaN where not measured
  std::vector<double> rot_disp;    // theta_axis * radius, length
  std::vector<double> theta_full;  // full rotation, rad; empty without orientations
  // With orientations: the single-axis rotation of the body's other principal axes (x and
  // y; the cavity is z), rad, for the paper's comparison of one-axis and full rotations.
  std::vector<double> theta_body_x, theta_body_y;
  Eigen::Vector3d drift = Eigen::Vector3d::Zero();  // mean displacement before removal
  bool has_rotation = false;                        // the run has axes or orientations
};

// Grain i's cavity axis in the frame: the run's axis, or the body z axis of its orientation.
Eigen::Vector3d axis_of(const RunHeader& header, const Frame& frame, std::size_t i);

// Displacements and rotations between `before` and `after`. The single-axis rotation uses
// the cavity axes, or the body z axes of the orientations when the run has no axes.
FrameMotion grain_motion(const RunHeader& header, const Frame& before, const Frame& after,
                         const MotionOptions& options);

}  // namespace granmem
