/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/voronoi_cell.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
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
  /** The border loop of each hole closed (vertex ids, the mesh on its left as it
   * was before), in the order they were closed. */
  std::vector<std::vector<int>> rims;
};

/** \brief How fillUndersampledHoles() weighs the triangulations of a loop. */
enum class HoleWeight {
  /** CGAL's triangulate_hole_polyline(): Liepa's minimum-weight triangulation (the
   * largest dihedral angle, then the area) over the 3D Delaunay faces of the loop's
   * vertices, and over all their triangles for loops of up to 40 edges; the patch is
   * then checked against the reach. */
  DIHEDRAL_ANGLES,
  /** The least total edge length among the triangulations whose new edges are
   * within the reach, unless it folds (two of its triangles, or one and the mesh's
   * beside the loop, facing more than 150 degrees apart); loops of up to 128 edges
   * (the search is cubic). Across a long narrow hole, such as a slit along the rim of
   * a plate thinner than the spacing, the dihedral angles prefer a fan of long edges
   * from one end (3 to 4.7 spacings measured), the length the strip across it. */
  LEAST_PERIMETER
};

/** \brief Close the border loops that are undersampled holes, not true borders
 * (the question Dey & Giesen leave open).
 *
 * A true border is where the sampled surface ends: across it there is nothing to
 * connect to within the sampling's resolution. An undersampled hole has samples all
 * around it that continue the surface, so it can be closed by triangles as short as
 * the sample spacing there: a loop is closed when the triangulation of its polygon
 * that \a weight prefers has all its new edges at most \a reach times the larger
 * local spacing of their ends (the plausibility of the advancing front, whose radius
 * ratio bound asks the same of a candidate triangle against its neighbour's) and
 * none of them in the mesh already. No new vertex; the patch faces as the loop's
 * triangles do, so the mesh stays an oriented 2-manifold.
 *
 * A patch folded flat back onto the mesh beside the loop (within a degree) is
 * refused: it would close a sheet's outline with the sheet's other side, a closed
 * piece of no volume.
 *
 * Where the sampling is finer along the rim than across it (a crease sampled along
 * its line, a vertex set that is dense round a face and sparse across it) the local
 * spacing, a mean over the nearest samples, reads the fine direction; the triangles
 * at the loop's rim read the coarse one. With \a rim_reach > 0 a new edge may also
 * be as long as rim_reach times the median circumdiameter of those triangles.
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
 * \param[in] true_border per vertex: on a true border (classifyBorderLoops()), whose
 *                loop stays open; empty: none
 * \param[in] weight which triangulation of a loop is tried: the pipeline tries the
 *                dihedral angles first and the least perimeter on the loops every
 *                other patch has left
 * \param[in] rim_reach the longest new edge allowed besides, in diameters of the
 *                loop's rim triangles (see above); 0: only \a reach
 */
HoleFilling
fillUndersampledHoles(const std::vector<Eigen::Vector3d>& points,
                      const std::vector<double>& spacing,
                      std::vector<Triangle>& triangles,
                      EdgeIncidences& incidences,
                      std::vector<std::vector<int>>& loops,
                      double reach,
                      std::size_t max_edges,
                      const std::vector<std::uint8_t>& true_border = {},
                      HoleWeight weight = HoleWeight::DIHEDRAL_ANGLES,
                      double rim_reach = 0.0);

