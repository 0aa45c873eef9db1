#pragma once

// The contact law and the grain model run once per contact and step, or per voxel and fit
// iteration: their small functions are forced inline so that the 3-vectors stay in
// registers (measured: a third fewer instructions) and their loops vectorise.
#if defined(__GNUC__)
#define GRANMEM_INLINE inline __attribute__((always_inline))
#else
#define GRANMEM_INLINE inline
#endif

// A loop over lanes compiled for x86-64-v4 (AVX-512), v3 (AVX2) and the baseline, the one
// picked when the program loads (an ifunc): GCC 12 or later on Linux. Elsewhere, and in a
// native build (-march=native), one version.
#if defined(__x86_64__) && defined(__linux__) && defined(__GNUC__) && !defined(__clang__) && \
    __GNUC__ >= 12 && !defined(GRANMEM_NATIVE_BUILD)
#define GRANMEM_LANE_TARGETS \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define GRANMEM_LANE_TARGETS
#endif
