#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace granmem {

// N x 3 per-grain vectors; row-major so that a frame is laid out as HDF5's [N,3].
using Vectors3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
// N x 4 unit quaternions, scalar first: (w, x, y, z), as LAMMPS and HOOMD write them.
using Quaternions = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;

// The container: an axis-aligned box from `lower` to `lower + edges`, in the run's length unit.
struct Box {
  Eigen::Vector3d lower = Eigen::Vector3d::Zero();
  Eigen::Vector3d edges = Eigen::Vector3d::Zero();
};

// What a frame is, in the protocol: a scan or snapshot at the end of a cycle, at full
// compression, or inside a cycle.
inline constexpr const char* kSampleEndOfCycle = "end_of_cycle";
inline constexpr const char* kSampleFullCompression = "full_compression";
inline constexpr const char* kSampleInCycle = "in_cycle";

// What stays the same over the frames of one run, experimental or simulated.
struct RunHeader {
  std::string length_unit = "m";  // m, cm, mm, um or voxel
  std::string time_unit = "s";    // "s", or "cycle" when only the cycle index is known
  std::string sample = kSampleEndOfCycle;
  std::vector<std::int64_t> id;  // grain labels (the trackpy `particle`), one per grain
  std::vector<double> radius;    // one per grain; NaN where unknown
  std::optional<Box> box;
  // Voxel size (x, y, z) in `length_unit`, when positions came from images.
  std::optional<Eigen::Vector3d> voxel_size;
  bool has_axis = false;          // cavity axes (unit, unsigned; NaN where unseen)
  bool has_orientation = false;   // full orientations (simulations)
  bool has_hole_contact = false;  // per-frame flag: grain touches a neighbour through its hole
  // Per-frame standard errors of a scan's measurement (locate's fit covariance).
  bool has_position_error = false;  // per axis, in length_unit
  bool has_axis_error = false;      // of the cavity axis' direction, radians
  std::string creator_name = "granmem";
  std::string creator_version;
  std::string author;
  // What produced the file, as "<producer>/<key>" -> value, e.g. "import/length_unit".
  std::map<std::string, std::string> parameters;

  std::size_t grain_count() const { return id.size(); }
};

// One sample of every grain of the run. A grain not seen has a NaN position.
struct Frame {
  std::int64_t step = 0;                   // cycle (or scan) index
  double time = 0;                         // in RunHeader::time_unit
  Vectors3 position;                       // N x 3
  Vectors3 axis;                           // N x 3 when the run has axes, else empty
  Quaternions orientation;                 // N x 4 when the run has orientations, else empty
  std::vector<std::uint8_t> hole_contact;  // N when the run has the flag, else empty
  Vectors3 position_error;                 // N x 3 when the run has them; NaN where unknown
  std::vector<double> axis_error;          // N when the run has them; NaN where unknown

  // A frame of `n` grains with every field the header declares, all unknown.
  static Frame unknown(const RunHeader& header);
};

// A scalar time series of the run (wall force, lid height, packing fraction...).
struct Observable {
  std::string unit;
  std::vector<double> value;
  std::vector<std::int64_t> step;
  std::vector<double> time;
};

// A whole run in memory. Large runs are streamed frame by frame instead
// (TrajectoryReader / TrajectoryWriter).
struct Trajectories {
  RunHeader header;
  std::vector<Frame> frames;
  std::map<std::string, Observable> observables;
};

// The run in its container's frame: every frame's positions less the container's lower
// corner (given in the positions' frame, e.g. a scan's), and the container, from the
// origin, as the run's box: tracked scans then share the DEM's coordinates, so their
// fields and wall distances compare without an offset. Throws Error for a container
// without positive edges.
void register_to_container(Trajectories& run, const Box& container);

// The container of edges `edges` found from the packing's extent in the first frame, since
// grains pressed into a container touch its floor and walls. Each end of the packing is
// its end layer: the mean over a quarter of a layer's grains (the packing's face over
// 4 d^2) of the surfaces nearest that wall (x - r, ..., or x + r), not the one
// extreme grain that noise pushes outward. Across x and y the packing is centred between
// the walls, so that radii located too small or too large, and noise, alike on both sides,
// cancel; along z the floor is where the bottom layer rests, the median of its grains' lowest
// surfaces (z - r; the lid is free, so the top is no wall), not the lowest one, which noise
// pushes below the floor. Error for a run without positions.
Box container_from_extent(const Trajectories& run, const Eigen::Vector3d& edges);

// Checks a header for consistency (sizes, unique ids, known units); throws Error naming `where`.
void check_header(const RunHeader& header, const std::string& where);

// Checks that a frame matches its header (sizes, declared fields); throws Error naming `where`.
void check_frame(const RunHeader& header, const Frame& frame, const std::string& where);

}  // namespace granmem
