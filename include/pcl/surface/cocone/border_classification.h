/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/voronoi_cell.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief Which border loops are true borders, where the sampling stops, and so
 * are never closed by the hole filling.
 *
 * An undersampled hole has samples all round it that continue the surface at
 * about the density the hole would need: it is no wider than a couple of the
 * triangles round it (a sample or two missing, or a part whose triangles the
 * flatness test turned down), or the sampling goes on inside it. A hole wider
 * than \a max_width times the triangles at its rim (the diameter of their median
 * circumcircle) is where the sampler stopped: a scanner's dropout, a cut-out of
 * the surface.
 *
 * The hole's width is 4 A / P of the loop (the diameter of a round hole, twice
 * the width of a slit), A the area of its projection onto the loop's best-fit
 * plane, P its length. With points in the hole, it is at most the diameter of the
 * widest disk they and the loop leave empty there (the largest Delaunay circle
 * centred in the projected hole): the opening the sampling really has. The points
 * in the hole are those reached from the loop through co-cone triangles, each
 * projecting into it: points no triangle uses (the sampling goes on inside), an
 * island of the mesh that a gap rings, or the mesh's other side when the loop is
 * no planar opening (it winds round a tip or a thin part and its projection folds
 * over the mesh); either way the filling's own tests decide. Measured on the
 * range scans: an occlusion gap ringing an island of the mesh read as many narrow
 * openings under the earlier estimate (4 A / P shared among the m points, 1 /
 * sqrt(m + 1) each) and was closed; on the closed meshes and the synthetic
 * surfaces no loop's class changed.
 *
 * A loop round the whole of its piece of the mesh (a strip or flake a few samples
 * across, whose other vertices lie over the loop) is a true border whatever its
 * width: the outline of a sheet cut off from the rest (an ear of a single view),
 * which a patch would double into a closed pillow of no volume.
 *
 * Assumes the sampling round a hole is locally even: a flat face that a mesh's
 * vertices sample only along its outline, wider than \a max_width of its rim's
 * triangles, reads as a true border, and so does a hole that noise tears where
 * registered views overlap if it is that wide (measured up to about 2.4).
 * \param[in] points the vertex positions
 * \param[in] triangles the mesh after the walk and the repair
 * \param[in] loops its border loops (boundaryLoops())
 * \param[in] cocone_triangles the co-cone triangles (VoronoiCells::triangles)
 * \param[in] max_width the widest undersampled hole, in rim triangle diameters;
 *            0 or less: no loop is a true border
 * \param[in] max_edges loops longer than this are not looked at (true borders)
 * \return per loop: 1 if it is a true border
 */
std::vector<std::uint8_t>
classifyBorderLoops(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Triangle>& triangles,
                    const std::vector<std::vector<int>>& loops,
                    const std::vector<CoconeTriangle>& cocone_triangles,
                    double max_width,
                    std::size_t max_edges);

} // namespace cocone
} // namespace pcl
