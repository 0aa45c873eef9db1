#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>

#include "granmem/core/trajectories.hpp"
#include "granmem/core/trajectory_store.hpp"

namespace granmem {

// How far a scan's centres err, read from the packing itself. Grains in contact sit one
// diameter apart, less overlaps of ~1e-3 d under the lid, so the scanned distances of
// touching neighbours spread about a diameter by the two centres' errors along the
// contact. Locate's standard errors come from its fit's residuals and miss what a grain's
// neighbourhood in the image does to it, the same from scan to scan (a sixth to a half of
// the errors against a render's truth, docs/CALIBRATION.md); the contacts see it,
// and it is what moves the packing's structure, or a packing placed where the scan has
// its grains.
//
// The scan's distances near contact are fitted as a simulated packing's under the same
// load (`reference`, whose distances are exact) convolved with a normal error of variance
// 2 (across^2 (1 - u_z^2) + along_z^2 u_z^2) along a contact of direction u, plus a mean
// `offset`: a maximum likelihood over the distances near contact, binned by |u_z|, each
// bin's distances conditioned on lying in the range fitted (grains the scan missed change
// how many there are, not their spread). The range is found from the data: a first fit
// over 0.75-1.05 d, then six and three times a contact's spread below and above, within
// 0.75-1.05 d (a coarse scan's is then the first range again, in finer bins). Errors
// that touching neighbours share cancel in a distance, as they do in the structure:
// `across` and `along_z` are one centre's independent part, of the errors' normal core: a
// grain located beyond the range (a coarse scan's stray) does not count in it. Grains of
// unequal size spread their contacts too: on real grains it is the locating error and the
// size spread together (radii spread by 1 % add ~0.007 d to a contact's spread).
struct ContactErrorOptions {
  double below = 0.03;  // the range fitted at least from (1 - below) d
  double above = 0.01;  // to (1 + above) d
  int bins = 80;        // of the distances in the range
  int directions = 5;   // bins of |u_z|, each an equal solid angle
  // Error for a diameter not above 0, a range outside 0.75-1.05 d, fewer than 10 bins.
  void validate(double diameter) const;
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
// distances in the range, or one centre's error over half the range below contact.
ContactLocatingError locating_error_from_contacts(const Vectors3& scanned,
                                                  const Vectors3& reference, double diameter,
                                                  const ContactErrorOptions& options = {});

// Every frame of `scans` pooled against every frame of `reference` (a simulation of the
// same packing's protocol), `diameter` in m; the result in m.
ContactLocatingError locating_error_from_contacts(const TrajectoryReader& scans,
                                                  const TrajectoryReader& reference,
                                                  double diameter,
                                                  const ContactErrorOptions& options = {});

// How far a scan's errors move its end-of-cycle displacements, read from its persistent
// contacts: a pair of grains touching (centres within 1.01 d) at both ends of a cycle keeps
// its true distance to ~1 um, so the change the scans read is the change of the two
// centres' errors along the contact. Its robust spread (1.4826 x the median absolute
// deviation, the errors' normal core) is 2 s for independent errors of s per frame and
// grain; consecutive scans' errors being partly shared, it is smaller, and half of it is the
// per-frame error that moves the displacements as the scans' own errors do (0.95-1.15 of
// their move on five scanned packings, docs/CALIBRATION.md). Read on horizontal contacts
// (|u_z| < 0.3) for the error across the slices and on vertical ones (|u_z| > 0.8) along z,
// the spread of `reference` (a simulation of the packing, its true changes) removed in
// quadrature; over the cycles of `window` (inclusive), each with its frame and the one
// before. `diameter` in m; the result in m, NaN where fewer than 100 contacts of a
// direction persist.
struct DisplacementError {
  double across = ContactLocatingError::kNaN;   // one centre's per-frame error along x, y
  double along_z = ContactLocatingError::kNaN;  // along z
  std::size_t contacts = 0;                     // persistent contacts read in the scans
};
DisplacementError displacement_error_from_contacts(const TrajectoryReader& scans,
                                                   const TrajectoryReader& reference,
                                                   double diameter,
                                                   std::pair<std::int64_t, std::int64_t> window);

}  // namespace granmem
