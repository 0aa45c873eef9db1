#pragma once

#include <cstddef>
#include <limits>

#include "granmem/core/trajectories.hpp"
#include "granmem/core/trajectory_store.hpp"

namespace granmem {

// How far a scan's centres err, read from the packing itself. Grains in contact sit one
// diameter apart, less overlaps of ~1e-3 d under the lid, so the scanned distances of
// touching neighbours spread about a diameter by the two centres' errors along the
// contact. Locate's standard errors come from its fit's residuals and miss what a grain's
// neighbourhood in the image does to it, the same from scan to scan (they are a third to a
// half of the errors against a render's truth, docs/CALIBRATION.md); the contacts see it,
// and it is what moves the packing's structure, or a packing placed where the scan has
// its grains.
//
// The scan's distances near contact are fitted as a simulated packing's under the same
// load (`reference`, whose distances are exact) convolved with a normal error of variance
// 2 (across^2 (1 - u_z^2) + along_z^2 u_z^2) along a contact of direction u, plus a mean
// `offset`: a maximum likelihood over the distances within [1 - below, 1 + above] d,
// binned by |u_z|, each bin's distances conditioned on lying in the range (grains the
// scan missed change how many there are, not their spread). Errors that touching
// neighbours share cancel in a distance, as they do in the structure: `across` and
// `along_z` are one centre's independent part.
struct ContactErrorOptions {
  double below = 0.03;  // of a diameter
  double above = 0.01;  // of a diameter
  double bin = 5e-4;    // the distances' bins, of a diameter
  int directions = 5;   // bins of |u_z|, each an equal solid angle
};

struct ContactLocatingError {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double across = kNaN;   // one centre's RMS error along x and along y, in the positions' unit
  double along_z = kNaN;  // along z
  double offset = kNaN;   // the scanned contacts' mean error in length (< 0: read too close)
  std::size_t pairs = 0;  // scanned distances fitted
};

// `scanned` and `reference` in one length unit, `diameter` the grains' (alike) in it;
// positions that are not finite are left out. NaN results with fewer than 100 scanned
// distances in the range.
ContactLocatingError locating_error_from_contacts(const Vectors3& scanned,
                                                  const Vectors3& reference, double diameter,
                                                  const ContactErrorOptions& options = {});

// Every frame of `scans` pooled against every frame of `reference` (a simulation of the
// same packing's protocol), `diameter` in m; the result in m.
ContactLocatingError locating_error_from_contacts(const TrajectoryReader& scans,
                                                  const TrajectoryReader& reference,
                                                  double diameter,
                                                  const ContactErrorOptions& options = {});

}  // namespace granmem
