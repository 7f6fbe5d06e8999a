/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief What the walk produced. */
struct WalkResult {
  /** Oriented triangles (vertex ids), in the order the walk reached them. */
  std::vector<Triangle> triangles;
  /** Per triangle its id in the complex. */
  std::vector<int> ids;
  /** Connected components of the pruned complex (one walk each). */
  std::size_t components = 0;
  /** Triangles reached again through another edge with the opposite orientation. */
  std::size_t conflicts = 0;
  /** Extra walks started from triangles the first walks left with no vertex used. */
  std::size_t reseeds = 0;
  /** Clusters of flat tetrahedra whose side was chosen before the walk, whatever
   * its orientation (see walk()). */
  std::size_t flat_clusters = 0;
};

/** \brief SURFACENEIGHBOR: the triangle to continue with across edge x->y of the
 * oriented triangle (x, y, z).
 *
 * Among the present triangles at the edge whose normals, oriented consistently with
 * (x, y, z), make an angle below pi / 2 with its normal, the first one met rotating
 * about the edge from the side its normal points to.
 *
 * \return the triangle id, or -1; \a apex receives its third vertex
 */
int
surfaceNeighbor(const TriangleComplex& complex,
                const std::vector<std::uint8_t>& present,
                int t,
                int x,
                int y,
                int z,
                int& apex);

/** \brief Stage 7: WALK, started once in every connected component of the pruned
 * complex, from a triangle whose vertices all have umbrellas where possible; then
 * again from every present triangle whose vertices no walk has reached (a component
 * joined to another only by stray triangles that the walk does not cross).
 *
 * Where nearly cospherical points make flat Delaunay tetrahedra all of whose faces
 * are present, SURFACENEIGHBOR would keep the faces on the side the walk's
 * orientation faces, an orientation that comes from the seed. The side is chosen
 * before the walk instead, by a rule of the points alone (the side whose longest
 * inner edge is shorter, compared exactly), so that the triangles do not depend on
 * the order or the handedness of the points: a cloud and its mirror image, a tile
 * and the whole cloud, give the same.
 *
 * \param[in] complex the candidate triangles
 * \param[in] pruned per triangle: survived pruning
 * \param[in] boundary per vertex: B plus the umbrella failures
 * \param[in] threads threads to find the components with (the same walk)
 */
WalkResult
walk(const TriangleComplex& complex,
     const std::vector<std::uint8_t>& pruned,
     const std::vector<std::uint8_t>& boundary,
     int threads = 1);

/** \brief The edge incidences of the walk's triangles, as EdgeIncidences would group
 * them, read off the complex's grouping with up to \a threads threads. */
EdgeIncidences
walkedIncidences(const TriangleComplex& complex, const WalkResult& walked, int threads);

} // namespace cocone
} // namespace pcl
