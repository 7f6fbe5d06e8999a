/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <type_traits>
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

/** \brief Drop non-finite points and merge exact duplicates, with up to \a threads
 * threads (the same result). */
UniquePoints
makeUniquePoints(const std::vector<Eigen::Vector3d>& input, int threads = 1);

namespace detail {
struct DelaunayStructure;
} // namespace detail

/** \brief Stage 1: the Delaunay triangulation (exact predicates).
 *
 * The cells (random samples of a surface have about 14 per point) are kept in flat
 * arrays, four vertex ids and four neighbours per cell, in the order the passes of
 * stages 2 and 4 visit them (forEachCell()): by smallest vertex id, so neighbouring
 * cells and their vertices' records are visited close together. The first pass
 * that asks for circumcenters (the Voronoi vertices) computes them once, from the
 * vertices in ascending id order so that the bits are reproducible; release()
 * frees it all. In these arrays the cells and their circumcenters take about as
 * much memory as CGAL's linked cells alone.
 *
 * When the points are coplanar (dimension 2) the cells are the triangles of the
 * planar Delaunay triangulation.
 */
struct Triangulation {
  /** Affine dimension of the points: 3, 2 (coplanar), 1 (collinear), 0 or -1. */
  int dimension = -1;
  /** Vertex positions, recentred: the original point is points[v] + offset. */
  std::vector<Eigen::Vector3d> points;
  /** The lexicographically smallest point, subtracted before triangulating. */
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  /** Number of finite cells (tetrahedra, or triangles in dimension 2). */
  std::size_t number_of_cells = 0;
  /** The cells and their circumcenters; null once released. */
  std::shared_ptr<detail::DelaunayStructure> structure;

  /** Free the cells (the points stay) and hand their memory back to the system. */
  void
  release();
};

/** \brief Triangulate unique points (stage 1).
 *
 * Points in space are inserted one by one in random rounds, each along the ids
 * (Bowyer-Watson; with several threads, each in its own part of space); every
 * decision is one of CGAL's filtered exact predicates, with CGAL's symbolic
 * perturbation of co-spherical points, so the cells are exactly those of CGAL's
 * Delaunay_triangulation_3 (the Delaunay triangulation is unique under that
 * perturbation). Coplanar points are triangulated by CGAL.
 * \param[in] points unique points (see makeUniquePoints, whose numbering along a
 *            Morton curve keeps the insertion's walks short); vertex v of the
 *            result is points[v]. Taken by value: move them in and they become the
 *            result's recentred points without a copy.
 * \param[in] threads threads to insert the points with: the same cells whatever
 *            their number
 */
Triangulation
triangulate(std::vector<Eigen::Vector3d> points, int threads = 1);

/** \brief A thread count: \a requested, or all processors for 0 (PCL's
 * convention). */
int
resolveThreads(unsigned int requested);

/** \brief How a cell relates to the dual Voronoi edge of one of its facets. */
enum class FacetRole : std::uint8_t {
  /** The facet lies on the convex hull: its dual is a ray. */
  HULL,
  /** This cell visits the facet: exactly one of its two cells does. */
  OWN,
  /** The neighbour across the facet visits it. */
  SHARED
};

/** \brief A finite cell, as a pass over the triangulation sees it. */
struct CellView {
  /** Vertex ids; in dimension 2, v[3] is -1. */
  std::array<int, 4> v;
  /** Vertex ids of a cell a few visits ahead (-1 if none), for the pass to fetch
   * its per-vertex records into the cache before it needs them. */
  std::array<int, 4> ahead;
  /** What a pass asks forEachCell() to compute, besides the vertices and facets. */
  enum Data : unsigned int {
    CIRCUMCENTER = 1,
    FACETS = 2,
    NEIGHBORS = 4 | FACETS,
    EDGES = 8
  };
  /** The six edges of a tetrahedron, as pairs of indices into v; edge 5 - e joins
   * the two vertices not on edge e. */
  static constexpr std::array<std::array<int, 2>, 6> EDGE_ENDS{
      {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
  /** The circumcenter (the cell's Voronoi vertex), if CIRCUMCENTER was asked. */
  Eigen::Vector3d circumcenter;
  /** The facet opposite v[i] (the edge, in dimension 2), if FACETS was asked. */
  std::array<FacetRole, 4> facet;
  /** For an OWN facet, the circumcenter of the cell across it, if NEIGHBORS was
   * asked. */
  std::array<Eigen::Vector3d, 4> neighbor_circumcenter;
  /** Bit e set: this cell stands for edge EDGE_ENDS[e], if EDGES was asked
   * (dimension 3). Of the finite cells around an edge, those whose two neighbours
   * about it are visited later (an infinite cell counts as later) stand for it: at
   * least one, the first visited, so a pass that needs every Delaunay edge once or
   * more reads these; about a third of the cells in general. */
  std::uint8_t edges;
  /** Number of vertices: 4, or 3 in dimension 2. */
  int corners;

  /** On which side of the facet opposite v[i] (dimension 3) the cell is not: +1
   * where n = (p1 - p0) x (p2 - p0) points for the facet's points p0, p1, p2 by
   * ascending id, -1 opposite. Exact: CGAL orients every cell positively, so this
   * is the parity of a permutation, where n . (v[i] - p0) in floating point can
   * take the wrong sign for a flat cell. */
  int
  outwardSide(int i) const;
};

/** \brief A facet of the convex hull (dimension 3). */
struct HullFacet {
  /** Vertex ids, ascending. */
  std::array<int, 3> v;
  /** The side where the outside of the hull lies, as in CellView::outwardSide(). */
  int outward;
};

namespace detail {
using CellVisitor = void (*)(void* context, const CellView& cell, int thread);
void
visitCells(const Triangulation& dt,
           unsigned int data,
           int threads,
           CellVisitor visitor,
           void* context);
using HullFacetVisitor = void (*)(void* context, const HullFacet& facet);
void
visitHullFacets(const Triangulation& dt, HullFacetVisitor visitor, void* context);
} // namespace detail

/** \brief Call visit(facet) once for every facet of the convex hull (dimension 3),
 * a HullFacet. The order of the calls is unspecified. */
template <typename Visit>
void
forEachHullFacet(const Triangulation& dt, Visit&& visit)
{
  detail::visitHullFacets(
      dt,
      [](void* context, const HullFacet& facet) {
        (*static_cast<std::remove_reference_t<Visit>*>(context))(facet);
      },
      const_cast<void*>(static_cast<const void*>(&visit)));
}

/** \brief Call visit(cell, thread) once for every finite cell.
 *
 * The cells are split among \a threads threads (thread is 0..threads-1); the order
 * of the calls is unspecified, so visitors must combine their results in a way that
 * does not depend on it.
 * \param[in] dt a triangulation not yet released
 * \param[in] data what to compute: a combination of CellView::Data
 * \param[in] threads number of threads (at least 1)
 * \param[in] visit the callable
 */
template <typename Visit>
void
forEachCell(const Triangulation& dt, unsigned int data, int threads, Visit&& visit)
{
  detail::visitCells(
      dt,
      data,
      threads,
      [](void* context, const CellView& cell, int thread) {
        (*static_cast<std::remove_reference_t<Visit>*>(context))(cell, thread);
      },
      const_cast<void*>(static_cast<const void*>(&visit)));
}

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
