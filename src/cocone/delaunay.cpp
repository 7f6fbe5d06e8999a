/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include "delaunay.h"

#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>
#include <CGAL/Spatial_sort_traits_adapter_3.h>

#include <algorithm>
#include <limits>
#include <new>
#include <utility>

namespace pcl {
namespace cocone {
namespace detail {

namespace {

using Point = Kernel::Point_3;
constexpr int INFINITE = BuildCell::INFINITE;

/** Bowyer-Watson insertion: find the cells whose circumsphere contains the new
 * point (its conflict region, a star-shaped hole), free them and fill the hole with
 * a cone of new cells from its boundary facets to the point. */
class Builder {
public:
  Builder(const std::vector<Point>& points, std::vector<BuildCell>& cells)
  : points_(points), cells_(cells)
  {}

  /** Start from a tetrahedron of four points and its four infinite cells. */
  void
  start(std::array<int, 4> s)
  {
    if (Kernel::Orientation_3()(point(s[0]), point(s[1]), point(s[2]), point(s[3])) ==
        CGAL::NEGATIVE)
      std::swap(s[0], s[1]);
    BuildCell first;
    first.v = s;
    cells_.push_back(first);
    // The infinite cell across the facet opposite s[i]: that facet's other side,
    // so two of its vertices trade places.
    for (int i = 0; i < 4; ++i) {
      BuildCell outside;
      outside.v = s;
      outside.v[i] = INFINITE;
      std::swap(outside.v[(i + 1) & 3], outside.v[(i + 2) & 3]);
      cells_.push_back(outside);
    }
    // Adjacencies by matching vertex sets: five cells, done once.
    for (int x = 0; x < 5; ++x)
      for (int i = 0; i < 4; ++i)
        for (int y = 0; y < 5; ++y)
          for (int j = 0; y != x && j < 4; ++j)
            if (facetKey(cells_[x].v, i) == facetKey(cells_[y].v, j))
              cells_[x].n[i] = static_cast<std::uint32_t>(y * 4 + j);
    mark_.assign(cells_.size(), 0);
  }

  /** Insert vertex q. */
  void
  insert(int q)
  {
    const Point& p = point(q);
    // Start from the finite cell of the previous point's star whose corners are
    // nearest to p on average, not from any cell of it: about a point of a sampled
    // surface the cells are thin, and a walk from the far side circles the point.
    // (Cell 0, the first tetrahedron, is alive until the first insertion.)
    int start = star_.empty() ? 0 : star_.front();
    double best = std::numeric_limits<double>::infinity();
    for (const int c : star_) {
      const auto& v = cells_[c].v;
      if ((v[0] | v[1] | v[2] | v[3]) < 0)
        continue;
      Eigen::Vector3d sum(-4.0 * p.x(), -4.0 * p.y(), -4.0 * p.z());
      for (const int w : v)
        sum += Eigen::Vector3d(point(w).x(), point(w).y(), point(w).z());
      if (sum.squaredNorm() < best) {
        best = sum.squaredNorm();
        start = c;
      }
    }
    const int first = locate(p, start);
    // A point already there (the points should be unique) stays out: a cell of
    // four distinct points cannot be flat.
    for (const int v : cells_[first].v)
      if (v != INFINITE && point(v) == p)
        return;
    stack_.clear();
    conflict_.clear();
    touched_.clear();
    boundary_.clear();
    prefetchNeighbors(first);
    stack_.push_back(first);
    conflict_.push_back(first);
    mark_[first] = IN_CONFLICT;
    while (!stack_.empty()) {
      const int c = stack_.back();
      stack_.pop_back();
      for (int i = 0; i < 4; ++i) {
        const std::uint32_t across = cells_[c].n[i];
        const int other = static_cast<int>(across >> 2);
        if (mark_[other] == IN_CONFLICT)
          continue;
        if (mark_[other] == UNSEEN) {
          if (inConflict(cells_[other].v, p)) {
            mark_[other] = IN_CONFLICT;
            prefetchNeighbors(other);
            stack_.push_back(other);
            conflict_.push_back(other);
            continue;
          }
          mark_[other] = OUTSIDE;
          touched_.push_back(other);
        }
        boundary_.push_back({cells_[c].v, i, across});
        boundary_.back().v[i] = q;
      }
    }
    for (const int c : touched_)
      mark_[c] = UNSEEN;
    for (const int c : conflict_) {
      mark_[c] = UNSEEN;
      cells_[c].v[0] = BuildCell::FREE;
      cells_[c].n[0] = static_cast<std::uint32_t>(free_);
      free_ = c;
    }
    starHole();
  }

private:
  enum Mark : std::uint8_t { UNSEEN, IN_CONFLICT, OUTSIDE };

