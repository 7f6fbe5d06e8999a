/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/candidates.h>

#include <algorithm>
#include <cmath>

namespace pcl {
namespace cocone {

std::vector<Triangle>
selectCandidates(const VoronoiCells& cells,
                 const std::vector<std::uint8_t>& boundary,
                 CandidateRule rule,
                 const Triangulation* dt,
                 const std::vector<double>& rim_reach)
{
  const bool rims = dt && rim_reach.size() == dt->points.size();
  // A rim vertex chooses a triangle when its co-cone meets the dual edge and the
  // triangle's edges at it are within its reach: its half of a disk.
  const auto rim_chooses = [&](const CoconeTriangle& t, int k) {
    const double r = rim_reach[t.v[k]];
    if (!(t.meets & (1u << k)))
      return false;
    for (int j = 1; j < 3; ++j)
      if ((dt->points[t.v[(k + j) % 3]] - dt->points[t.v[k]]).squaredNorm() > r * r)
        return false;
    return true;
  };
  std::vector<Triangle> out;
  // A triangle none of whose vertices' co-cones meet its dual edge is not in
  // cells.triangles; it can only be chosen by nobody.
  for (const auto& t : cells.triangles) {
    bool chosen = true, any_interior = false;
    for (int k = 0; k < 3; ++k)
      if (!boundary[t.v[k]]) {
        any_interior = true;
        chosen = chosen && (t.meets & (1u << k));
      }
    // Where no interior vertex chooses, at a border band more than one vertex wide,
    // the rim vertices do; undersampled vertices never choose.
    if (!any_interior && rims && rule == CandidateRule::INTERIOR_CHOOSES) {
      bool any_rim = false;
      for (int k = 0; k < 3 && chosen; ++k)
        if (std::isfinite(rim_reach[t.v[k]])) {
          any_rim = true;
          chosen = rim_chooses(t, k);
        }
      if (any_rim && chosen)
        out.push_back(t.v);
      continue;
    }
    if (chosen && (any_interior || rule == CandidateRule::LITERAL))
      out.push_back(t.v);
  }
  if (rule == CandidateRule::LITERAL && dt && dt->dimension == 3) {
    // All-boundary triangles whose dual edge meets no co-cone.
    forEachCell(*dt, CellView::FACETS, 1, [&](const CellView& cell, int) {
      for (int i = 0; i < 4; ++i) {
        if (cell.facet[i] == FacetRole::SHARED)
          continue;
        Triangle f;
        for (int k = 0, j = 0; k < 4; ++k)
          if (k != i)
            f[j++] = cell.v[k];
        std::sort(f.begin(), f.end());
        if (boundary[f[0]] && boundary[f[1]] && boundary[f[2]])
          out.push_back(f);
      }
    });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }
  return out;
}

} // namespace cocone
} // namespace pcl
