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

/** \brief Fewest samples round a tunnel that the sample can resolve: a tube of
 * radius r sampled with spacing s has about 2 pi r / s samples round it, and an
 * epsilon-sample (s <= 2 epsilon r at the tube) with epsilon below about 0.5, the
 * coarsest on which the Co-cone's decisions hold in practice, has at least six. */
constexpr std::size_t MIN_TUNNEL_SAMPLES = 6;

/** \brief Cut the handles no sampled tunnel explains (topological noise, Guskov
 * and Wood 2001): those with a cycle of fewer than \a min_tunnel_samples mesh edges
 * that does not separate the surface, and whose two sides meet again within a
 * small ball round it (the handle is short both ways). Where the walk meets the
 * same surface twice within the noise, or a couple of spacings apart, it can close
 * a tunnel no sample lies round; the mesh then has handles the object has not. A
 * true handle with a short cycle (a coarse tube, a ring) is long the other way.
 *
 * The cycles are found by their homology: a tree-cotree decomposition of the mesh
 * (its border loops capped) gives each edge the generators whose dual loops cross
 * it, as a 64-bit hash, and the short cycles through each vertex (two breadth-first
 * paths and an edge) whose sum is not zero, off the borders, are the candidates.
 * Each is checked exactly before it is cut (its two sides meet without crossing
 * it), the shortest first: the triangles along one side of the cycle are taken out
 * and the two loops this opens are closed by least-perimeter patches of their own
 * vertices. A cut needing a new edge the mesh has or a degenerate patch triangle,
 * or touching a border or another cut of its round, is not made. Every vertex
 * stays in the mesh, which stays an oriented 2-manifold; its borders are unchanged.
 *
 * \param[in] points vertex positions (for the cycles' lengths and the patches)
 * \param[in,out] triangles oriented 2-manifold mesh
 * \param[in,out] incidences the edge incidences of \a triangles, kept up to date
 * \param[in] min_tunnel_samples cycles of fewer edges than this are cut
 * \param[in] threads threads for the cycle search
 * \return the number of handles cut
 */
std::size_t
cutShortHandles(const std::vector<Eigen::Vector3d>& points,
                std::vector<Triangle>& triangles,
                EdgeIncidences& incidences,
                std::size_t min_tunnel_samples = MIN_TUNNEL_SAMPLES,
                int threads = 1);

} // namespace cocone
} // namespace pcl