  struct BoundaryFacet {
    /** The new cell: the conflict cell's vertices with the facet's opposite one
     * replaced by the new point (which keeps the orientation). */
    std::array<int, 4> v;
    int i;
    /** The cell outside the hole across the facet, as in BuildCell::n. */
    std::uint32_t across;
  };

  /** Ask for the cells across c's facets, which the search of the conflict region
   * reads next: their loads overlap instead of waiting one after another. */
  void
  prefetchNeighbors(int c) const
  {
    for (const std::uint32_t across : cells_[c].n) {
      __builtin_prefetch(&cells_[across >> 2]);
      __builtin_prefetch(&mark_[across >> 2]);
    }
  }

  const Point&
  point(int v) const
  {
    return points_[v];
  }

  static std::array<int, 3>
  facetKey(const std::array<int, 4>& v, int i)
  {
    std::array<int, 3> key;
    for (int k = 0, m = 0; k < 4; ++k)
      if (k != i)
        key[m++] = v[k];
    std::sort(key.begin(), key.end());
    return key;
  }

  /** CGAL's order of the symbolic perturbation: lexicographic, the largest point
   * perturbed most. */
  static bool
  perturbationOrder(const Point* a, const Point* b)
  {
    return Kernel::Compare_xyz_3()(*a, *b) == CGAL::SMALLER;
  }

  /** CGAL's Delaunay_triangulation_3::side_of_oriented_sphere with its symbolic
   * perturbation, for a positively oriented cell: > 0 inside. */
  int
  sideOfOrientedSphere(const Point& p0,
                       const Point& p1,
                       const Point& p2,
                       const Point& p3,
                       const Point& p) const
  {
    const auto side = Kernel::Side_of_oriented_sphere_3()(p0, p1, p2, p3, p);
    if (side != CGAL::ON_ORIENTED_BOUNDARY)
      return side;
    // Co-spherical: perturb the points, the lexicographically largest most.
    std::array<const Point*, 5> sorted{&p0, &p1, &p2, &p3, &p};
    std::sort(sorted.begin(), sorted.end(), perturbationOrder);
    const Kernel::Orientation_3 orientation;
    for (int i = 4; i > 2; --i) {
      if (sorted[i] == &p)
        return CGAL::ON_NEGATIVE_SIDE;
      CGAL::Orientation o = CGAL::COPLANAR;
      if (sorted[i] == &p3 && (o = orientation(p0, p1, p2, p)) != CGAL::COPLANAR)
        return o;
      if (sorted[i] == &p2 && (o = orientation(p0, p1, p, p3)) != CGAL::COPLANAR)
        return o;
      if (sorted[i] == &p1 && (o = orientation(p0, p, p2, p3)) != CGAL::COPLANAR)
        return o;
      if (sorted[i] == &p0 && (o = orientation(p, p1, p2, p3)) != CGAL::COPLANAR)
        return o;
    }
    return CGAL::ON_NEGATIVE_SIDE;
  }

  /** CGAL's coplanar_side_of_bounded_circle with its symbolic perturbation: > 0
   * inside. */
  int
  coplanarSideOfBoundedCircle(const Point& p0,
                              const Point& p1,
                              const Point& p2,
                              const Point& p) const
  {
    const auto side = Kernel::Coplanar_side_of_bounded_circle_3()(p0, p1, p2, p);
    if (side != CGAL::ON_BOUNDARY)
      return side;
    std::array<const Point*, 4> sorted{&p0, &p1, &p2, &p};
    std::sort(sorted.begin(), sorted.end(), perturbationOrder);
    const Kernel::Coplanar_orientation_3 orientation;
    const int local = orientation(p0, p1, p2);
    for (int i = 3; i > 0; --i) {
      if (sorted[i] == &p)
        return CGAL::ON_UNBOUNDED_SIDE;
      int o = CGAL::COLLINEAR;
      if (sorted[i] == &p2 && (o = orientation(p0, p1, p)) != CGAL::COLLINEAR)
        return o * local;
      if (sorted[i] == &p1 && (o = orientation(p0, p, p2)) != CGAL::COLLINEAR)
        return o * local;
      if (sorted[i] == &p0 && (o = orientation(p, p1, p2)) != CGAL::COLLINEAR)
        return o * local;
    }
    return CGAL::ON_UNBOUNDED_SIDE;
  }