/** \brief Close border loops, and cover points no triangle uses, with the triangles
 * another mesh of the same vertices has there: the original Co-cone's, every vertex
 * choosing (the flatness test flags every point of a part sampled too coarsely for
 * it, a tube with a few samples around, so the boundary-aware mesh has nothing
 * there, while the Co-cone triangles still make the surface), or the advancing
 * front's (advancingFrontMesh()).
 *
 * A loop is closed by the triangles of \a other reached from its edges, on the side
 * away from the mesh, without crossing an edge of the mesh or a border of
 * \a other: they must make a disk whose border is the loop and whose inner
 * vertices no triangle of the mesh uses, and face as the mesh does (\a other turned
 * over if it faces the other way), every new edge at most \a reach local spacings
 * long as in fillUndersampledHoles() (where another mesh covers a true border's
 * opening, it does so with long triangles).
 *
 * Where the two meshes disagree next to the hole (a loop edge \a other does not
 * have, a triangle of \a other that would cross an edge of the mesh or use a vertex
 * the mesh uses), the mesh's triangles there join a band around the hole, at most
 * \a band_per_edge per loop edge, and the patch is sought on the band's rim
 * instead: it replaces the band if the band with the holes it holds capped has the
 * patch's Euler characteristic (the genus stays; the mesh's loops the band takes
 * in are closed with it), the rim leaves each of its vertices once, and every new
 * edge is within the reach. A component of \a other with such edges, none of whose
 * vertices the mesh uses (a part the flatness test turned down whole, such as a
 * tube a few samples round), is added when it is closed, or when it is a surface
 * with holes (each edge in at most two of its triangles, its border edges at most
 * a quarter of its triangles) whose holes fillUndersampledHoles() all closes, with
 * those patches. Assumes such a part is not a piece of a tube cut off by holes of
 * its own: one capped at both ends would come out as a closed bead (a tube with
 * 4 samples round it does).
 * \param[in] points the vertex positions
 * \param[in] spacing per vertex its local spacing (localSpacing())
 * \param[in] other an oriented manifold mesh of the same vertices
 * \param[in,out] triangles the oriented manifold mesh; the patches are appended,
 *                 the bands taken out (the others keep their order)
 * \param[in,out] incidences the mesh's edge incidences, kept up to date
 * \param[in,out] loops the mesh's border loops; the closed ones are taken out
 * \param[in] reach the longest new edge allowed, in local spacings
 * \param[in] max_edges loops longer than this are left open
 * \param[in] band_per_edge the largest band, in triangles per loop edge; 0: only
 *            patches bounded by the loop itself
 * \param[in] true_border per vertex: on a true border, whose loop stays open and
 *            which no band reaches; empty: none
 * \param[in] join_loops only the patches that close two loops or more at once,
 *            and these may join them: a patch bounded by r cycles of the band's rim,
 *            where the band with its holes capped is r disks, may be a sphere with r
 *            holes (connected, Euler characteristic 2 - r), so the genus grows by
 *            r - 1 (a tunnel whose wall the walk left out, sampled but in no
 *            triangle, its two rims open: capped each on its own, the tunnel would
 *            close); no component of \a other is added
 */
HoleFilling
fillHolesFromMesh(const std::vector<Eigen::Vector3d>& points,
                  const std::vector<double>& spacing,
                  const std::vector<Triangle>& other,
                  std::vector<Triangle>& triangles,
                  EdgeIncidences& incidences,
                  std::vector<std::vector<int>>& loops,
                  double reach,
                  std::size_t max_edges,
                  std::size_t band_per_edge = 0,
                  const std::vector<std::uint8_t>& true_border = {},
                  bool join_loops = false);

/** \brief Close border loops round samples no triangle uses, through them: the
 * sampling goes on inside the hole, but neither the walk nor the other meshes
 * (fillHolesFromMesh()) made a surface of it (where two sheets come within a couple
 * of spacings, as two spheres nearly touching, both meshes bridge the gap; on a
 * flat face of a mesh's vertices sampled more sparsely than its surroundings).
 *
 * The loop is projected onto its best-fit plane, where it must be a simple polygon;
 * the free samples inside it (reached from the loop through the co-cone triangles)
 * within half its local spacing of the quadratic height the loop's vertices fit over
 * that plane are its candidates (at a whole spacing, spheres 2 spacings apart lent
 * one hole a sample of the other), and of those the hole's are the loop's own sheet:
 * taken from the loop inwards, each unless it stands over or under the samples
 * taken round it (off their plane by a quarter spacing, beyond the noise). CGAL's
 * constrained Delaunay triangulation of the polygon and them, in the plane, gives
 * the patch: its triangles inside the polygon, every new edge at most \a reach local
 * spacings long and new to the mesh, facing as the mesh. Assumes the hole is a
 * height field over the loop's plane (small against the surface's curvature) and
 * another sheet within half a spacing of it, if any, farther from it than the noise;
 * a hole without free samples inside is left to the others.
 * \param[in] points the vertex positions
 * \param[in] spacing per vertex its local spacing (localSpacing())
 * \param[in] cocone_triangles the co-cone triangles (VoronoiCells::triangles)
 * \param[in,out] triangles the oriented manifold mesh; the patches are appended
 * \param[in,out] incidences the mesh's edge incidences, kept up to date
 * \param[in,out] loops the mesh's border loops; the closed ones are taken out
 * \param[in] reach the longest new edge allowed, in local spacings
 * \param[in] max_edges loops longer than this are left open
 * \param[in] true_border per vertex: on a true border, whose loop stays open;
 *            empty: none
 * \param[in] noise the noise's sigma in local spacings (Result::noise_level): the
 *            spread in height two samples of one sheet may have
 */
