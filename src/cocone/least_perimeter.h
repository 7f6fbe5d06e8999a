/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <limits>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** The tables of leastPerimeterTriangulation(), kept between calls so that closing
 * many small holes allocates once. */
struct LeastPerimeterScratch {
  std::vector<double> cost, length;
  std::vector<int> split;
  std::vector<std::array<std::size_t, 2>> stack;
};

/** The triangulation of a closed polygon (a hole's loop) with the least total
 * perimeter among those made of triangles \a valid (i, m, j) accepts, i < m < j
 * positions in \a loop: dynamic programming over the polygon's sub-chains, cubic in
 * its vertices. Each triangle (loop[i], loop[m], loop[j]) is appended to \a out in
 * the loop's order; false (and \a out unchanged) if no such triangulation exists.
 *
 * Where CGAL's triangulate_hole_polyline() weighs dihedral angles first (Liepa), this
 * weighs length only: the patch of a long narrow hole is the strip across it, not a
 * fan from one end. */
template <typename Valid>
bool
leastPerimeterTriangulation(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<int>& loop,
                            const Valid& valid,
                            std::vector<std::array<int, 3>>& out,
                            LeastPerimeterScratch& scratch)
{
  const std::size_t k = loop.size();
  if (k < 3)
    return false;
  const double inf = std::numeric_limits<double>::infinity();
  auto& cost = scratch.cost;
  auto& split = scratch.split;
  auto& length = scratch.length; // the loop's pairwise distances, read k times each
  cost.assign(k * k, inf);
  split.assign(k * k, -1);
  length.assign(k * k, 0.0);
  for (std::size_t i = 0; i < k; ++i)
    for (std::size_t j = i + 1; j < k; ++j)
      length[i * k + j] = (points[loop[i]] - points[loop[j]]).norm();
  for (std::size_t i = 0; i + 1 < k; ++i)
    cost[i * k + i + 1] = 0.0;
  for (std::size_t len = 2; len < k; ++len)
    for (std::size_t i = 0; i + len < k; ++i) {
      const std::size_t j = i + len;
      for (std::size_t m = i + 1; m < j; ++m) {
        const double c = cost[i * k + m] + cost[m * k + j];
        if (!(c < inf) || !valid(i, m, j))
          continue;
        const double w = c + length[i * k + m] + length[m * k + j] + length[i * k + j];
        if (w < cost[i * k + j]) {
          cost[i * k + j] = w;
          split[i * k + j] = static_cast<int>(m);
        }
      }
    }
  if (!(cost[k - 1] < inf))
    return false;
  auto& stack = scratch.stack;
  stack.assign(1, {0, k - 1});
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (j - i < 2)
      continue;
    const std::size_t m = split[i * k + j];
    out.push_back({loop[i], loop[m], loop[j]});
    stack.push_back({i, m});
    stack.push_back({m, j});
  }
  return true;
}

} // namespace detail
} // namespace cocone
} // namespace pcl
