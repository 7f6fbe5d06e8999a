/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief Edges of an oriented triangle list grouped by their end points.
 *
 * Incidence i of edge e says which triangle uses the edge and whether it traverses
 * it from the lower to the higher vertex id.
 */
struct EdgeIncidences {
  std::vector<std::array<int, 2>> edges; ///< end points, ascending
  std::vector<std::size_t> first;        ///< CSR offsets, size edges + 1
  std::vector<int> triangle;             ///< per incidence
  std::vector<std::uint8_t> forward;     ///< per incidence: traverses lower -> higher

  /** None: not grouped yet (see grouped()). */
  EdgeIncidences() = default;

  /** Group the edges of \a oriented, with up to \a threads threads. */
  explicit EdgeIncidences(const std::vector<Triangle>& oriented, int threads = 1);

  /** Group in the triangles \a oriented [from, end) too, as if grouped with the
   * others from the start (the triangles before \a from are those grouped). Linear
   * in the edges: cheaper than grouping all again when a few are added. */
  void
  add(const std::vector<Triangle>& oriented, std::size_t from);

  /** Take out the triangles marked in \a dropped and number the others as they
   * keep their order, as if grouped again after removing the marked ones from the
   * list. One pass over the incidences. */
  void
  remove(const std::vector<std::uint8_t>& dropped);

  /** Whether these are a grouping (of no triangle, too) rather than none. */
  bool
  grouped() const
  {
    return !first.empty();
  }

  /** The id of edge ab (either order), or -1 if there is none. */
  std::ptrdiff_t
  find(int a, int b) const;

  /** Number of triangles at edge e. */
  std::size_t
  count(std::size_t e) const
  {
    return first[e + 1] - first[e];
  }
};

/** \brief Per vertex, the fans of its star: groups of triangles connected through
 * edges at the vertex. A 2-manifold has one fan per vertex.
 *
 * \param[in] threads threads to go through the vertices with
 * \return per triangle corner (3 t + k): the fan id of vertex oriented[t][k] that the
 *         triangle belongs to, numbered from 0 per vertex
 */
std::vector<int>
vertexFans(const std::vector<Triangle>& oriented,
           std::size_t num_vertices,
           std::vector<int>* fans_per_vertex = nullptr,
           int threads = 1);

/** \brief Topology of an oriented triangle mesh. */
struct MeshTopology {
  std::size_t vertices = 0;              ///< vertices used by a triangle
  std::size_t edges = 0;                 ///< distinct edges
  std::size_t triangles = 0;             ///< triangles
  std::size_t boundary_edges = 0;        ///< edges in one triangle
  std::size_t nonmanifold_edges = 0;     ///< in more than two triangles
  std::size_t nonmanifold_vertices = 0;  ///< more than one fan
  std::size_t orientation_conflicts = 0; ///< edges traversed twice the same way
  std::size_t components = 0;            ///< through shared edges
  std::size_t closed_components = 0;     ///< components without boundary edges
  long euler = 0;                        ///< V - E + F

  /** Valid oriented 2-manifold with boundary. */
  bool
  manifold() const
  {
    return nonmanifold_edges == 0 && nonmanifold_vertices == 0 &&
           orientation_conflicts == 0;
  }
};

/** \brief Count the topology of an oriented triangle mesh. */
MeshTopology
analyzeMesh(const std::vector<Triangle>& oriented, std::size_t num_vertices);

/** \brief Count the topology of an oriented triangle mesh whose edges \a inc
 * groups already (EdgeIncidences of \a oriented). */
MeshTopology
analyzeMesh(const std::vector<Triangle>& oriented,
            std::size_t num_vertices,
            const EdgeIncidences& inc);

/** \brief The borders of an oriented 2-manifold mesh as closed vertex loops, each
 * traversed with the mesh on its left, starting at its lowest vertex id; loops are
 * sorted by that vertex. */
std::vector<std::vector<int>>
boundaryLoops(const std::vector<Triangle>& oriented, std::size_t num_vertices);

/** \brief boundaryLoops() from the mesh's edge incidences. */
std::vector<std::vector<int>>
boundaryLoops(const EdgeIncidences& inc, std::size_t num_vertices);

/** \brief The vertices of the edges that lie in exactly one triangle (the border
 * vertices of any triangle mesh, manifold or not), ascending. */
std::vector<int>
borderVertices(const std::vector<Triangle>& triangles);

/** \brief Per vertex (of \a num_vertices): whether it is an end of an edge in
 * exactly one triangle (\a inc): the border vertices, as a mask. */
std::vector<std::uint8_t>
borderMask(const EdgeIncidences& inc, std::size_t num_vertices);

/** \brief Per vertex (of \a num_vertices): whether a triangle uses it. */
std::vector<std::uint8_t>
usedVertices(const std::vector<Triangle>& triangles, std::size_t num_vertices);

/** \brief Component id of every triangle (through shared edges), numbered in order
 * of the lowest triangle of each component. */
std::vector<int>
triangleComponents(const std::vector<Triangle>& oriented, std::size_t* count = nullptr);

/** \brief The same from the edge incidences of \a num_triangles triangles. */
std::vector<int>
triangleComponents(const EdgeIncidences& inc,
                   std::size_t num_triangles,
                   std::size_t* count = nullptr);

/** \brief Per component (\a component numbers each triangle's, 0 to \a count - 1):
 * the signed volume of its triangles about the centroid of their corners, six times
 * that of the solid they bound when closed, positive when they face outward. */
std::vector<double>
signedVolumes(const std::vector<Eigen::Vector3d>& points,
              const std::vector<Triangle>& triangles,
              const std::vector<int>& component,
              std::size_t count);

} // namespace cocone
} // namespace pcl
