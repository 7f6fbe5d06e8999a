/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/triangulation.h>
#include <pcl/surface/cocone/voronoi_cell.h>

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief How CANDIDATETRIANGLEEXTRACTION treats triangles of boundary vertices. */
enum class CandidateRule {
  /** At least one interior vertex, and every interior vertex's co-cone meets the dual
   * Voronoi edge. Measured better: it keeps no triangle across holes. */
  INTERIOR_CHOOSES,
  /** The paper's pseudocode read literally: a triangle is deleted only if an interior
   * vertex did not choose it, so every Delaunay triangle of three boundary vertices
   * stays (kept to measure the difference). */
  LITERAL
};

/** \brief Stage 4: the candidate triangles, chosen by the interior vertices.
 *
 * \param[in] cells stage 2 output
 * \param[in] boundary per vertex: in B (boundary_detection off: all zero, and every
 *            vertex chooses)
 * \param[in] rule see CandidateRule
 * \param[in] dt the triangulation, needed by the LITERAL rule and with \a rim_reach
 * \param[in] rim_reach per vertex, empty or: finite for a rim vertex of the half-disk
 *            test (halfDiskTest(), in \a boundary too), the longest edge at it of a
 *            triangle it chooses. Rim vertices choose only triangles without an
 *            interior vertex, so that a border band more than one vertex wide keeps
 *            its triangles while no triangle crosses a rim's gap.
 */
std::vector<Triangle>
selectCandidates(const VoronoiCells& cells,
                 const std::vector<std::uint8_t>& boundary,
                 CandidateRule rule = CandidateRule::INTERIOR_CHOOSES,
                 const Triangulation* dt = nullptr,
                 const std::vector<double>& rim_reach = {});

} // namespace cocone
} // namespace pcl
