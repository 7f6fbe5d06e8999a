/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/pipeline.h>

#include <cstddef>

namespace pcl {
namespace cocone {

/** \brief What refineFilledHoles() did. */
struct HoleRefinement {
  /** Holes whose patch was refined and faired. */
  std::size_t holes = 0;
  /** Holes left with their first patch: CGAL made no new vertex (the patch is as
   * dense as its rim already), the patch is not a disk the rim bounds, or the
   * fairing's linear system had no solution. */
  std::size_t kept = 0;
  /** Vertices added. */
  std::size_t vertices = 0;
};

/** \brief Refine and fair the patches that closed undersampled holes, for users
 * who want a smooth surface there rather than the fewest triangles
 * (Parameters::refine_filled_holes).
 *
 * A hole's patch is the disk of triangles that its rim (Result::filled_holes)
 * bounds on the side away from the mesh it had. CGAL's Polygon_mesh_processing
 * refine() adds vertices inside it until its triangles are as dense as the mesh at
 * its rim (Liepa's refinement, density factor sqrt 2), and fair() moves the new
 * vertices so that the patch minimises the discrete bilaplacian with two rings of
 * the mesh round it fixed: the patch meets the surface round it with its tangent
 * plane, what CGAL's triangulate_refine_and_fair_hole() does for a hole of a
 * polygon mesh. Each patch is refined in a copy of it and those rings, so the cost
 * follows the holes, not the mesh; a hole whose patch cannot be refined keeps the
 * one it had (HoleRefinement::kept).
 *
 * The added vertices follow the input's: vertex ids from Result::vertices on, with
 * caller ids from \a first_id on (Result::representative), their positions
 * appended to Result::positions (in the frame the decisions were taken in, the
 * smoothed one when Result::smoothed), their normals (area-weighted over their
 * triangles) to Result::normals and false to the per-vertex labels;
 * Result::added_vertices counts them. Result::triangles and Result::polygons are
 * changed alike; the mesh stays an oriented 2-manifold and the loops, rims and
 * labels of the input points stay as they were.
 *
 * \param[in,out] result a reconstruction with its caller ids (run(), runTiled())
 * \param[in] first_id the caller id of the first added vertex: above every id the
 *            caller gave
 */
HoleRefinement
refineFilledHoles(Result& result, int first_id);

} // namespace cocone
} // namespace pcl
