#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "granmem/core/hdf5.hpp"
#include "granmem/core/trajectories.hpp"

// The trajectory store: one run, experimental or simulated, in one HDF5 file laid out as
// H5MD (see docs/FORMAT.md):
//   /h5md                                   version; author, creator groups
//   /particles/grains/position/{value[T,N,3], step[T], time[T]}
//   /particles/grains/axis/...              [T,N,3] cavity axis, unsigned unit vector
//   /particles/grains/orientation/...       [T,N,4] quaternion (w,x,y,z)
//   /particles/grains/hole_contact/...      [T,N]   uint8 flag
//   /particles/grains/position_error/...    [T,N,3] a scan's standard errors (length unit)
//   /particles/grains/axis_error/...        [T,N]   a scan's axis standard error (rad)
//   /particles/grains/{id,radius}[N], box/edges[3], box/offset[3]
//   /observables/<name>/{value,step,time}
//   /parameters/<producer>@<key>, /parameters/voxel_size[3]
// Every dataset has a `unit` attribute.
namespace granmem {

// Writes a run frame by frame into a temporary file; commit() renames it into place and
// writes the XDMF sidecar (<name>.xmf) that lets ParaView open it. Dropped without
// commit(), it leaves nothing behind and any existing file of that name untouched.
// For long runs, publish() puts a complete copy of what is written so far in place and
// goes on, and resume() continues a run published or committed before.
// The author written into stores whose header names none (/h5md/author): this name
// (`granmem --author`), else the login ($USER), else "unknown". Set it before writing.
void set_default_author(const std::string& name);

class TrajectoryWriter {
 public:
  TrajectoryWriter(const std::filesystem::path& path, RunHeader header);
  // Continues the run in the file at `path` after its first `keep_frames` frames (later
  // frames, and observables of later steps, are dropped). The file itself is untouched
  // until the next publish() or commit().
  static TrajectoryWriter resume(const std::filesystem::path& path, std::size_t keep_frames);
  ~TrajectoryWriter();
  TrajectoryWriter(TrajectoryWriter&&) noexcept;
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;

  void append(const Frame& frame);
  void set_observable(const std::string& name, Observable observable);
  // Replaces what the file says produced it (a resumed run asked for more cycles).
  void set_parameters(std::map<std::string, std::string> parameters);
  const std::map<std::string, Observable>& observables() const;
  const RunHeader& header() const;
  std::size_t frame_count() const;
  void publish();
  void commit();

 private:
  TrajectoryWriter() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Reads a run: the header and observables at once, frames one at a time, so that runs
// larger than memory can be streamed.
class TrajectoryReader {
 public:
  explicit TrajectoryReader(const std::filesystem::path& path);
  ~TrajectoryReader();
  TrajectoryReader(TrajectoryReader&&) noexcept;

  const RunHeader& header() const;
  std::size_t frame_count() const;
  const std::vector<std::int64_t>& steps() const;
  const std::vector<double>& times() const;
  const std::map<std::string, Observable>& observables() const;
  Frame read_frame(std::size_t t) const;
  const std::string& file_name() const;
  const h5::File& file() const;
  // Path of the particles group, e.g. "/particles/grains".
  const std::string& particles_group() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

void write_trajectories(const std::filesystem::path& path, const Trajectories& run);
Trajectories read_trajectories(const std::filesystem::path& path);

}  // namespace granmem
