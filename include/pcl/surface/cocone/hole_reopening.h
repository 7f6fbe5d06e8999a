/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief The triangles a hole is reopened by: those within \a rings rings of the
 * loop \a loop (the first ring: the triangles with a corner on it; each next one:
 * those with a corner on the ring before), and the whole star of any vertex that
 * removing them would pinch (left with two fans or more), so that the triangles
 * left are an oriented manifold where the mesh was one.
 *
 * Where two sheets meet within the noise, the walk leaves a crumpled cluster round a
 * loop: fans folding over, the loop's arc and a chord bounding a handle. No patch of
 * the loop's own vertices closes it without keeping the handle; taken out with the
 * triangles round it, it leaves a wider hole whose patches (through the samples it
 * frees) can close both.
 * \param[in] triangles the mesh
 * \param[in] loop a border loop of the mesh (vertex ids)
 * \param[in] rings rings of triangles, at least 1
 * \param[in] num_vertices the number of vertices
 * \param[out] corners if given, per vertex: 1 if it is a corner of a triangle
 *             within the rings (the loop's vertices among them)
 * \return per triangle: 1 if it is within the rings
 */
std::vector<std::uint8_t>
trianglesRoundLoop(const std::vector<Triangle>& triangles,
                   const std::vector<int>& loop,
                   int rings,
                   std::size_t num_vertices,
                   std::vector<std::uint8_t>* corners = nullptr);

/** \brief The vertices \a before uses and \a after does not, inserted into the
 * surface that replaced them: each into the nearest triangle of \a after with a
 * corner in \a region, split in three round it (the orientation kept), if it lies
 * within \a reach of its local spacings of that triangle.
 *
 * The split keeps an oriented manifold and its topology (the vertex was in no
 * triangle), and the mesh goes through every sample it went through before.
 * \param[in] points vertex positions
 * \param[in] spacing per vertex its local spacing
 * \param[in] before the mesh before
 * \param[in,out] after the mesh after, with the vertices inserted
 * \param[in] region per vertex: round the change
 * \param[in] reach the farthest a vertex is inserted from, in its local spacings
 * \return whether every vertex left out was inserted (if not, \a after holds those
 *         that were)
 */
bool
insertLeftOut(const std::vector<Eigen::Vector3d>& points,
              const std::vector<double>& spacing,
              const std::vector<Triangle>& before,
              std::vector<Triangle>& after,
              const std::vector<std::uint8_t>& region,
              double reach);

} // namespace cocone
} // namespace pcl
