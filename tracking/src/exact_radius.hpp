#pragma once

#include <cstddef>
#include <vector>

namespace granmem {

// The radius the exactly blurred image (hole_axis.hpp) gives a grain, predicted from its
// model fit's radius, which runs small by the blur's curvature shift and scatters by its
// noise (at 12-voxel grains ~0.35 voxel small, 13 um against the exact refits' 3 um). The
// least-squares line through a sample's pairs (model fit, exact refit), its slope held in
// [0, 1]: near 0 where the grains are alike and the model radii scatter by noise alone
// (each grain then the sample's mean exact radius), near 1 where their sizes differ more
// than that noise. The line, not a median shortfall: a 24-grain sample's median of the
// differences carries the model radii's noise (2-3 um), and each neighbour so drawn its own
// (13 um): locate models every grain's neighbours at this radius, and a neighbour drawn
// 1 um large pushes the grain 0.1 um away from it.
struct ExactRadius {
  double intercept = 0, slope = 1;  // default: the model fit's radius as it is
  double operator()(double model_radius) const { return intercept + slope * model_radius; }
};

// The line through the finite pairs; the default (slope 1, no shift) with none, the mean
// difference (slope 1) with one or with model radii all alike.
ExactRadius fit_exact_radius(const std::vector<double>& model, const std::vector<double>& exact);

}  // namespace granmem
