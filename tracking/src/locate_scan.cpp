#include "granmem/tracking/locate_scan.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace granmem {

void ScanLocateOptions::validate() const {
  check_diameter(diameter, "--diameter");
  LocateOptions settings = locate;
  settings.diameter = 1;  // set from `diameter` as each stack is read
  settings.validate();
}

LocatedScan locate_scan(const std::filesystem::path& path, const ScanLocateOptions& options) {
  options.validate();
  Stack stack = read_stack(path, options.read);
  LocateOptions o = options.locate;
  o.diameter = diameter_in_voxels(options.diameter, stack, "--diameter");
  LocatedScan s;
  s.voxels = stack.nx * stack.ny * stack.nz;
  s.detections = locate(std::move(stack), o, &s.summary);  // the stack is not needed after
  Detections& d = s.detections;
  d.frame = options.frame;
  d.source = path.string();
  if (const auto& region = options.read.region) {
    const Eigen::Vector3d origin(double(region->x0), double(region->y0), double(region->z0));
    const Eigen::Vector3d shift =
        origin.cwiseProduct(d.voxel_size.value_or(Eigen::Vector3d::Ones()));
    d.position.rowwise() += shift.transpose();
  }
  return s;
}

std::string LocatedScan::Report() const {
  const LocateSummary& sum = summary;
  const Detections& d = detections;
  std::ostringstream out;
  out << d.source << ": " << sum.located << " grains (" << sum.on_edge
      << " cut by the stack's edge) from " << sum.candidates << " candidates, " << std::fixed
      << std::setprecision(1) << sum.seconds << " s (" << std::setprecision(2)
      << 1e3 * sum.seconds / double(std::max<std::size_t>(1, sum.located)) << " ms per grain, "
      << std::setprecision(1) << 1e-6 * double(voxels) / sum.seconds << " Mvoxel/s)"
      << std::defaultfloat << "; lengths in " << d.length_unit
      << (d.voxel_size ? "" : " (no voxel size given or found)") << "\n";
  return out.str();
}

}  // namespace granmem
