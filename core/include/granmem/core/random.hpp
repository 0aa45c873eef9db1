#pragma once

#include <Eigen/Core>
#include <cstddef>
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

// FNV-1a of `size` bytes, continuing from `hash`: a digest (or a seed) that is the same
// on every platform, unlike std::hash.
inline constexpr std::uint64_t kFnv1aBasis = 14695981039346656037ull;
inline std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t hash = kFnv1aBasis) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t b = 0; b < size; ++b)
    hash = (hash ^ bytes[b]) * 1099511628211ull;
  return hash;
}

}  // namespace granmem
