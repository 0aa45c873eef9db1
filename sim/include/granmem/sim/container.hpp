#pragma once

#include <Eigen/Core>
#include <array>

namespace granmem {

// The flat walls a grain can touch, in the order their forces are summed.
enum class Wall : int { floor = 0, x_low, x_high, y_low, y_high, lid };
inline constexpr int kWallCount = 6;

// A rigid horizontal plate resting on the grains, free to move along z only.
struct Lid {
  bool present = false;
  double mass = 1.0;  // kg (the paper's 1 kg weight)
  double z = 0;       // height of its lower face
  double v = 0;       // velocity along z
  double force = 0;   // net force along z at the last step (grains + gravity)
};

// The square box: floor at z = 0, side walls at x = 0, x = size.x(), y = size.y(), the
// driven wall normal to y at y = y_wall (at rest 0, compressing towards +y), and the lid.
struct Container {
  Eigen::Vector2d size{0.15, 0.15};  // inner side lengths along x and y, m
  double y_wall = 0;                 // driven wall position
  double y_wall_velocity = 0;
  Lid lid;

  // Plane of wall w: inward unit normal, the distance of point x from it, its velocity.
  struct Plane {
    Eigen::Vector3d normal;
    double offset;  // distance = normal . x - offset
    Eigen::Vector3d velocity;
  };
  Plane plane(Wall w) const {
    switch (w) {
      case Wall::floor:
        return {Eigen::Vector3d::UnitZ(), 0.0, Eigen::Vector3d::Zero()};
      case Wall::x_low:
        return {Eigen::Vector3d::UnitX(), 0.0, Eigen::Vector3d::Zero()};
      case Wall::x_high:
        return {-Eigen::Vector3d::UnitX(), -size.x(), Eigen::Vector3d::Zero()};
      case Wall::y_low:
        return {Eigen::Vector3d::UnitY(), y_wall, Eigen::Vector3d(0, y_wall_velocity, 0)};
      case Wall::y_high:
        return {-Eigen::Vector3d::UnitY(), -size.y(), Eigen::Vector3d::Zero()};
      case Wall::lid:
        return {-Eigen::Vector3d::UnitZ(), -lid.z, Eigen::Vector3d(0, 0, lid.v)};
    }
    return {};
  }
};

}  // namespace granmem
