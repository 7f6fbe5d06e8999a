/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * CGAL's Delaunay triangulation as stage 1 keeps it (not installed).
 */

#pragma once

#include <pcl/surface/cocone/triangulation.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
/** Vertex info: the vertex id. */
using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>;
/** Cells as CGAL's default: the circumcenters are recomputed where a pass needs
 * them, which is cheaper than the memory to keep them (about 19 cells per point). */
using CellBase = CGAL::Delaunay_triangulation_cell_base_3<Kernel>;
/** The concurrent structure, also when built sequentially: it builds as fast with
 * one thread and takes less memory (TBB's allocator). */
using Tds =
    CGAL::Triangulation_data_structure_3<VertexBase, CellBase, CGAL::Parallel_tag>;
using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, Tds>;

struct DelaunayStructure {
  Delaunay dt;
  /** The finite cells in the order the passes visit them: by smallest vertex id.
   * CGAL's container reuses freed slots, so its order scatters neighbouring cells;
   * in this order the cells across a cell's facets and the per-vertex records of
   * its vertices are mostly still in cache. */
  std::vector<Delaunay::Cell_handle> cells;
};

} // namespace detail
} // namespace cocone
} // namespace pcl
