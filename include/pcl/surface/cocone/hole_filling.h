/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace pcl {
namespace cocone {

struct EdgeIncidences;

/** \brief What fillUndersampledHoles() did. */
struct HoleFilling {
  /** Border loops closed. */
  std::size_t holes = 0;
  /** Triangles added. */
  std::size_t triangles = 0;
  /** Edges of each hole closed, in the order of the loops. */
  std::vector<std::size_t> sizes;
};

/** \brief Close the border loops that are undersampled holes, not true borders
 * (the question Dey & Giesen leave open).
 *
 * A true border is where the sampled surface ends: across it there is nothing to
 * connect to within the sampling's resolution. An undersampled hole has samples all
 * around it that continue the surface, so it can be closed by triangles as short as
 * the sample spacing there: a loop is closed when CGAL's triangulate_hole_polyline()
 * (Liepa's minimum-weight triangulation over the 3D Delaunay faces of the loop's
 * vertices, weighted against folding over the triangles beside the loop) finds a
 * patch all of whose new edges are at most \a reach times the larger local spacing
 * of their ends (the plausibility of the advancing front, whose radius ratio bound
 * asks the same of a candidate triangle against its neighbour's) and none of which
 * the mesh has already. No new vertex; the patch faces as the loop's triangles do,
 * so the mesh stays an oriented 2-manifold.
 *
 * Assumes that the spacing along a true border is not more than 1 / reach times the
 * width of what it encloses: a true hole narrower than about reach spacings is
 * taken for undersampling and closed.
 * \param[in] points the vertex positions
 * \param[in] spacing per vertex its local spacing (localSpacing())
 * \param[in,out] triangles the oriented manifold mesh; the patches are appended
 * \param[in,out] incidences the mesh's edge incidences, kept up to date
 * \param[in,out] loops the mesh's border loops (boundaryLoops()); the closed ones are
 *                taken out
 * \param[in] reach the longest new edge allowed, in local spacings
 * \param[in] max_edges loops longer than this are left open (the search's time
 *                grows with the loop)
 */
HoleFilling
fillUndersampledHoles(const std::vector<Eigen::Vector3d>& points,
                      const std::vector<double>& spacing,
                      std::vector<Triangle>& triangles,
                      EdgeIncidences& incidences,
                      std::vector<std::vector<int>>& loops,
                      double reach,
                      std::size_t max_edges);

/** \brief Close border loops, and cover points no triangle uses, with the triangles
 * another mesh of the same vertices has there: the original Co-cone's, every vertex
 * choosing (the flatness test flags every point of a part sampled too coarsely for
 * it, a tube with a few samples around, so the boundary-aware mesh has nothing
 * there, while the Co-cone triangles still make the surface).
 *
 * A loop is closed by the triangles of \a other reached from its edges, on the side
 * away from the mesh, without crossing an edge of the mesh or a border of
 * \a other: they must make a disk whose border is the loop and whose inner
 * vertices no triangle of the mesh uses, and face as the mesh does (\a other turned
 * over if it faces the other way), every new edge at most \a reach local spacings
 * long as in fillUndersampledHoles() (where the original Co-cone covers a true
 * border's opening, it does so with long triangles). A closed component of \a other
 * with such edges, none of whose vertices the mesh uses, is added as it is.
 * \param[in] points the vertex positions
 * \param[in] spacing per vertex its local spacing (localSpacing())
 * \param[in] other an oriented manifold mesh of the same vertices
 * \param[in,out] triangles the oriented manifold mesh; the patches are appended
 * \param[in,out] incidences the mesh's edge incidences, kept up to date
 * \param[in,out] loops the mesh's border loops; the closed ones are taken out
 * \param[in] reach the longest new edge allowed, in local spacings
 * \param[in] max_edges loops longer than this are left open
 */
HoleFilling
fillHolesFromMesh(const std::vector<Eigen::Vector3d>& points,
                  const std::vector<double>& spacing,
                  const std::vector<Triangle>& other,
                  std::vector<Triangle>& triangles,
                  EdgeIncidences& incidences,
                  std::vector<std::vector<int>>& loops,
                  double reach,
                  std::size_t max_edges);

} // namespace cocone
} // namespace pcl