HoleFilling
fillHolesWithInnerSamples(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<double>& spacing,
                          const std::vector<CoconeTriangle>& cocone_triangles,
                          std::vector<Triangle>& triangles,
                          EdgeIncidences& incidences,
                          std::vector<std::vector<int>>& loops,
                          double reach,
                          std::size_t max_edges,
                          const std::vector<std::uint8_t>& true_border = {},
                          double noise = 0.0);

/** \brief CGAL's advancing front reconstruction (Cohen-Steiner and Da; CGAL's
 * default plausibility: radius ratio bound 5, beta 0.52) of the points \a island
 * labels, one run per label (-1: no island), made an oriented manifold by
 * repairManifold(); the triangles index \a points.
 *
 * Where the sampling is too coarse for the co-cones (a thin part, a crease, the
 * vertex density changing several times over a few spacings), the advancing
 * front still grows triangles as large as their neighbours': a patch source for
 * fillHolesFromMesh(). One run per island of the region rather than one over it
 * all: CGAL's front seeds each of its connected components with a scan of every
 * Delaunay facet, so one run over many islands takes the time of their product. */
std::vector<Triangle>
advancingFrontMesh(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<int>& island,
                   int threads = 1);

/** \brief Close whole pieces of the mesh that the patches leave open: a piece
 * whose loops are all undersampled holes, the longest about as large as the piece
 * (the piece's vertices at most the square of its edges), is replaced by CGAL's
 * advancing front over its vertices and the free samples the co-cone triangles join
 * to them (directly or through other free samples: the samples in its holes), where
 * that is a single closed oriented manifold with the Euler characteristic of the
 * piece with its holes capped (the genus the piece says) and every edge within the
 * reach. A free sample closes one piece at most.
 *
 * The last resort after the patches: where the band round a hole is no disk (a
 * hole winding round a tube a few samples across, its rim pinched by the walk's
 * shards) no patch is bounded by the loop, but the advancing front over the whole
 * piece, which grows each triangle from its neighbours', may close it. A piece much
 * larger than its holes, however many, is left to the patches (which also bounds
 * the cost to the square of \a max_edges points); a piece with a true border is
 * never replaced (the advancing front would not close it). Vertices the advancing
 * front leaves out are left in no triangle.
 * \param[in] points the vertex positions
 * \param[in] spacing per vertex its local spacing (localSpacing())
 * \param[in] cocone_triangles the co-cone triangles (VoronoiCells::triangles)
 * \param[in,out] triangles the oriented manifold mesh
 * \param[in,out] incidences the mesh's edge incidences, kept up to date
 * \param[in,out] loops the mesh's border loops; the closed ones are taken out
 * \param[in] reach the longest edge allowed, in local spacings
 * \param[in] max_edges pieces with a loop longer than this are left open
 * \param[in] true_border per vertex: on a true border; empty: none
 * \param[in] threads threads for the repair of the advancing front's mesh
 */
HoleFilling
closePiecesWithAdvancingFront(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<double>& spacing,
                              const std::vector<CoconeTriangle>& cocone_triangles,
                              std::vector<Triangle>& triangles,
                              EdgeIncidences& incidences,
                              std::vector<std::vector<int>>& loops,
                              double reach,
                              std::size_t max_edges,
                              const std::vector<std::uint8_t>& true_border = {},
                              int threads = 1);

} // namespace cocone
} // namespace pcl