  /** CGAL's side_of_sphere(c, p, true) == ON_BOUNDED_SIDE: the conflict test. An
   * infinite cell is in conflict when p lies beyond its hull facet, or in that
   * facet's plane and inside its circumcircle. */
  bool
  inConflict(const std::array<int, 4>& v, const Point& p) const
  {
    const int i3 = infiniteCorner(v);
    if (i3 < 0)
      return sideOfOrientedSphere(
                 point(v[0]), point(v[1]), point(v[2]), point(v[3]), p) > 0;
    // The finite facet, in CGAL's order for the infinite vertex at i3.
    const int i0 = (i3 % 2 == 1) ? (i3 + 1) & 3 : (i3 + 2) & 3;
    const int i1 = (i3 % 2 == 1) ? (i3 + 2) & 3 : (i3 + 1) & 3;
    const int i2 = (i3 + 3) & 3;
    const Point &a = point(v[i0]), &b = point(v[i1]), &c = point(v[i2]);
    const auto o = Kernel::Orientation_3()(a, b, c, p);
    if (o != CGAL::COPLANAR)
      return o == CGAL::POSITIVE;
    return coplanarSideOfBoundedCircle(a, b, c, p) > 0;
  }

  /** Walk towards p: first with plain floating-point orientations, cheap and
   * possibly wrong near p (it only chooses where to start), then with exact ones,
   * each step through a facet that p lies beyond, tried from a random facet (a
   * walk that cannot cycle). Ends in a cell containing p, or in an infinite cell
   * in conflict with p when p lies outside the hull. */
  int
  locate(const Point& p, int c)
  {
    c = roughWalk(p, c);
    const Kernel::Orientation_3 orientation;
    int previous = -1;
    for (;;) {
      const BuildCell& cell = cells_[c];
      const int i3 = infiniteCorner(cell.v);
      if (i3 >= 0) {
        if (inConflict(cell.v, p))
          return c;
        // p is not beyond this hull facet: back inside.
        previous = c;
        c = static_cast<int>(cell.n[i3] >> 2);
        continue;
      }
      const int next = step(cell, p, previous, [&](const auto& q) {
        return orientation(*q[0], *q[1], *q[2], *q[3]) == CGAL::NEGATIVE;
      });
      if (next < 0)
        return c;
      previous = c;
      c = next;
    }
  }

  /** One step of a walk from finite cell \a cell: the cell across the first facet,
   * tried from a random one, that p lies beyond, i.e. where \a negative says the
   * cell's corners with p in place of the facet's opposite vertex are negatively
   * oriented; the cell the walk came from is skipped. -1 if p lies beyond none. */
  template <typename Negative>
  int
  step(const BuildCell& cell, const Point& p, int previous, const Negative& negative)
  {
    const int r = nextRandom();
    std::array<const Point*, 4> q{
        &point(cell.v[0]), &point(cell.v[1]), &point(cell.v[2]), &point(cell.v[3])};
    for (int k = 0; k < 4; ++k) {
      const int i = (r + k) & 3;
      const int other = static_cast<int>(cell.n[i] >> 2);
      if (other == previous)
        continue;
      const Point* own = q[i];
      q[i] = &p;
      const bool beyond = negative(q);
      q[i] = own;
      if (beyond)
        return other;
    }
    return -1;
  }

  int
  roughWalk(const Point& p, int c)
  {
    int previous = -1;
    for (int steps = 0; steps < 1000; ++steps) {
      const BuildCell& cell = cells_[c];
      if ((cell.v[0] | cell.v[1] | cell.v[2] | cell.v[3]) < 0)
        return c;
      for (const std::uint32_t across : cell.n)
        __builtin_prefetch(&cells_[across >> 2]);
      const int next = step(cell, p, previous, [](const auto& q) {
        const double ax = q[1]->x() - q[0]->x(), ay = q[1]->y() - q[0]->y(),
                     az = q[1]->z() - q[0]->z();
        const double bx = q[2]->x() - q[0]->x(), by = q[2]->y() - q[0]->y(),
                     bz = q[2]->z() - q[0]->z();
        const double cx = q[3]->x() - q[0]->x(), cy = q[3]->y() - q[0]->y(),
                     cz = q[3]->z() - q[0]->z();
        return ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) +
                   az * (bx * cy - by * cx) <
               0.0;
      });
      if (next < 0)
        return c;
      previous = c;
      c = next;
    }
    return c;
  }

  int
  nextRandom()
  {
    random_ = random_ * 1664525u + 1013904223u;
    return static_cast<int>(random_ >> 30);
  }

  int
  allocate()
  {
    if (free_ >= 0) {
      const int c = free_;
      free_ = static_cast<int>(cells_[c].n[0]);
      return c;
    }
    // Codes are cell * 4 + facet in 32 bits.
    if (cells_.size() >= (std::size_t(1) << 30))
      throw std::bad_alloc();
    cells_.emplace_back();
    mark_.push_back(UNSEEN);
    return static_cast<int>(cells_.size()) - 1;
  }

