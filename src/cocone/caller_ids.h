/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * From vertex ids back to the caller's ids, for the pipeline and the tiling (not
 * installed).
 */

#pragma once

#include <pcl/surface/cocone/pipeline.h>

namespace pcl {
namespace cocone {
namespace detail {

/** Fill Result::polygons from Result::triangles and turn Result::border_loops into
 * caller ids, each vertex standing as its Result::representative. */
inline void
meshToCallerIds(Result& result)
{
  result.polygons.reserve(result.triangles.size());
  for (const auto& t : result.triangles)
    result.polygons.push_back({result.representative[t[0]],
                               result.representative[t[1]],
                               result.representative[t[2]]});
  for (auto& loop : result.border_loops)
    for (auto& v : loop)
      v = result.representative[v];
}

} // namespace detail
} // namespace cocone
} // namespace pcl
