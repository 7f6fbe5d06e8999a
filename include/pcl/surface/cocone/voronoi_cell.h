/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/triangulation.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief A Delaunay triangle whose dual Voronoi edge meets the co-cone of at least
 * one of its vertices.
 *
 * Only these triangles matter later: the co-cone neighbours (stage 3) and the
 * candidate triangles (stage 4) are read off them.
 */
struct CoconeTriangle {
  /** Vertex ids, ascending. */
  std::array<int, 3> v;
  /** Bit k set: the co-cone of v[k] meets the dual Voronoi edge. */
  std::uint8_t meets;
};

/** \brief Stage 2: the geometry of every Voronoi cell V_p (Dey & Giesen, section 2.3).
 *
 * All arrays are indexed by vertex id.
 */
struct VoronoiCells {
  /** Unit direction of the pole vector v+ - p. For a vertex on the convex hull (V_p
   * unbounded) the normalised sum of the outward normals of its hull facets. */
  std::vector<Eigen::Vector3d> pole;
  /** h+ = |v+ - p|; infinite on the convex hull. */
  std::vector<double> height_plus;
  /** h- = |v- - p|, v- the farthest Voronoi vertex of V_p on the other side of p
   * from v+; infinite if an unbounded edge of V_p goes that way, 0 if none does. */
  std::vector<double> height_minus;
  /** Co-cone width w = max |py| over y in C_p; infinite if C_p is unbounded or empty.
   */
  std::vector<double> width;
  /** Per vertex: on the convex hull. */
  std::vector<std::uint8_t> on_hull;
  /** The Delaunay triangles whose dual edge meets a co-cone, sorted by vertex ids. */
  std::vector<CoconeTriangle> triangles;
  /** Number of nearest Delaunay neighbours kept per vertex. */
  static constexpr int NEAREST = 12;
  /** Per vertex its NEAREST nearest Delaunay neighbours (the sites across the
   * nearest facets of V_p), nearest first, ties by id; -1 after the last if it has
   * fewer. Gathered in the first pass over the cells: the local spacing and the
   * half-disk test of stage 3 read them instead of walking the triangulation again.
   */
  std::vector<std::array<int, NEAREST>> nearest;

  /** Height h = min(h+, h-). */
  double
  height(int v) const
  {
    return std::min(height_plus[v], height_minus[v]);
  }
};

/** \brief Result of intersecting one Voronoi edge with one co-cone. */
struct CoconeHit {
  /** The edge has a point in the co-cone. */
  bool meets = false;
  /** Largest distance from p over that part of the edge; infinite when a ray stays
   * in the co-cone; -infinity when the edge misses it. */
  double max_distance = -std::numeric_limits<double>::infinity();
};

/** \brief Exact edge/co-cone test.
 *
 * The co-cone of p is {y : |cos angle(y - p, pole)| <= cos_angle}. Along the edge
 * y(t) = a + t d, with t in [0, 1] for a segment and t in [0, inf) for a ray, the
 * condition is a quadratic inequality in t, solved here: an edge may cross the
 * co-cone between two end points that both lie outside it. A segment is solved from
 * its end nearer to p: from a far end (a flat cell's circumcenter) the crossing near
 * p would be lost in rounding.
 *
 * \param[in] p the sample point
 * \param[in] pole unit pole direction of p
 * \param[in] cos_angle cosine of the co-cone angle (cos(3 pi / 8) by default)
 * \param[in] a start of the edge
 * \param[in] d direction (segment: the vector to the end point)
 * \param[in] ray the edge is a ray
 */
CoconeHit
intersectCocone(const Eigen::Vector3d& p,
                const Eigen::Vector3d& pole,
                double cos_angle,
                const Eigen::Vector3d& a,
                const Eigen::Vector3d& d,
                bool ray);

/** \brief Stage 2, first pass over the cells: the poles, h+, the convex-hull flags
 * and the nearest Delaunay neighbours (in dimension 2, the whole of stage 2).
 *
 * Stage 3 reads the neighbour lists; it can run before computeCocones(), so that
 * the lists are freed before the second pass, the peak of the pipeline.
 * \param[in] dt the triangulation (dimension 2 or 3)
 * \param[in] cocone_angle the co-cone angle in radians (used in dimension 2 only)
 * \param[in] num_threads threads to use, 0 for all processors
 */
VoronoiCells
computePoles(const Triangulation& dt,
             double cocone_angle,
             unsigned int num_threads = 1);

/** \brief Stage 2, second pass: h-, the co-cone widths and the co-cone triangles,
 * from the poles of computePoles().
 * \param[in] dt the triangulation computePoles() read
 * \param[in] cocone_angle the co-cone angle in radians (3 pi / 8 in the paper)
 * \param[in] num_threads threads to use, 0 for all processors
 * \param[in,out] cells the result of computePoles(), completed
 */
void
computeCocones(const Triangulation& dt,
               double cocone_angle,
               unsigned int num_threads,
               VoronoiCells& cells);

/** \brief Compute poles, heights, widths and the co-cone triangles (stage 2):
 * computePoles() then computeCocones().
 *
 * The result does not depend on the number of threads.
 * \param[in] dt the triangulation (dimension 2 or 3)
 * \param[in] cocone_angle the co-cone angle in radians (3 pi / 8 in the paper)
 * \param[in] num_threads threads to use, 0 for all processors
 */
VoronoiCells
computeVoronoiCells(const Triangulation& dt,
                    double cocone_angle,
                    unsigned int num_threads = 1);

} // namespace cocone
} // namespace pcl
