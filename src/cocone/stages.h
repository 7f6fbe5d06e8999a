/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/voronoi_cell.h>

#include <Eigen/Core>

#include "points.h"

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Which co-cone triangles have every edge within FAR_NEIGHBOUR spacings
 * (triangleWithinReach()): those the undersampled holes' stage follows over the
 * surface (the unmeshed parts, the rings round a hole, the islands), not those along
 * the convex hull or across a wide void. Read at the first need, then kept: a clean
 * cloud has no hole to follow them round. */
class CoconeTrianglesWithinReach {
public:
  CoconeTrianglesWithinReach(const std::vector<Eigen::Vector3d>& points,
                             const std::vector<double>& spacing,
                             const std::vector<CoconeTriangle>& triangles)
  : points_(points), spacing_(spacing), triangles_(triangles)
  {}

  /** Per co-cone triangle (as \a triangles orders them), 1 if within reach. */
  const std::vector<std::uint8_t>&
  mask()
  {
    if (mask_.empty() && !triangles_.empty()) {
      mask_.resize(triangles_.size());
      for (std::size_t i = 0; i < triangles_.size(); ++i)
        mask_[i] =
            triangleWithinReach(points_, spacing_, FAR_NEIGHBOUR, triangles_[i].v);
    }
    return mask_;
  }

private:
  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<double>& spacing_;
  const std::vector<CoconeTriangle>& triangles_;
  std::vector<std::uint8_t> mask_;
};

/** Stages 5-7 and the repair over stage 4's candidates: the oriented manifold
 * mesh, its edge incidences, and per vertex whether it failed the umbrella check. */
struct WalkedMesh {
  std::vector<Triangle> triangles;
  EdgeIncidences incidences;
  std::vector<std::uint8_t> umbrella_failed;
};

/** Stages 5-7 and the repair over \a candidates, with the undersampled points
 * \a labels marks; the stages' figures added to \a counts. */
WalkedMesh
walkCandidates(const std::vector<Eigen::Vector3d>& points,
               const std::vector<Triangle>& candidates,
               const std::vector<std::uint8_t>& labels,
               int threads,
               ReconstructionCounts& counts);

/** The original Co-cone's mesh (every vertex chooses) over the vertices of the
 * \a region and the co-cone triangles among them. */
std::vector<Triangle>
plainCoconeMesh(const std::vector<Eigen::Vector3d>& points,
                const VoronoiCells& cells,
                const std::vector<std::uint8_t>& region,
                int threads);

/** The undersampled holes of the walk's mesh (result.triangles, its edges
 * \a incidences and its loops result.border_loops) closed, its true borders kept
 * (Parameters::fill_undersampled_holes); \a spacing per vertex its local spacing,
 * \a within_reach over \a cells' triangles. Nothing if the option is off or
 * \a spacing is empty. */
void
closeUndersampledHoles(const std::vector<Eigen::Vector3d>& points,
                       const VoronoiCells& cells,
                       const Parameters& parameters,
                       const std::vector<double>& spacing,
                       CoconeTrianglesWithinReach& within_reach,
                       EdgeIncidences& incidences,
                       Result& result);

} // namespace detail
} // namespace cocone
} // namespace pcl
