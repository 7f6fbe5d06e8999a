/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/triangulation.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include "delaunay.h"
#include "edge_sort.h"
#include "parallel.h"
#include "points.h"
#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#ifdef __linux__
#include <sys/mman.h>
#include <unistd.h>
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
#include <unordered_map>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

using detail::isFinite;
using detail::Kernel;
using detail::lexLess;

/** Below this many points makeUniquePoints() sorts by comparison rather than by
 * radix (measured, one thread, warm: 400 points 0.01 against 0.35 ms, 10,000 2.3
 * against 3.1, 30,000 7.3 against 6.1; cold, in a process's first run, the radix
 * sort's counters cost 4 ms more, their pages faulted in). */
constexpr std::size_t SMALL_SORT = std::size_t(1) << 14;

Eigen::Vector3d
toEigen(const CGAL::Exact_predicates_exact_constructions_kernel::Point_3& p)
{
  return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
}

} // namespace

UniquePoints
makeUniquePoints(const std::vector<Eigen::Vector3d>& input, int threads)
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
  std::vector<std::pair<std::uint64_t, int>> keys(finite.size());
  detail::forEachRange(
      finite.size(),
      detail::partsFor(finite.size(), threads),
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t j = begin; j < end; ++j) {
          const int i = finite[j];
          std::uint64_t code = 0;
          for (int k = 0; k < 3; ++k) {
            const double t = (input[i][k] - lo[k]) / extent * 2097151.0;
            code |= spread(static_cast<std::uint64_t>(std::clamp(t, 0.0, 2097151.0)))
                    << k;
          }
          keys[j] = {code, i};
        }
      });
  std::vector<int>().swap(finite);
  // By code, the input order kept within a code; the few runs of one code are then
  // ordered by position. A large cloud takes a radix sort, one stable counting sort
  // a 16-bit digit; a small one a comparison sort of (code, index), the same order
  // without the digits' four passes over 65,536 counters (SMALL_SORT).
  if (keys.size() < SMALL_SORT)
    std::sort(keys.begin(), keys.end());
  else {
    constexpr int DIGIT = 16;
    std::vector<std::pair<std::uint64_t, int>> buffer(keys.size());
    for (int shift = 0; shift < 64; shift += DIGIT) {
      detail::countingSort(
          keys.size(),
          std::size_t(1) << DIGIT,
          threads,
          [&](std::size_t j) {
            return static_cast<std::size_t>((keys[j].first >> shift) &
                                            ((1u << DIGIT) - 1));
          },
          [&](std::size_t j, std::uint32_t place) { buffer[place] = keys[j]; });
      keys.swap(buffer);
    }
  }
  for (std::size_t i = 0, j = 0; i < keys.size(); i = j) {
    for (j = i + 1; j < keys.size() && keys[j].first == keys[i].first;)
      ++j;
    if (j - i > 1)
      std::sort(keys.begin() + i, keys.begin() + j, [&](const auto& a, const auto& b) {
        return lexLess(input[a.second], input[b.second]) ||
               (input[a.second] == input[b.second] && a.second < b.second);
      });
  }
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

/** Hand glibc's free memory back to the system: glibc keeps freed blocks mapped (a
 * small block left on top of a heap keeps the rest too), and what CGAL's planar
 * triangulation allocated lies in the malloc arena of the thread that built it.
 * Not under AddressSanitizer: its allocator replaces glibc's, whose arenas are then
 * never set up, and malloc_trim() from two threads at once crashed there. */
void
trimMallocArenas()
{
#if defined(__GLIBC__) && !defined(COCONE_UNDER_ASAN)
  malloc_trim(0);
#endif
}

/** The number of built cells whose memory holds the circumcenters of \a finite
 * cells (a circumcenter takes less than a cell, so never more than were built). */
std::size_t
circumcenterCells(std::size_t finite)
{
  return (finite * sizeof(Eigen::Vector3d) + sizeof(detail::BuildCell) - 1) /
         sizeof(detail::BuildCell);
}

