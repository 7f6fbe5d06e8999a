/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/triangulation.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/spatial_sort.h>

#include "delaunay.h"
#include "points.h"
#include <tbb/scalable_allocator.h>
#include <tbb/task_arena.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <cmath>
#include <cstdint>
#include <exception>
#include <iterator>
#include <limits>
#include <memory>
#include <new>
#include <numeric>
#include <thread>
#include <type_traits>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

using detail::isFinite;
using detail::Kernel;
using detail::lexLess;

Eigen::Vector3d
toEigen(const CGAL::Exact_predicates_exact_constructions_kernel::Point_3& p)
{
  return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
}

} // namespace

UniquePoints
makeUniquePoints(const std::vector<Eigen::Vector3d>& input)
{
  UniquePoints out;
  out.vertex_of_input.assign(input.size(), -1);
  std::vector<int> finite;
  finite.reserve(input.size());
  for (std::size_t i = 0; i < input.size(); ++i)
    if (isFinite(input[i]))
      finite.push_back(static_cast<int>(i));
  if (finite.empty())
    return out;

  // Number the vertices along a Morton (Z-order) curve, ties in lexicographic order:
  // neighbours in space get nearby ids, which keeps the per-cell passes cache
  // friendly, and the numbering still depends only on the point set. Duplicates
  // share a code and sort next to each other: one sort does both.
  Eigen::Vector3d lo = input[finite.front()], hi = lo;
  for (const int i : finite) {
    lo = lo.cwiseMin(input[i]);
    hi = hi.cwiseMax(input[i]);
  }
  const double extent =
      std::max((hi - lo).maxCoeff(), std::numeric_limits<double>::min());
  const auto spread = [](std::uint64_t v) { // 21 bits -> every third bit
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  std::vector<std::pair<std::uint64_t, int>> keys;
  keys.reserve(finite.size());
  for (const int i : finite) {
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double t = (input[i][k] - lo[k]) / extent * 2097151.0;
      code |= spread(static_cast<std::uint64_t>(std::clamp(t, 0.0, 2097151.0))) << k;
    }
    keys.emplace_back(code, i);
  }
  std::vector<int>().swap(finite);
  std::sort(keys.begin(), keys.end(), [&](const auto& a, const auto& b) {
    if (a.first != b.first)
      return a.first < b.first;
    return lexLess(input[a.second], input[b.second]) ||
           (input[a.second] == input[b.second] && a.second < b.second);
  });
  for (const auto& key : keys) {
    const Eigen::Vector3d& p = input[key.second];
    if (out.points.empty() || out.points.back() != p)
      out.points.push_back(p);
    out.vertex_of_input[key.second] = static_cast<int>(out.points.size()) - 1;
  }
  return out;
}

Eigen::Vector3d
tetrahedronCircumcenter(const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c,
                        const Eigen::Vector3d& d)
{
  const Eigen::Vector3d u = b - a, v = c - a, w = d - a;
  const Eigen::Vector3d vw = v.cross(w), wu = w.cross(u), uv = u.cross(v);
  const double den = 2.0 * u.dot(vw);
  const Eigen::Vector3d num =
      u.squaredNorm() * vw + v.squaredNorm() * wu + w.squaredNorm() * uv;
  if (den != 0.0) {
    Eigen::Vector3d cc = a + num / den;
    if (isFinite(cc))
      return cc;
  }
  // The cell is flat to rounding but not exactly (CGAL's predicates guarantee a
  // positive volume): construct exactly, then round.
  using EK = CGAL::Exact_predicates_exact_constructions_kernel;
  const auto p = [](const Eigen::Vector3d& x) { return EK::Point_3(x[0], x[1], x[2]); };
  return toEigen(CGAL::circumcenter(p(a), p(b), p(c), p(d)));
}

