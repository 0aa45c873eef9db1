#pragma once

#include <atomic>
#include <functional>

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "granmem/core/trajectories.hpp"
#include "granmem/tracking/detections.hpp"

// Linking: the detections of successive scans joined into grain trajectories.
namespace granmem {

struct LinkOptions {
  // The largest distance between a grain's detection and where it is expected: its last
  // position moved by the predicted motion (the global drift and the local displacement
  // field, when these are on; with both off, simply its last position). In the
  // detections' length unit; 0: 0.7 median grain diameter. It must exceed the random,
  // non-collective part of the motion plus the detection error; a wider reach costs little,
  // as the one-to-one assignment keeps a neighbour's detection for that neighbour.
  double max_displacement = 0;
  // Scans a grain may go unseen and still be linked again, looked for at its last position
  // moved by the motion predicted for the scans in between. 0: a grain missing once starts
  // a new track.
  int memory = 2;
  // Estimate the global drift between two scans (the mode of all displacements, then the
  // mean of the links it gives) and search around each grain's drifted position.
  bool estimate_drift = true;
  // With the drift: fit a uniform deformation too (drift + displacement gradient: a
  // compression, a simple shear), when it explains the scans better.
  bool deformation = true;
  // Then predict each grain's motion from its neighbourhood: first the common motion of
  // its 2 x `neighbours` nearest grains found without links (the densest spot of their
  // displacements to all detections near them), then, up to `refinements` times, the
  // median displacement of its `neighbours` nearest confidently linked grains (itself left
  // out in both), each kept while it explains the scans better.
  bool local_field = true;
  int neighbours = 12;
  int refinements = 3;
  // What linking is doing (a line per scan), and a flag (Python's Ctrl-C) that stops it
  // between two scans with Error "link: stopped ...".
  std::function<void(const std::string&)> log;
  const std::atomic<bool>* stop = nullptr;
};

// What linking scan k (from the scans before it) gave.
struct ScanLinks {
  std::int64_t frame = 0;
  std::size_t detections = 0;  // grains found in this scan
  std::size_t previous = 0;    // tracks seen in the scan before (0 for the first scan)
  std::size_t linked = 0;      // detections continuing a track
  std::size_t relinked = 0;    // of those, tracks back from memory
  std::size_t started = 0;     // detections starting a new track
  std::size_t unlinked = 0;    // tracks seen in the scan before and not found in this one
  std::size_t kept = 0;        // tracks not seen in this scan and kept in memory
  std::size_t ended = 0;       // tracks given up: unseen for more than `memory` scans
  // Links chosen by the assignment among several candidates (the track had more than one
  // detection within reach, or the detection more than one track).
  std::size_t ambiguous = 0;
  // The global motion predicted, u(x) = drift + gradient (x - centre of the grains): zero
  // when the drift is off or explains nothing.
  Eigen::Vector3d drift = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gradient = Eigen::Matrix3d::Zero();
  Eigen::Vector3d mean_displacement = Eigen::Vector3d::Zero();  // of the links from the scan before
  double rms_residual = 0;   // rms distance of the links from where they were expected
  bool local_field = false;  // the local displacement field gave the links
  // What could not be linked: tracks of the scan before not found here, and detections of
  // this scan that start a new track (indices into the scan), both ascending.
  std::vector<std::int64_t> unlinked_tracks;
  std::vector<std::size_t> new_detections;
  std::int64_t first_new_track = 0;  // new_detections[k] starts track first_new_track + k

  // Of the tracks seen in the scan before, the fraction found in this one (1 when none).
  double linked_fraction() const {
    return previous ? double(previous - unlinked) / double(previous) : 1.0;
  }
};

struct LinkSummary {
  double max_displacement = 0;  // as used, in length_unit
  std::string length_unit;
  std::size_t tracks = 0;
  std::vector<ScanLinks> scans;  // one per scan, in order
};

// Links the scans, in the order given (their frames must increase), into one run: a grain
// per track (id = track number, in order of first appearance), a frame per scan (step and
// time = the scan's frame, time unit "cycle"), NaN where a grain is not seen; cavity axes
// and hole contacts carried when the detections have them; radius = the mean over the
// scans. Length unit and voxel size come from the detections, which must all agree.
// Throws Error on disagreeing scans, non-finite positions or bad options.
Trajectories link_scans(const std::vector<Detections>& scans, const LinkOptions& options,
                        LinkSummary* summary = nullptr);

// 0.7 times the median diameter of the detections (their median nearest-neighbour spacing
// where no radius is known): the default max_displacement.
double default_max_displacement(const std::vector<Detections>& scans);

}  // namespace granmem