/** Hand the pages of \a cells past the first \a keep cells back to the system (their
 * contents are not needed any more); the address space stays. */
void
releaseTail(detail::BuildCells& cells, std::size_t keep)
{
#ifdef __linux__
  // Whole pages only, in bytes from the start of the array.
  char* const base = reinterpret_cast<char*>(cells.data());
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  const std::size_t skew = reinterpret_cast<std::uintptr_t>(base) % page;
  const std::size_t from = std::min(keep, cells.size()) * sizeof(detail::BuildCell);
  const std::size_t to = cells.size() * sizeof(detail::BuildCell);
  const std::size_t first = (from + skew + page - 1) / page * page - skew;
  const std::size_t last = (to + skew) / page * page;
  if (last > skew && first < last - skew)
    madvise(base + first, last - skew - first, MADV_DONTNEED);
#else
  (void)cells;
  (void)keep;
#endif
}

/** CGAL's triangulation, for coplanar points only (dimension 2: its cells are the
 * triangles of the planar Delaunay triangulation). */
using PlanarDelaunay = CGAL::Delaunay_triangulation_3<
    Kernel,
    CGAL::Triangulation_data_structure_3<
        CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>,
        CGAL::Delaunay_triangulation_cell_base_3<Kernel>>>;

/** The planar triangulation of coplanar points, as cells of three corners. */
void
triangulatePlanar(const std::vector<Eigen::Vector3d>& points, detail::BuildCells& cells)
{
  std::vector<std::pair<Kernel::Point_3, int>> sites;
  sites.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    sites.emplace_back(Kernel::Point_3(points[i].x(), points[i].y(), points[i].z()),
                       static_cast<int>(i));
  const PlanarDelaunay dt(sites.begin(), sites.end());
  std::unordered_map<const void*, std::uint32_t> number;
  for (auto c = dt.tds().raw_cells_begin(); c != dt.tds().raw_cells_end(); ++c)
    number.emplace(&*c, static_cast<std::uint32_t>(number.size()));
  cells.resize(number.size());
  for (auto c = dt.tds().raw_cells_begin(); c != dt.tds().raw_cells_end(); ++c) {
    detail::BuildCell& cell = cells[number.at(&*c)];
    cell.v = {-1, -1, -1, -1};
    cell.n = {0, 0, 0, 0};
    for (int i = 0; i < 3; ++i) {
      cell.v[i] = dt.is_infinite(c->vertex(i)) ? detail::BuildCell::INFINITE
                                               : c->vertex(i)->info();
      cell.n[i] = 4 * number.at(&*c->neighbor(i));
    }
  }
}

/** Keep the cells in the order the passes visit them: the finite cells by smallest
 * vertex id, in buckets of 64 ids (a counting sort with few write positions; inside
 * a bucket the builder's order, which does not matter), then the infinite ones. In
 * this order the cells across a cell's facets and the per-vertex records of its
 * vertices are mostly in cache when a pass needs them. */
