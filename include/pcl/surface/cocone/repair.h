/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <vector>

namespace pcl {
namespace cocone {

struct EdgeIncidences;

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
  /** Added to close small holes (see fillHoles()). */
  std::size_t filled = 0;
  /** Dropped with components that have no inner vertex (see dropRibbons()) or as
   * bridges across gaps (see dropBridges()). */
  std::size_t ribbon = 0;
  /** Dropped with components of too few vertices (see dropSpecks()) or within a
   * spacing of a larger one (see dropLayers()). */
  std::size_t speck = 0;
  /** Peeled off true borders (see peelBorderSlivers()). */
  std::size_t peeled = 0;

  /** Triangles dropped in all. */
  std::size_t
  dropped() const
  {
    return nonmanifold_edge + nonmanifold_vertex + orientation + ribbon + speck +
           peeled;
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
 * \param[in] threads threads for the vertex fans
 * \param[in,out] incidences if given and not empty, the edge incidences of
 *                \a triangles (grouped here otherwise); if given, on return those of
 *                the repaired triangles, for fillHoles() to go on with
 * \param[in] whole_stars if given, per vertex whether \a triangles hold its whole
 *                star: only those are checked for several fans (a part of a mesh,
 *                cut out, splits the stars at its edge)
 */
void
repairManifold(const std::vector<Eigen::Vector3d>& points,
               std::vector<Triangle>& triangles,
               RepairCounts& counts,
               int threads = 1,
               EdgeIncidences* incidences = nullptr,
               const std::vector<std::uint8_t>* whole_stars = nullptr);

/** \brief Close border loops of at most \a max_edges edges by triangles that
 * \a allowed accepts (given their vertex ids ascending), oriented with their
 * neighbours.
 *
 * On noisy samples most spurious holes are one missing triangle. Each loop is
 * triangulated with the least total perimeter among the triangulations whose
 * triangles are all allowed and add no edge the mesh already has; a loop without
 * one stays open. The mesh must be an oriented 2-manifold, as repairManifold()
 * leaves it; it stays one (each hole is a simple loop, as every vertex has one fan,
 * and its triangles run against the loop), so no repair is needed afterwards.
 * \param[in,out] incidences if given and not empty, the edge incidences of
 *                \a triangles (grouped here otherwise); on return those of the
 *                filled mesh
 * \return the number of triangles added
 */
std::size_t
fillHoles(const std::vector<Eigen::Vector3d>& points,
          std::vector<Triangle>& triangles,
          const std::function<bool(const Triangle&)>& allowed,
          std::size_t max_edges = 3,
          EdgeIncidences* incidences = nullptr);

/** \brief Drop every component of the mesh that has no inner vertex (every vertex on
 * its border): a strip one triangle wide, such as a walk leaves from a border band,
 * samples no piece of surface.
 * \param[in,out] incidences if given and not empty, the edge incidences of
 *                \a triangles (grouped here otherwise); on return those of the
 *                triangles left
 * \return the number of triangles dropped
 */
std::size_t
dropRibbons(std::vector<Triangle>& triangles,
            std::size_t num_vertices,
            EdgeIncidences* incidences = nullptr);

/** \brief Drop the bridges across gaps: two triangles whose shared edge is all that
 * joins two parts of the mesh (a bridge of the dual graph) and is longer than
 * \a max_spacings local spacings of both its ends.
 *
 * Where two bodies pass a few spacings apart (two linked tori of CGAL's knot2,
 * 5 spacings), the walk can join them by a strip of two long triangles whose
 * sides lie on the borders round it: one surface then, with a loop round the
 * strip. A surface the sample resolves is wider than a triangle wherever it joins
 * two parts, and its edges are about a spacing long; such a strip is neither. The
 * strips one triangle wide within a part (a thin fin, an antler's tip) have edges
 * of about a spacing and stay. Repeated until no such bridge is left.
 * \param[in] points the vertex positions
 * \param[in] spacing per vertex its local spacing; empty: nothing is dropped
 * \param[in] max_spacings the longest bridge edge kept, in local spacings
 * \param[in,out] incidences as for dropSpecks()
 * \return the number of triangles dropped
 */
std::size_t
dropBridges(const std::vector<Eigen::Vector3d>& points,
            const std::vector<double>& spacing,
            double max_spacings,
            std::vector<Triangle>& triangles,
            EdgeIncidences* incidences = nullptr);

/** \brief Drop every component of the mesh with fewer than \a min_vertices
 * vertices, closed or not.
 *
 * Where two sheets come within a couple of spacings (two spheres nearly touching),
 * the walk leaves shards of a few triangles across the gap, which the hole filling
 * would close into beads; an outlier cluster of a few points off a scan gives a
 * tetrahedron. A closed surface needs more samples than that to be sampled at all
 * (a sphere covered at epsilon 1 takes about 4 / epsilon^2, at 0.5 sixteen), and a
 * piece of a few samples says nothing of the surface it came from. Their points
 * stay vertices, in no triangle.
 * \param[in,out] incidences if given and not empty, the edge incidences of
 *                \a triangles (grouped here otherwise); on return those of the
 *                triangles left
 * \return the number of triangles dropped
 */
std::size_t
dropSpecks(std::vector<Triangle>& triangles,
           std::size_t num_vertices,
           std::size_t min_vertices,
           EdgeIncidences* incidences = nullptr);

/** \brief Drop the components of the mesh that lie within the sampling of a larger
 * one: each of their vertices is within its local spacing (\a spacing) of a
 * triangle of a component of more vertices.
 *
 * Where two bodies come closer than the spacing (touching spheres, two registered
 * views of a surface a little apart) the walk and the patches can make a layer of
 * the samples between the two surfaces, a closed flat piece or a patch, apart from
 * both while each surface closes over it. What lies within a spacing of a surface
 * the sample does not resolve from it; a body of its own has a side farther off.
 * Their points stay vertices, in no triangle.
 * \param[in,out] incidences as for dropSpecks()
 * \return the number of triangles dropped
 */
std::size_t
dropLayers(const std::vector<Eigen::Vector3d>& points,
           const std::vector<double>& spacing,
           std::vector<Triangle>& triangles,
           EdgeIncidences* incidences = nullptr);

/** \brief Take the triangles marked in \a drop out of \a triangles (the others keep
 * their order) and, if given, out of their edge incidences \a inc.
 * \return the number taken out
 */
std::size_t
removeTriangles(std::vector<Triangle>& triangles,
                const std::vector<std::uint8_t>& drop,
                EdgeIncidences* inc = nullptr);

/** \brief Peel the border triangles whose border edge skips a sample: the
 * triangle's apex lies inside the edge's diametral ball (its angle there is obtuse,
 * an exact predicate), so the apex is as near the border as the edge is, and the
 * border passes through it instead.
 *
 * Where the samples along a border are uneven or noisy, the walk's border takes long
 * edges between the outermost samples and leaves the samples just inside them as
 * inner vertices: the mesh's border then misses parts of the sampled border (on
 * random samples with noise, up to 16 % of it farther than 2.5 spacings from a
 * border vertex). One pass: a triangle the peeling exposes is kept (peeling on eats
 * into the surface), and so is a triangle whose apex is on a border or the apex of
 * another peeled triangle (the mesh stays an oriented 2-manifold, no vertex is left
 * without a triangle). The number of loops and the Euler characteristic stay.
 * \param[in,out] incidences the edge incidences of \a triangles, kept up to date
 * \param[in,out] loops the border loops (vertex ids, the mesh on their left), updated
 * \return the number of triangles peeled
 */
std::size_t
peelBorderSlivers(const std::vector<Eigen::Vector3d>& points,
                  std::vector<Triangle>& triangles,
                  EdgeIncidences& incidences,
                  std::vector<std::vector<int>>& loops);

} // namespace cocone
} // namespace pcl
