#include "granmem/calibration/scan_errors.hpp"

#include <cmath>

namespace granmem {

ScanErrors scan_errors(const TrajectoryReader& run) {
  const RunHeader& h = run.header();
  ScanErrors e;
  if (!h.has_position_error && !h.has_axis_error) return e;
  Eigen::Vector3d position_squares = Eigen::Vector3d::Zero();
  double axis_squares = 0;
  for (std::size_t t = 0; t < run.frame_count(); ++t) {
    const Frame f = run.read_frame(t);
    for (Eigen::Index i = 0; i < f.position_error.rows(); ++i) {
      const Eigen::Vector3d sigma = f.position_error.row(i).transpose();
      if (!sigma.allFinite()) continue;
      position_squares += sigma.cwiseAbs2();
      ++e.positions;
    }
    for (double sigma : f.axis_error) {
      if (!std::isfinite(sigma)) continue;
      axis_squares += sigma * sigma;
      ++e.axes;
    }
  }
  if (e.positions) e.position = (position_squares / double(e.positions)).cwiseSqrt();
  if (e.axes) e.axis = std::sqrt(axis_squares / double(e.axes));
  return e;
}

}  // namespace granmem
