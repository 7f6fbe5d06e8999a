/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief The unique finite points of an input, in a canonical order.
 *
 * Exact duplicates become one point (one Delaunay vertex); non-finite points are
 * dropped. The points are numbered along a Morton curve (ties lexicographically),
 * so vertex ids, and everything derived from them, depend only on the point set,
 * not on the order of the input, and neighbours in space have nearby ids.
 */
struct UniquePoints {
  /** Unique finite points in Morton order. */
  std::vector<Eigen::Vector3d> points;
  /** Per input point: its unique point, or -1 if it is not finite. */
  std::vector<int> vertex_of_input;
};

/** \brief Drop non-finite points and merge exact duplicates. */
UniquePoints
makeUniquePoints(const std::vector<Eigen::Vector3d>& input);

/** \brief Stage 1: the Delaunay triangulation (exact predicates) as flat arrays.
 *
 * Cells are indexed 0..cells.size()-1; a neighbour id of -1 means the facet
 * opposite that vertex lies on the convex hull. The circumcenters of the cells are
 * the vertices of the Voronoi diagram; each is computed once, here.
 *
 * When the points are coplanar (dimension 2) the "cells" are the triangles of the
 * planar Delaunay triangulation: cells[c][3] == -1, neighbors[c][i] is the triangle
 * across the edge opposite vertex i, and circumcenters lie in the plane.
 */
struct Triangulation {
  /** Affine dimension of the points: 3, 2 (coplanar), 1 (collinear), 0 or -1. */
  int dimension = -1;
  /** Vertex positions, recentred: the original point is points[v] + offset. */
  std::vector<Eigen::Vector3d> points;
  /** The lexicographically smallest point, subtracted before triangulating. */
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  /** Vertex ids of each finite cell. */
  std::vector<std::array<int, 4>> cells;
  /** neighbors[c][i]: the cell sharing the facet opposite cells[c][i], or -1. */
  std::vector<std::array<int, 4>> neighbors;
  /** Circumcenter of each cell (a Voronoi vertex). */
  std::vector<Eigen::Vector3d> circumcenters;
};

/** \brief Triangulate unique points (stage 1).
 *
 * \param[in] points unique points (see makeUniquePoints); vertex v of the result
 *            is points[v]
 */
Triangulation
triangulate(const std::vector<Eigen::Vector3d>& points);

/** \brief Circumcenter of a tetrahedron, stable for nearly flat ones.
 *
 * Evaluated relative to \a a in double; falls back to exact arithmetic when the
 * floating-point denominator vanishes. Callers pass the vertices in a canonical
 * order so that the result is bitwise reproducible.
 */
Eigen::Vector3d
tetrahedronCircumcenter(const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c,
                        const Eigen::Vector3d& d);

/** \brief Circumcenter of a triangle in space (in its plane). */
Eigen::Vector3d
triangleCircumcenter(const Eigen::Vector3d& a,
                     const Eigen::Vector3d& b,
                     const Eigen::Vector3d& c);

} // namespace cocone
} // namespace pcl
