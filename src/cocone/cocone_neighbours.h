/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The co-cone triangles' vertex adjacency, shared by the stages that grow regions
 * through them (not installed).
 */

#pragma once

#include <pcl/surface/cocone/voronoi_cell.h>

#include <cstddef>
#include <numeric>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Per vertex, the corners of its co-cone triangles, in compressed rows: the
 * neighbours of v are neighbour[first[v]] .. neighbour[first[v + 1] - 1]. */
struct CoconeNeighbours {
  std::vector<std::size_t> first;
  std::vector<int> neighbour;
};

/** The corners b of each co-cone triangle at a vertex a (a itself included) that
 * \a keep (b) accepts, per vertex in the order of the triangles. */
template <typename Keep>
CoconeNeighbours
coconeNeighbours(const std::vector<CoconeTriangle>& triangles,
                 std::size_t num_vertices,
                 const Keep& keep)
{
  CoconeNeighbours out;
  out.first.assign(num_vertices + 1, 0);
  for (const auto& t : triangles)
    for (const int a : t.v)
      for (const int b : t.v)
        out.first[a + 1] += keep(b) ? 1 : 0;
  std::partial_sum(out.first.begin(), out.first.end(), out.first.begin());
  out.neighbour.resize(out.first.back());
  std::vector<std::size_t> next(out.first.begin(), out.first.end() - 1);
  for (const auto& t : triangles)
    for (const int a : t.v)
      for (const int b : t.v)
        if (keep(b))
          out.neighbour[next[a]++] = b;
  return out;
}

} // namespace detail
} // namespace cocone
} // namespace pcl
