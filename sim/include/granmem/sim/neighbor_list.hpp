#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "granmem/sim/grains.hpp"

namespace granmem {

// Verlet list of the grain pairs that may touch before any grain moves half a skin,
// found through a cell grid in O(N). Each pair is listed once, under its owner, the grain
// of smaller id, and every grain's pairs are sorted by the partner's id: so the order in
// which a grain's contact forces are summed depends on the grains alone, not on memory
// order, thread count or when the list was rebuilt.
class NeighborList {
 public:
  explicit NeighborList(double skin = 0) : skin_(skin) {}

  // Rebuilds from the grains' current positions.
  void build(const Grains& grains);
  // True once grain i, now at x, has moved more than half the skin since the last build:
  // the list must then be rebuilt.
  bool moved_too_far(const Eigen::Vector3d& x, std::size_t i) const {
    return i >= built_at_.size() || (x - built_at_[i]).squaredNorm() > 0.25 * skin_ * skin_;
  }

  double skin() const { return skin_; }
  void set_threads(int threads) { threads_ = threads; }
  std::size_t pair_count() const { return partner_.size(); }
  // Pairs owned by grain i: indices [begin(i), end(i)) into partner().
  std::uint32_t begin(std::size_t i) const { return offset_[i]; }
  std::uint32_t end(std::size_t i) const { return offset_[i + 1]; }
  const std::vector<std::uint32_t>& partner() const { return partner_; }
  // Pairs in which grain i is the partner: pair indices, sorted by the owner's id.
  std::uint32_t incoming_begin(std::size_t i) const { return incoming_offset_[i]; }
  std::uint32_t incoming_end(std::size_t i) const { return incoming_offset_[i + 1]; }
  const std::vector<std::uint32_t>& incoming() const { return incoming_; }
  // Owner of each pair.
  const std::vector<std::uint32_t>& owner() const { return owner_; }

  // Carries per-pair data (contact histories) from the pairs of `before` to this list's:
  // a pair present in both keeps its value, a new pair gets `fresh`.
  template <class T>
  std::vector<T> carry(const NeighborList& before, const std::vector<T>& values,
                       const std::vector<std::int64_t>& id, const T& fresh) const;

 private:
  double skin_;
  int threads_ = 1;
  std::vector<std::uint32_t> offset_, partner_, owner_;
  std::vector<std::uint32_t> incoming_offset_, incoming_;
  std::vector<Eigen::Vector3d> built_at_;
};

template <class T>
std::vector<T> NeighborList::carry(const NeighborList& before, const std::vector<T>& values,
                                   const std::vector<std::int64_t>& id, const T& fresh) const {
  std::vector<T> out(partner_.size(), fresh);
  if (before.offset_.size() != offset_.size()) return out;  // a different set of grains
  const std::size_t n = offset_.size() - 1;
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (std::size_t i = 0; i < n; ++i) {
    // Both lists of grain i are sorted by partner id: a merge finds the common pairs.
    std::uint32_t a = before.offset_[i];
    const std::uint32_t a_end = before.offset_[i + 1];
    for (std::uint32_t k = offset_[i]; k < offset_[i + 1] && a < a_end; ++k) {
      const std::int64_t want = id[partner_[k]];
      while (a < a_end && id[before.partner_[a]] < want)
        ++a;
      if (a < a_end && before.partner_[a] == partner_[k]) out[k] = values[a];
    }
  }
  return out;
}

}  // namespace granmem
