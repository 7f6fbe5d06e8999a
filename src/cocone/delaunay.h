/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The Delaunay triangulation of stage 1 in flat arrays (not installed).
 */

#pragma once

#include <pcl/surface/cocone/triangulation.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "allocator.h"

#include <array>
#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/** A cell while the triangulation is built: four vertex ids, positively oriented
 * (INFINITE stands for the vertex at infinity, oriented as if it were a point
 * outside the hull, as in CGAL), and per facet the cell across it times four plus
 * the index of the shared facet there. */
struct BuildCell {
  static constexpr int INFINITE = -1;
  /** v[0] of a cell that was freed and not reused. */
  static constexpr int FREE = -2;
  std::array<int, 4> v;
  std::array<std::uint32_t, 4> n;
};

/** The cells as built, freed ones included (v[0] == BuildCell::FREE). */
using BuildCells = std::vector<BuildCell, DefaultInitAllocator<BuildCell>>;

/** The index of the vertex at infinity in a cell's vertices, -1 for a finite cell. */
inline int
infiniteCorner(const std::array<int, 4>& v)
{
  for (int i = 0; i < 4; ++i)
    if (v[i] == BuildCell::INFINITE)
      return i;
  return -1;
}

/** \brief The Delaunay triangulation of points in general position in space, by
 * Bowyer-Watson insertion in random rounds (a biased randomized insertion order),
 * each round by id.
 *
 * Every decision is CGAL's filtered exact predicate with CGAL's symbolic
 * perturbation of co-spherical and co-circular points, so the cells are those of
 * CGAL's Delaunay_triangulation_3: the Delaunay triangulation is unique under the
 * perturbation. Kept in two 16-byte arrays per cell instead of CGAL's linked cells,
 * which halves its memory and lets the passes read cells by index.
 *
 * With several threads, the points after the first eighth (the last round) are
 * cut into one stretch of ids per thread, a part of space each (makeUniquePoints
 * numbers the points along a Morton curve), and inserted at once; a thread holds
 * every cell it reads, and an insertion that meets a cell held by another thread is
 * left for the end, when one thread inserts what is left. The triangulation is
 * unique, so the cells are the same whatever the thread count (their order in
 * \a cells is not).
 * \param[in] points unique points; numbered along a space-filling curve (as
 *            makeUniquePoints numbers them), or the insertion's walks grow long
 * \param[out] cells the cells, finite and infinite, and freed ones (v[0] == FREE)
 * \param[in] threads threads to insert with
 * \return the affine dimension of the points: below 3 the cells are left empty
 */
int
buildDelaunay(const std::vector<Eigen::Vector3d>& points,
              BuildCells& cells,
              int threads = 1);

/** The triangulation as the passes read it: the finite cells in the order they
 * are visited, then the infinite ones (dimension 3: one per hull facet). */
struct DelaunayStructure {
  /** Vertex ids per cell (INFINITE for the vertex at infinity; dimension 2: the
   * three corners, then -1). */
  std::vector<std::array<int, 4>, DefaultInitAllocator<std::array<int, 4>>> vertices;
  /** Per cell, the cell across the facet opposite vertices[c][i]. */
  std::vector<std::array<int, 4>, DefaultInitAllocator<std::array<int, 4>>> neighbors;
  /** Cells [0, finite) are finite. */
  std::size_t finite = 0;
  /** Per finite cell its circumcenter once a pass has asked for them, null before:
   * in the memory the cells took while they were built (see build). */
  Eigen::Vector3d* circumcenters = nullptr;
  /** The cells as built, emptied: their pages are resident, and fresh pages would
   * cost more in page faults (0.7 ms a MB here) than computing the circumcenters. */
  BuildCells build;
};

} // namespace detail
} // namespace cocone
} // namespace pcl