Eigen::Vector3d
triangleCircumcenter(const Eigen::Vector3d& a,
                     const Eigen::Vector3d& b,
                     const Eigen::Vector3d& c)
{
  const Eigen::Vector3d u = b - a, v = c - a;
  const Eigen::Vector3d n = u.cross(v);
  const double den = 2.0 * n.squaredNorm();
  if (den != 0.0) {
    Eigen::Vector3d cc = a + (u.squaredNorm() * v - v.squaredNorm() * u).cross(n) / den;
    if (isFinite(cc))
      return cc;
  }
  using EK = CGAL::Exact_predicates_exact_constructions_kernel;
  const auto p = [](const Eigen::Vector3d& x) { return EK::Point_3(x[0], x[1], x[2]); };
  return toEigen(CGAL::circumcenter(p(a), p(b), p(c)));
}

namespace {

/** Hand glibc's free memory back to the system. What the builder thread and TBB's
 * workers allocated lies in malloc arenas of their own, which glibc keeps mapped
 * after it is freed (a small block left on top of a heap keeps the rest too). */
void
trimMallocArenas()
{
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

/** Number of the cell's vertices: 4, or 3 when the triangulation is planar. */
template <typename Delaunay>
int
cornersOf(const Delaunay& dt)
{
  return dt.dimension() == 3 ? 4 : 3;
}

template <typename Delaunay>
bool
isFiniteCell(const Delaunay& dt, typename Delaunay::Cell_handle c)
{
  for (int i = 0, corners = cornersOf(dt); i < corners; ++i)
    if (dt.is_infinite(c->vertex(i)))
      return false;
  return true;
}

/** The circumcenter of a finite cell, from its vertices in ascending id order (a
 * canonical order: the result is bitwise reproducible). */
template <typename Delaunay>
Eigen::Vector3d
circumcenterOf(const Delaunay& dt, typename Delaunay::Cell_handle c)
{
  // The points are read from CGAL's vertices, which are loaded for their ids
  // anyway; they hold the same recentred coordinates as Triangulation::points.
  std::array<std::pair<int, const Kernel::Point_3*>, 4> s;
  const int corners = cornersOf(dt);
  for (int i = 0; i < corners; ++i)
    s[i] = {c->vertex(i)->info(), &c->vertex(i)->point()};
  detail::sortCorners(s, corners, [](const auto& corner) { return corner.first; });
  const auto p = [&](int k) {
    const Kernel::Point_3& q = *s[k].second;
    return Eigen::Vector3d(q.x(), q.y(), q.z());
  };
  return corners == 4 ? tetrahedronCircumcenter(p(0), p(1), p(2), p(3))
                      : triangleCircumcenter(p(0), p(1), p(2));
}

/** Fill structure.cells: the finite cells by their smallest vertex id, in buckets
 * of 64 ids (a few hundred cells: a counting sort with few write positions; inside
 * a bucket the container's order, which does not matter); and structure.hull. */
template <typename Built>
void
orderCells(Built& structure, std::size_t number_of_vertices)
{
  const auto& dt = structure.dt;
  const int corners = cornersOf(dt);
  std::vector<int> key;
  key.reserve(dt.tds().number_of_cells());
  constexpr int BUCKET_BITS = 6;
  std::vector<std::uint32_t> start((number_of_vertices >> BUCKET_BITS) + 2, 0);
  for (auto c = dt.tds().raw_cells_begin(); c != dt.tds().raw_cells_end(); ++c) {
    int lowest = -1;
    if (isFiniteCell(dt, c)) {
      lowest = c->vertex(0)->info();
      for (int i = 1; i < corners; ++i)
        lowest = std::min(lowest, c->vertex(i)->info());
      lowest >>= BUCKET_BITS;
      ++start[lowest + 1];
    }
    else if (corners == 4)
      structure.hull.push_back(c);
    key.push_back(lowest);
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  structure.cells.resize(start.back());
  auto k = key.begin();
  for (auto c = dt.tds().raw_cells_begin(); c != dt.tds().raw_cells_end(); ++c, ++k)
    if (*k >= 0)
      structure.cells[start[*k]++] = c;
}

/** Run body(cell, thread) over the finite cells, split in equal runs per thread. */
template <typename Built, typename Body>
void
splitCells(const Built& structure, int threads, const Body& body)
{
  using Cell_handle = typename decltype(Built::dt)::Cell_handle;
  constexpr std::size_t AHEAD = 8;
  const int corners = cornersOf(structure.dt);
  // An exception must not leave a parallel region: it is caught in the thread and
  // thrown again after the region (only std::bad_alloc can occur here).
  bool failed = false;
#pragma omp parallel num_threads(threads)
  {
#ifdef _OPENMP
    const int thread = omp_get_thread_num(), team = omp_get_num_threads();
#else
    const int thread = 0, team = 1;
#endif
    const std::size_t count = structure.cells.size();
    const std::size_t begin = count * thread / team, end = count * (thread + 1) / team;
    try {
      for (std::size_t k = begin; k < end; ++k) {
        // The cells lie scattered in memory: fetch ahead, the cell first, then its
        // vertices once the cell has arrived; the body gets a cell further on still
        // whose vertices have arrived, to fetch its own records.
        if (k + 3 * AHEAD < end) {
          const char* ahead =
              reinterpret_cast<const char*>(&*structure.cells[k + 3 * AHEAD]);
          __builtin_prefetch(ahead);
          __builtin_prefetch(ahead + 64);
        }
        if (k + 2 * AHEAD < end) {
          const auto c = structure.cells[k + 2 * AHEAD];
          for (int i = 0; i < corners; ++i)
            __builtin_prefetch(&*c->vertex(i));
        }
        body(structure.cells[k],
             k + AHEAD < end ? structure.cells[k + AHEAD] : Cell_handle(),
             thread);
      }
    }
    catch (const std::bad_alloc&) {
      __atomic_store_n(&failed, true, __ATOMIC_RELAXED);
    }
  }
  if (failed)
    throw std::bad_alloc();
}

} // namespace

Triangulation
triangulate(std::vector<Eigen::Vector3d> points, unsigned int num_threads)
{
  Triangulation out;
  if (points.empty())
    return out;

  // Recentre in double so that georeferenced coordinates keep their precision. The
  // origin is an input point (the lexicographically smallest): differences of float
  // coordinates are exact in double, so a translated cloud gives the very same
  // recentred points, and the same triangulation even where it is degenerate.
  out.offset = *std::min_element(points.begin(), points.end(), lexLess);
  for (auto& p : points)
    p -= out.offset;
  out.points = std::move(points);

  std::vector<std::pair<Kernel::Point_3, int>> sites;
  sites.reserve(out.points.size());
  for (std::size_t i = 0; i < out.points.size(); ++i) {
    const auto& p = out.points[i];
    sites.emplace_back(Kernel::Point_3(p.x(), p.y(), p.z()), static_cast<int>(i));
  }
  out.structure = std::make_shared<detail::DelaunayStructure>();
  const int threads = resolveThreads(num_threads);
  // Concurrent insertion pays off only on large clouds; the grid of 100^3 locks
  // was the fastest measured on a million points (10^3: blocked most of the time).
  // One thread builds CGAL's sequential structure, which is faster so.
  const bool concurrent = threads > 1 && sites.size() >= 100000;
  // One thread: CGAL's spatial sort (Hilbert order with random rounds, seeded) and
  // insertion with the previous vertex as the hint, what range insertion does minus
  // its indirection through an index array. Several: CGAL's range insertion, which
  // sorts in parallel itself. CGAL's symbolic perturbation makes the triangulation
  // of degenerate (co-spherical) input independent of the order.
  if (concurrent)
    out.structure->parallel =
        std::make_unique<detail::Built<detail::ParallelDelaunay>>();
  else {
    CGAL::spatial_sort(
        sites.begin(),
        sites.end(),
        CGAL::Spatial_sort_traits_adapter_3<
            Kernel,
            CGAL::First_of_pair_property_map<std::pair<Kernel::Point_3, int>>>());
    out.structure->sequential =
        std::make_unique<detail::Built<detail::SequentialDelaunay>>();
  }
  // CGAL's insertion keeps scratch tables in thread-local storage that an exception
  // (std::bad_alloc) leaves dirty, which breaks every later insertion in the same
  // thread. Building in a thread of its own confines that state to this call.
  std::exception_ptr failure;
  std::thread builder([&]() {
    try {
      if (concurrent) {
        auto& dt = out.structure->parallel->dt;
        CGAL::Bbox_3 box;
        for (const auto& site : sites)
          box += site.first.bbox();
        detail::ParallelDelaunay::Lock_data_structure locks(box, 100);
        dt.set_lock_data_structure(&locks);
        tbb::task_arena arena(threads);
        arena.execute([&]() { dt.insert(sites.begin(), sites.end()); });
        dt.set_lock_data_structure(nullptr);
      }
      else {
        auto& dt = out.structure->sequential->dt;
        detail::SequentialDelaunay::Vertex_handle hint;
        for (const auto& site : sites) {
          hint = dt.insert(site.first, hint);
          hint->info() = site.second;
        }
      }
    }
    catch (...) {
      failure = std::current_exception();
    }
  });
  builder.join();
  if (failure)
    std::rethrow_exception(failure);
  std::vector<std::pair<Kernel::Point_3, int>>().swap(sites);
  // Before the passes add their arrays on top (measured peak on a million saddle
  // points: 1005 -> 962 MB with two threads, 945 -> 928 MB with one).
  trimMallocArenas();
  out.structure->visit(
      [&](const auto& built) { out.dimension = built.dt.dimension(); });
  if (out.dimension < 2) {
    out.release();
    return out;
  }

  out.structure->visit([&](auto& built) {
    orderCells(built, out.points.size());
    out.number_of_cells = built.cells.size();
  });
  return out;
}

void
Triangulation::release()
{
  if (!structure)
    return;
  const bool concurrent = structure->parallel != nullptr;
  structure.reset();
  // The concurrent structure's cells come from TBB's allocator, which keeps freed
  // blocks for reuse: hand them back. (Only then: TBB's allocator must not be
  // asked before it has served anything.)
  if (concurrent)
    scalable_allocation_command(TBBMALLOC_CLEAN_ALL_BUFFERS, nullptr);
  // And glibc's (measured: peak 1.41 GB instead of 0.96 GB on a million saddle
  // points, two threads).
  trimMallocArenas();
}

int
CellView::outwardSide(int i) const
{
  // The cell lies on the side of its own vertex v[i].
  return -detail::oppositeFacet(v, i).parity;
}

int
resolveThreads(unsigned int requested)
{
#ifdef _OPENMP
  const int available = std::max(1, omp_get_num_procs());
#else
  const int available = 1;
#endif
  return requested == 0 ? available : static_cast<int>(requested);
}

namespace detail {

void
visitHullFacets(const Triangulation& triangulation,
                HullFacetVisitor visitor,
                void* context)
{
  if (!triangulation.structure || triangulation.dimension != 3)
    return;
  triangulation.structure->visit([&](const auto& built) {
    const auto& dt = built.dt;
    const auto& hull = built.hull;
    constexpr std::size_t AHEAD = 8;
    for (std::size_t k = 0; k < hull.size(); ++k) {
      // The cells lie in the container's order, their vertices scattered.
      if (k + 2 * AHEAD < hull.size())
        __builtin_prefetch(&*hull[k + 2 * AHEAD]);
      if (k + AHEAD < hull.size())
        for (int i = 0; i < 4; ++i)
          __builtin_prefetch(&*hull[k + AHEAD]->vertex(i));
      // The finite facet of an infinite cell, which CGAL orients as if the
      // infinite vertex were a point outside the hull.
      const auto c = hull[k];
      const int infinite = c->index(dt.infinite_vertex());
      std::array<int, 4> ids;
      for (int i = 0; i < 4; ++i)
        ids[i] = i == infinite ? -1 : c->vertex(i)->info();
      const auto opposite = detail::oppositeFacet(ids, infinite);
      visitor(context, HullFacet{opposite.ids, opposite.parity});
    }
  });
}

void
visitCells(const Triangulation& triangulation,
           unsigned int data,
           int threads,
           CellVisitor visitor,
           void* context)
{
  if (!triangulation.structure)
    return;
  triangulation.structure->visit([&](const auto& built) {
    const auto& dt = built.dt;
    using Cell_handle = typename std::remove_reference_t<decltype(dt)>::Cell_handle;
    const int corners = cornersOf(dt);
    // A small direct-mapped cache of circumcenters per thread: the cells across a
    // cell's facets were mostly created, and are visited, close to it, and computing
    // a circumcenter again costs mainly the cache misses of loading that cell.
    constexpr int CACHE_BITS = 14;
    struct Entry {
      const void* cell = nullptr;
      Eigen::Vector3d circumcenter;
    };
    // Without the neighbours every cell is asked for once: no cache.
    const bool caching = (data & CellView::NEIGHBORS) == CellView::NEIGHBORS;
    std::vector<std::vector<Entry>> caches(
        threads, std::vector<Entry>(caching ? std::size_t(1) << CACHE_BITS : 0));
    const auto circumcenter = [&](std::vector<Entry>& cache, Cell_handle c) {
      if (!caching)
        return circumcenterOf(dt, c);
      const auto key = reinterpret_cast<std::uintptr_t>(&*c);
      Entry& e = cache[(key * 0x9e3779b97f4a7c15ULL) >> (64 - CACHE_BITS)];
      if (e.cell != &*c) {
        e.cell = &*c;
        e.circumcenter = circumcenterOf(dt, c);
      }
      return e.circumcenter;
    };
    splitCells(built, threads, [&](Cell_handle c, Cell_handle ahead, int thread) {
      auto& cache = caches[thread];
      CellView view;
      view.corners = corners;
      view.v = {-1, -1, -1, -1};
      view.ahead = {-1, -1, -1, -1};
      for (int i = 0; i < corners; ++i) {
        view.v[i] = c->vertex(i)->info();
        if (ahead != Cell_handle())
          view.ahead[i] = ahead->vertex(i)->info();
      }
      if ((data & CellView::NEIGHBORS) == CellView::NEIGHBORS && ahead != Cell_handle())
        for (int i = 0; i < corners; ++i) {
          const char* other = reinterpret_cast<const char*>(&*ahead->neighbor(i));
          __builtin_prefetch(other);
          __builtin_prefetch(other + 64);
        }
      if (data & CellView::CIRCUMCENTER)
        view.circumcenter = circumcenter(cache, c);
      view.edges = 0;
      // The neighbours about an edge lie across the facets opposite the other two
      // vertices; only their addresses are compared, the cells are not loaded.
      for (int e = 0; (data & CellView::EDGES) && corners == 4 && e < 6; ++e) {
        const auto& across = CellView::EDGE_ENDS[5 - e];
        if (&*c < &*c->neighbor(across[0]) && &*c < &*c->neighbor(across[1]))
          view.edges |= static_cast<std::uint8_t>(1u << e);
      }
      for (int i = 0; (data & CellView::FACETS) && i < 4; ++i) {
        if (i >= corners) {
          view.facet[i] = FacetRole::HULL;
          continue;
        }
        const auto other = c->neighbor(i);
        // Each interior facet once: from the cell at the higher address
        // (which one does not matter to the visitors; both are visited
        // close together, so the other's circumcenter is mostly cached).
        if (!isFiniteCell(dt, other))
          view.facet[i] = FacetRole::HULL;
        else if (&*other > &*c)
          view.facet[i] = FacetRole::SHARED;
        else {
          view.facet[i] = FacetRole::OWN;
          if ((data & CellView::NEIGHBORS) == CellView::NEIGHBORS)
            view.neighbor_circumcenter[i] = circumcenter(cache, other);
        }
      }
      visitor(context, view, thread);
    });
  });
}

} // namespace detail

} // namespace cocone
} // namespace pcl
