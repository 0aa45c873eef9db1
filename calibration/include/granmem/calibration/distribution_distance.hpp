#pragma once

#include <vector>

namespace granmem {

// Distances between the distributions of two samples (NaN values are dropped), as the
// goodness of a fit and the measure of agreement between two runs.

// Kolmogorov-Smirnov: the largest difference between the two empirical CDFs.
double ks_distance(std::vector<double> a, std::vector<double> b);

// Wasserstein-1 (earth mover's): the area between the two empirical CDFs, in the samples'
// unit.
double wasserstein1_distance(std::vector<double> a, std::vector<double> b);

// The asymptotic p-value of the two-sample KS statistic `d` for samples of sizes n and m
// (Kolmogorov's distribution at sqrt(n m / (n + m)) d, with Stephens' correction). It
// assumes independent values: pooled cycles of one grain are not, so read it as a guide.
double ks_p_value(double d, std::size_t n, std::size_t m);

}  // namespace granmem
