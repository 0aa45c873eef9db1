#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <string>

#include "granmem/core/error.hpp"
#include "granmem/core/table.hpp"

// Small checks the test programs share.
namespace granmem::testing {

// The message of the granmem::Error that `f` throws (a test failure if it throws none).
template <class F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected granmem::Error";
  return "";
}

// Equal as stored numbers: the same double, or both NaN (CSV writes any NaN as "nan").
inline bool same_number(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

// Of a probability density table: the sum of counts, and the integral of the density.
inline double pdf_total_count(const Table& pdf) {
  double n = 0;
  for (double c : pdf["count"].values)
    n += c;
  return n;
}
inline double pdf_integral(const Table& pdf) {
  double sum = 0;
  for (std::size_t b = 0; b < pdf.rows(); ++b) {
    sum += pdf["density"].values[b] * (pdf["bin_hi"].values[b] - pdf["bin_lo"].values[b]);
  }
  return sum;
}

// Uniform on the unit sphere: a normalised Gaussian vector.
inline Eigen::Vector3d random_unit_vector(std::mt19937& rng) {
  std::normal_distribution<double> gauss;
  return Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
}

}  // namespace granmem::testing
