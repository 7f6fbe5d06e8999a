/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include <Eigen/Core>

#include <vector>

namespace pcl {
namespace cocone {

/** \brief What the repair after the walk changed, in triangles. */
struct RepairCounts {
  /** Dropped at edges with more than two triangles. */
  std::size_t nonmanifold_edge = 0;
  /** Dropped from the smaller fans of vertices with several fans. */
  std::size_t nonmanifold_vertex = 0;
  /** Dropped because no orientation of their component agreed with them. */
  std::size_t orientation = 0;
  /** Turned over to agree with their component. */
  std::size_t flipped = 0;
  /** Added to close holes of three edges (single missing triangles). */
  std::size_t filled = 0;

  /** Triangles dropped in all. */
  std::size_t
  dropped() const
  {
    return nonmanifold_edge + nonmanifold_vertex + orientation;
  }
};

/** \brief Make an oriented triangle list a valid oriented 2-manifold with boundary.
 *
 * The walk of the paper leaves defects next to boundary vertices: an edge that a
 * triangle reached through another edge gives a third triangle, and triangles of
 * opposite orientation. At an edge with more than two triangles the consistently
 * oriented pair whose normals agree best is kept; at a vertex with several fans the
 * largest fan is kept; each component is then oriented from its first triangle
 * across the edges whose triangles agree best in their normals first (so that a
 * non-orientable fold is cut at the fold, by dropping a triangle there), and turned
 * so that its signed volume about its centroid is positive (closed components face
 * outward). Repeats until nothing changes.
 *
 * \param[in] points vertex positions
 * \param[in,out] triangles oriented triangles
 * \param[in,out] counts what was changed (added to)
 */
void
repairManifold(const std::vector<Eigen::Vector3d>& points,
               std::vector<Triangle>& triangles,
               RepairCounts& counts);

/** \brief Close every border loop of exactly three edges whose triangle is in
 * \a allowed (sorted vertex triples, ascending), oriented with its neighbours.
 *
 * On noisy samples most spurious holes are one missing triangle. The mesh must be a
 * 2-manifold; repairManifold() should run again afterwards.
 * \return the number of triangles added
 */
std::size_t
fillTriangleHoles(std::vector<Triangle>& triangles,
                  std::size_t num_vertices,
                  const std::vector<Triangle>& allowed);

} // namespace cocone
} // namespace pcl