  /** Fill the hole with one new cell per boundary facet; new cells meet along the
   * hole's boundary edges, each shared by two of them, matched in a hash table. */
  void
  starHole()
  {
    std::size_t size = 16;
    while (size < boundary_.size() * 4)
      size <<= 1;
    if (edges_.size() < size)
      edges_.assign(size, Edge{});
    ++stamp_;
    // Probe only the first size slots: the table keeps the size of the largest hole
    // so far, a small hole stays in a few cache lines.
    const std::size_t mask = size - 1;
    star_.clear();
    for (const BoundaryFacet& b : boundary_) {
      const int id = allocate();
      BuildCell& cell = cells_[id];
      cell.v = b.v;
      cell.n[b.i] = b.across;
      cells_[b.across >> 2].n[b.across & 3] = static_cast<std::uint32_t>(id * 4 + b.i);
      // The facet opposite v[j] (j != i) contains q and the edge of the other two.
      for (int j = 0; j < 4; ++j) {
        if (j == b.i)
          continue;
        std::array<int, 2> e;
        for (int k = 0, m = 0; k < 4; ++k)
          if (k != j && k != b.i)
            e[m++] = b.v[k];
        const std::uint64_t key =
            (std::uint64_t(static_cast<std::uint32_t>(std::min(e[0], e[1]))) << 32) |
            static_cast<std::uint32_t>(std::max(e[0], e[1]));
        const std::uint32_t code = static_cast<std::uint32_t>(id * 4 + j);
        for (std::size_t h = (key * 0x9e3779b97f4a7c15ULL) >> 40;; ++h) {
          Edge& slot = edges_[h & mask];
          if (slot.stamp != stamp_) {
            slot = Edge{key, code, stamp_};
            break;
          }
          if (slot.key == key) {
            cells_[id].n[j] = slot.code;
            cells_[slot.code >> 2].n[slot.code & 3] = code;
            slot.key = ~std::uint64_t(0); // each edge is met twice
            break;
          }
        }
      }
      star_.push_back(id);
    }
  }

  struct Edge {
    std::uint64_t key = 0;
    std::uint32_t code = 0;
    std::uint32_t stamp = 0;
  };

  const std::vector<Point>& points_;
  std::vector<BuildCell>& cells_;
  std::vector<std::uint8_t> mark_;
  std::vector<int> stack_, conflict_, touched_;
  /** The cells made by the latest insertion. */
  std::vector<int> star_;
  std::vector<BoundaryFacet> boundary_;
  std::vector<Edge> edges_;
  std::uint32_t stamp_ = 0;
  std::uint32_t random_ = 12345;
  int free_ = -1;
};

} // namespace

int
buildDelaunay(const std::vector<Eigen::Vector3d>& input, std::vector<BuildCell>& cells)
{
  cells.clear();
  const int n = static_cast<int>(input.size());
  std::vector<Point> points;
  points.reserve(input.size());
  for (const auto& p : input)
    points.emplace_back(p.x(), p.y(), p.z());

  // CGAL's insertion order: its spatial sort (a Hilbert curve over random rounds
  // of growing size, seeded), which keeps every walk short.
  std::vector<int> order(n);
  {
    std::vector<std::pair<Point, int>> sites;
    sites.reserve(input.size());
    for (int i = 0; i < n; ++i)
      sites.emplace_back(points[i], i);
    CGAL::spatial_sort(sites.begin(),
                       sites.end(),
                       CGAL::Spatial_sort_traits_adapter_3<
                           Kernel,
                           CGAL::First_of_pair_property_map<std::pair<Point, int>>>());
    for (int i = 0; i < n; ++i)
      order[i] = sites[i].second;
  }

  // The affine dimension, and a first tetrahedron: the first two points, the first
  // one off their line, the first one off their plane.
  if (n < 2)
    return n - 1;
  const Point &a = points[order[0]], &b = points[order[1]];
  int third = -1, fourth = -1;
  for (int k = 2; k < n && third < 0; ++k)
    if (!Kernel::Collinear_3()(a, b, points[order[k]]))
      third = k;
  if (third < 0)
    return 1;
  for (int k = third + 1; k < n && fourth < 0; ++k)
    if (Kernel::Orientation_3()(a, b, points[order[third]], points[order[k]]) !=
        CGAL::COPLANAR)
      fourth = k;
  if (fourth < 0)
    return 2;

  // About 7 cells per point in a volume, up to 15 on a sampled surface; reserved
  // address space costs no memory until it is used.
  cells.reserve(std::size_t(n) * 16);
  Builder builder(points, cells);
  builder.start({order[0], order[1], order[third], order[fourth]});
  for (int k = 2; k < n; ++k)
    if (k != third && k != fourth)
      builder.insert(order[k]);
  return 3;
}

} // namespace detail
} // namespace cocone
} // namespace pcl
