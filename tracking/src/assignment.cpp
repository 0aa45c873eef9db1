#include "granmem/tracking/assignment.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include "granmem/core/error.hpp"

namespace granmem {

// Successive shortest augmenting paths with potentials (the primal-dual Hungarian method in
// its sparse, Dijkstra form, as in Jonker & Volgenant 1987). Invariants, for every row r
// already placed and every edge (r, c):
//   reduced(r, c) = cost(r, c) - u[r] - v[c] >= 0, and = 0 on the pairs taken,
// which certify that the current partial assignment is of minimum cost. A new row s gets
// u[s] = min_c (cost(s, c) - v[c]); Dijkstra on reduced costs then finds the cheapest
// alternating path from s to a free column t (length D), the path is flipped, and for each
// column c settled before t (distance dist[c] <= D):  v[c] -= D - dist[c],  u[row of c] +=
// D - dist[c],  u[s] += D, which keeps every reduced cost non-negative and makes the new
// path's edges tight. Row r's private column (index cols + r, cost `unassigned_cost`) is
// the "left unassigned" choice; since it is free until r takes it, every search ends.
std::vector<std::int64_t> min_cost_assignment(const SparseCosts& g, double unassigned_cost) {
  if (g.offsets.size() != g.rows + 1 || g.columns.size() != g.costs.size() ||
      g.offsets.back() != g.columns.size() || !std::is_sorted(g.offsets.begin(), g.offsets.end())) {
    throw Error("min_cost_assignment: malformed cost graph");
  }
  if (!(unassigned_cost >= 0) || !std::isfinite(unassigned_cost)) {
    throw Error("min_cost_assignment: the cost of leaving a row out must be finite and >= 0");
  }
  for (std::size_t k = 0; k < g.costs.size(); ++k) {
    if (!(g.costs[k] >= 0) || !std::isfinite(g.costs[k]) || g.columns[k] >= g.cols) {
      throw Error("min_cost_assignment: costs must be finite and >= 0, columns in range");
    }
  }
  const std::size_t rows = g.rows, cols = g.cols, all_cols = cols + rows;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr std::int64_t kFree = -1;

  std::vector<double> u(rows, 0.0), v(all_cols, 0.0), dist(all_cols, kInf);
  std::vector<std::int64_t> col_row(all_cols, kFree), row_col(rows, kFree);
  std::vector<std::int64_t> pred(all_cols, kFree);  // the row a column was reached from
  std::vector<char> settled(all_cols, 0);
  std::vector<std::size_t> touched, done;
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;

  // Calls f(column, cost) for the edges of row r, its private column included.
  auto for_edges = [&](std::size_t r, auto&& f) {
    for (std::size_t k = g.offsets[r]; k < g.offsets[r + 1]; ++k) {
      // A pair dearer than leaving the row out is never worth taking.
      if (g.costs[k] < unassigned_cost) f(std::size_t(g.columns[k]), g.costs[k]);
    }
    f(cols + r, unassigned_cost);
  };

  for (std::size_t s = 0; s < rows; ++s) {
    double us = kInf;
    for_edges(s, [&](std::size_t c, double cost) { us = std::min(us, cost - v[c]); });
    u[s] = us;

    auto relax = [&](std::size_t r, double base) {
      for_edges(r, [&](std::size_t c, double cost) {
        if (settled[c]) return;
        const double d = base + std::max(0.0, cost - u[r] - v[c]);  // >= 0 up to rounding
        if (d < dist[c]) {
          if (dist[c] == kInf) touched.push_back(c);
          dist[c] = d;
          pred[c] = std::int64_t(r);
          heap.push({d, c});
        }
      });
    };
    relax(s, 0.0);
    std::size_t target = all_cols;
    double D = 0;
    while (!heap.empty()) {
      const auto [d, c] = heap.top();
      heap.pop();
      if (settled[c] || d > dist[c]) continue;
      settled[c] = 1;
      done.push_back(c);
      if (col_row[c] == kFree) {
        target = c;
        D = d;
        break;
      }
      relax(std::size_t(col_row[c]), d);
    }
    // The private column is free until s itself takes it: a free column is always found.
    // Potentials first (they refer to the assignment before the flip).
    for (std::size_t c : done) {
      if (c == target) continue;
      const double delta = D - dist[c];
      v[c] -= delta;
      u[std::size_t(col_row[c])] += delta;
    }
    u[s] += D;
    // Flip the alternating path s -> ... -> target.
    for (std::size_t c = target;;) {
      const auto r = std::size_t(pred[c]);
      const std::int64_t previous = row_col[r];
      row_col[r] = std::int64_t(c);
      col_row[c] = std::int64_t(r);
      if (r == s) break;
      c = std::size_t(previous);
    }
    for (std::size_t c : touched) {
      dist[c] = kInf;
      settled[c] = 0;
      pred[c] = kFree;
    }
    touched.clear();
    done.clear();
    heap = {};
  }
  for (std::int64_t& c : row_col) {
    if (c >= std::int64_t(cols)) c = kFree;
  }
  return row_col;
}

}  // namespace granmem
