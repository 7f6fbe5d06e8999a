/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * From vertex ids back to the caller's ids, for the pipeline and the tiling (not
 * installed).
 */

#pragma once

#include <pcl/surface/cocone/pipeline.h>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Each loop rotated to start at its lowest id, the loops ordered by it: a listing
 * that depends neither on the order the loops were found in nor on who found them. */
inline void
sortLoops(std::vector<std::vector<int>>& loops)
{
  for (auto& loop : loops)
    std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end()), loop.end());
  std::sort(loops.begin(), loops.end());
}

/** The caller id of the first vertex refineFilledHoles() adds: one above the
 * largest of \a ids (of \a count points when \a ids is empty); -1 if there is none
 * (the largest is the largest int). */
inline int
firstAddedId(const std::vector<int>& ids, std::size_t count)
{
  if (ids.empty())
    return count < static_cast<std::size_t>(std::numeric_limits<int>::max())
               ? static_cast<int>(count)
               : -1;
  const int largest = *std::max_element(ids.begin(), ids.end());
  return largest < std::numeric_limits<int>::max() ? largest + 1 : -1;
}

/** Result::polygons made anew from Result::triangles, each vertex standing as its
 * Result::representative. */
inline void
polygonsFromTriangles(Result& result)
{
  result.polygons.clear();
  result.polygons.reserve(result.triangles.size());
  for (const auto& t : result.triangles)
    result.polygons.push_back({result.representative[t[0]],
                               result.representative[t[1]],
                               result.representative[t[2]]});
}

/** Fill Result::polygons from Result::triangles and turn Result::border_loops and
 * Result::filled_holes into caller ids, each vertex standing as its
 * Result::representative. */
inline void
meshToCallerIds(Result& result)
{
  polygonsFromTriangles(result);
  for (auto& loop : result.border_loops)
    for (auto& v : loop)
      v = result.representative[v];
  for (auto& loop : result.filled_holes)
    for (auto& v : loop)
      v = result.representative[v];
  sortLoops(result.filled_holes);
}

} // namespace detail
} // namespace cocone
} // namespace pcl
