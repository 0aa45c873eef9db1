#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>

namespace granmem {

// Uniform and normal deviates from the 64-bit Mersenne Twister, whose raw sequence the
// C++ standard fixes, transformed here rather than by <random>'s distributions, whose
// results differ between standard libraries.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return double(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double normal();

 private:
  std::mt19937_64 engine_;
};

// Three standard normal draws of `source` (anything with normal()) as a vector, drawn z,
// y, x in statements of their own: C++ leaves the order of a constructor's arguments to the
// compiler, and this is the one GCC used, so that every compiler draws the same vector.
template <class Source>
Eigen::Vector3d normal_vector(Source& source) {
  const double z = source.normal(), y = source.normal(), x = source.normal();
  return {x, y, z};
}

}  // namespace granmem
