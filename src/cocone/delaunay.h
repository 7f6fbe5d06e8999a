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

#include <memory>
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
template <typename ConcurrencyTag>
using DelaunayOf = CGAL::Delaunay_triangulation_3<
    Kernel,
    CGAL::Triangulation_data_structure_3<VertexBase, CellBase, ConcurrencyTag>>;
/** Built by one thread: CGAL's sequential structure, which builds fastest so. */
using SequentialDelaunay = DelaunayOf<CGAL::Sequential_tag>;
/** Built by several threads (points inserted concurrently, cells locked). */
using ParallelDelaunay = DelaunayOf<CGAL::Parallel_tag>;

/** A triangulation and the order in which the passes visit its cells. */
template <typename Delaunay>
struct Built {
  Delaunay dt;
  /** The finite cells by smallest vertex id. CGAL's container reuses freed slots,
   * so its order scatters neighbouring cells; in this order the cells across a
   * cell's facets and the per-vertex records of its vertices are mostly still in
   * cache. */
  std::vector<typename Delaunay::Cell_handle> cells;
  /** The infinite cells (dimension 3), one per hull facet, in the container's
   * order: collected while ordering the cells, so the hull is read without a walk
   * about the infinite vertex. */
  std::vector<typename Delaunay::Cell_handle> hull;
};

/** One of the two, as the thread count chose. */
struct DelaunayStructure {
  std::unique_ptr<Built<SequentialDelaunay>> sequential;
  std::unique_ptr<Built<ParallelDelaunay>> parallel;

  /** Call f on the one that is built. */
  template <typename F>
  void
  visit(F&& f) const
  {
    if (sequential)
      f(static_cast<const Built<SequentialDelaunay>&>(*sequential));
    else
      f(static_cast<const Built<ParallelDelaunay>&>(*parallel));
  }

  template <typename F>
  void
  visit(F&& f)
  {
    if (sequential)
      f(*sequential);
    else
      f(*parallel);
  }
};

} // namespace detail
} // namespace cocone
} // namespace pcl
