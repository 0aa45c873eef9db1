#pragma once

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

}  // namespace granmem
