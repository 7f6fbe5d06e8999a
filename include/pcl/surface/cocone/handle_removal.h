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

/** \brief Cut the necks no sample resolves: where the walk joined two bodies that
 * touch, or nearly, it leaves a neck of a few triangles between them (the sheets
 * closer than the spacing there, the hole filling closes round it). A neck of
 * radius r has about 2 pi r / s samples round it, as a tunnel has, so one with a
 * cycle of fewer than \a min_tunnel_samples edges is below what the sample
 * resolves. The candidates are the cycles of two breadth-first paths from a seed
 * and an edge, of 3 to \a min_tunnel_samples - 1 edges and off the borders, that
 * separate the surface (their hash sum is zero: no handle's cycle), from the seeds
 * whose ball of two rings is no disk (Euler characteristic below 1: round a vertex
 * of a surface it is a disk, where every cycle bounds); one is a neck
 * where the surface opens out on both sides and grows on as a surface (the sixth
 * ring of triangles round it holds at least twice the first's, the twelfth 1.4
 * times the sixth's: a coarse tube's rings stay alike) and goes on for 32 rings on
 * each (a body of its own, not a blister noise pinched off). Each is cut as a
 * handle is, the shortest first: the two sides become components of their own,
 * closed by least-perimeter patches of their vertices. Every vertex stays in the
 * mesh, which stays an oriented 2-manifold; its borders are unchanged.
 * \param[in] points vertex positions
 * \param[in,out] triangles oriented 2-manifold mesh
 * \param[in,out] incidences the edge incidences of \a triangles, kept up to date
 * \param[in] seeds the vertices the cycles are searched from (where the walk may
 *            have joined two bodies: round the holes the hole filling closed)
 * \param[in] min_tunnel_samples cycles of fewer edges than this are cut
 * \return the number of necks cut
 */
std::size_t
cutShortNecks(const std::vector<Eigen::Vector3d>& points,
              std::vector<Triangle>& triangles,
              EdgeIncidences& incidences,
              const std::vector<int>& seeds,
              std::size_t min_tunnel_samples = MIN_TUNNEL_SAMPLES);

} // namespace cocone
} // namespace pcl