void
orderCells(const detail::BuildCells& built,
           int corners,
           std::size_t number_of_vertices,
           int threads,
           detail::DelaunayStructure& out)
{
  constexpr int BUCKET_BITS = 6;
  constexpr int FREE = -1;
  const int infinite = static_cast<int>(number_of_vertices >> BUCKET_BITS) + 1;
  // A counting sort by bucket, each thread counting a range of the built cells: the
  // places follow bucket by bucket, then thread by thread, the builder's order.
  std::vector<std::vector<std::uint32_t>> start(threads);
  // Per built cell its bucket, then its place.
  std::vector<int> slot(built.size());
  detail::forEachRange(
      built.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
        start[t].assign(infinite + 1, 0);
        for (std::size_t c = begin; c < end; ++c) {
          const auto& v = built[c].v;
          slot[c] = FREE;
          if (v[0] == detail::BuildCell::FREE)
            continue;
          int lowest = v[0];
          for (int i = 1; i < corners; ++i)
            lowest = (lowest < 0 || v[i] < 0) ? -1 : std::min(lowest, v[i]);
          slot[c] = lowest < 0 ? infinite : lowest >> BUCKET_BITS;
          ++start[t][slot[c]];
        }
      });
  std::uint32_t total = 0;
  for (int b = 0; b <= infinite; ++b) {
    if (b == infinite)
      out.finite = total;
    for (auto& count : start) {
      const std::uint32_t here = count[b];
      count[b] = total;
      total += here;
    }
  }
  // Sized without being written: the pages are first touched by the threads below.
  out.vertices.resize(total);
  out.neighbors.resize(total);
  detail::forEachRange(
      built.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
        for (std::size_t c = begin; c < end; ++c)
          if (slot[c] != FREE)
            slot[c] = static_cast<int>(start[t][slot[c]]++);
      });
  detail::forEachRange(
      built.size(), threads, [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t c = begin; c < end; ++c) {
          if (slot[c] == FREE)
            continue;
          auto& v = out.vertices[slot[c]];
          auto& n = out.neighbors[slot[c]];
          v = built[c].v;
          for (int i = 0; i < 4; ++i)
            n[i] = i < corners ? slot[built[c].n[i] >> 2] : -1;
        }
      });
}

/** Number of the cells' corners: 4, or 3 when the triangulation is planar. */
int
cornersOf(const Triangulation& dt)
{
  return dt.dimension == 3 ? 4 : 3;
}

/** Room for the circumcenters of the finite cells, in the built cells' memory
 * (trivial objects: reusing it ends their lifetime). */
Eigen::Vector3d*
placeCircumcenters(detail::DelaunayStructure& s)
{
  s.build.clear();
  s.build.reserve(circumcenterCells(s.finite));
  auto* circumcenters = reinterpret_cast<Eigen::Vector3d*>(s.build.data());
  std::uninitialized_default_construct_n(circumcenters, s.finite);
  return circumcenters;
}

/** The circumcenter of finite cell k, from its vertices in ascending id order (a
 * canonical order: the result is bitwise reproducible). */
Eigen::Vector3d
circumcenterOf(const Triangulation& dt, int corners, std::size_t k)
{
  std::array<int, 4> v = dt.structure->vertices[k];
  detail::sortCorners(v, corners, [](int id) { return id; });
  const auto& P = dt.points;
  return corners == 4 ? tetrahedronCircumcenter(P[v[0]], P[v[1]], P[v[2]], P[v[3]])
                      : triangleCircumcenter(P[v[0]], P[v[1]], P[v[2]]);
}

/** The circumcenters of the finite cells, for a pass that reads its neighbours'. */
void
computeCircumcenters(const Triangulation& dt, int threads)
{
  auto& s = *dt.structure;
  const int corners = cornersOf(dt);
  Eigen::Vector3d* circumcenters = placeCircumcenters(s);
  detail::forEachRange(s.finite, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t k = begin; k < end; ++k)
      circumcenters[k] = circumcenterOf(dt, corners, k);
  });
  s.circumcenters = circumcenters;
}

} // namespace

Triangulation
triangulate(std::vector<Eigen::Vector3d> points, int threads)
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

  detail::BuildCells cells;
  out.dimension = detail::buildDelaunay(out.points, cells, threads);
  if (out.dimension == 2) {
    // CGAL's insertion keeps scratch tables in thread-local storage that an
    // exception (std::bad_alloc) leaves dirty, which breaks every later insertion in
    // the same thread. Building in a thread of its own confines that state to this
    // call.
    std::exception_ptr failure;
    std::thread planar([&]() {
      try {
        triangulatePlanar(out.points, cells);
      }
      catch (...) {
        failure = std::current_exception();
      }
    });
    planar.join();
    if (failure)
      std::rethrow_exception(failure);
  }
  if (out.dimension < 2)
    return out;

  out.structure = std::make_shared<detail::DelaunayStructure>();
  orderCells(cells, cornersOf(out), out.points.size(), threads, *out.structure);
  // The built cells' memory waits for the circumcenters; what they will not need
  // goes back to the system before the passes add their arrays on top.
  out.structure->build = std::move(cells);
  releaseTail(out.structure->build, circumcenterCells(out.structure->finite));
  trimMallocArenas();
  out.number_of_cells = out.structure->finite;
  return out;
}

