/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/voronoi_cell.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

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
 * (Parameters::fill_undersampled_holes); \a spacing per vertex its local spacing.
 * Nothing if the option is off or \a spacing is empty. */
void
closeUndersampledHoles(const std::vector<Eigen::Vector3d>& points,
                       const VoronoiCells& cells,
                       const Parameters& parameters,
                       const std::vector<double>& spacing,
                       EdgeIncidences& incidences,
                       Result& result);

} // namespace detail
} // namespace cocone
} // namespace pcl
