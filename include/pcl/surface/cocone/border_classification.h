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
 * plane, P its length, shared among the points in it: m points split it into
 * about m + 1 openings, each 1 / sqrt(m + 1) as wide. A point in the hole is a
 * vertex sharing a co-cone triangle with the loop that projects into it: a point
 * no triangle uses (the sampling goes on inside), or one of the mesh's when the
 * loop is no planar opening (it winds round a tip or a thin part and its
 * projection folds over the mesh); either way the filling's own tests decide.
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