void
Triangulation::release()
{
  structure.reset();
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
visitHullFacets(const Triangulation& dt, HullFacetVisitor visitor, void* context)
{
  if (!dt.structure || dt.dimension != 3)
    return;
  const auto& s = *dt.structure;
  for (std::size_t c = s.finite; c < s.vertices.size(); ++c) {
    // The finite facet of an infinite cell, which is oriented as if the infinite
    // vertex were a point outside the hull.
    const auto& v = s.vertices[c];
    const auto opposite = oppositeFacet(v, infiniteCorner(v));
    visitor(context, HullFacet{opposite.ids, opposite.parity});
  }
}

void
visitCells(const Triangulation& dt,
           unsigned int data,
           int threads,
           CellVisitor visitor,
           void* context)
{
  if (!dt.structure)
    return;
  auto& s = *dt.structure;
  const int corners = cornersOf(dt);
  const bool neighbors = (data & CellView::NEIGHBORS) == CellView::NEIGHBORS;
  // The first pass that asks for the circumcenters computes each as it visits its
  // cell (one pass over the cells less), unless it reads the neighbours' too.
  Eigen::Vector3d* computing = nullptr;
  if (((data & CellView::CIRCUMCENTER) || neighbors) && !s.circumcenters) {
    if (neighbors)
      computeCircumcenters(dt, threads);
    else
      computing = placeCircumcenters(s);
  }
  const int finite = static_cast<int>(s.finite);
  detail::forEachRange(
      s.finite, threads, [&](std::size_t begin, std::size_t end, int thread) {
        constexpr std::size_t AHEAD = 8;
        CellView view;
        view.corners = corners;
        for (std::size_t k = begin; k < end; ++k) {
          const int c = static_cast<int>(k);
          const auto& across = s.neighbors[k];
          view.v = s.vertices[k];
          view.ahead = {-1, -1, -1, -1};
          if (k + AHEAD < end) {
            view.ahead = s.vertices[k + AHEAD];
            if (neighbors)
              for (int i = 0; i < corners; ++i) {
                const int other = s.neighbors[k + AHEAD][i];
                if (other < finite)
                  __builtin_prefetch(&s.circumcenters[other]);
              }
          }
          if (computing)
            view.circumcenter = computing[k] = circumcenterOf(dt, corners, k);
          else if (data & CellView::CIRCUMCENTER)
            view.circumcenter = s.circumcenters[k];
          view.edges = 0;
          // The neighbours about an edge lie across the facets opposite the other two
          // vertices.
          for (int e = 0; (data & CellView::EDGES) && corners == 4 && e < 6; ++e) {
            const auto& ends = CellView::EDGE_ENDS[5 - e];
            if (c < across[ends[0]] && c < across[ends[1]])
              view.edges |= static_cast<std::uint8_t>(1u << e);
          }
          for (int i = 0; (data & CellView::FACETS) && i < 4; ++i) {
            // Each interior facet once: from the cell visited later.
            if (i >= corners || across[i] >= finite)
              view.facet[i] = FacetRole::HULL;
            else if (across[i] > c)
              view.facet[i] = FacetRole::SHARED;
            else {
              view.facet[i] = FacetRole::OWN;
              if (neighbors)
                view.neighbor_circumcenter[i] = s.circumcenters[across[i]];
            }
          }
          visitor(context, view, thread);
        }
      });
  // Only once every cell has its circumcenter (forEachRange rethrows a failure).
  if (computing)
    s.circumcenters = computing;
}

} // namespace detail

} // namespace cocone
} // namespace pcl
