/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include "delaunay.h"

#include <boost/random/linear_congruential.hpp>
#include <boost/random/random_number_generator.hpp>

#include <CGAL/algorithm.h>

#include "parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <system_error>
#include <thread>
#include <utility>

namespace pcl {
namespace cocone {
namespace detail {

namespace {

using Point = Kernel::Point_3;
constexpr int INFINITE = BuildCell::INFINITE;

/** What the builders of one triangulation share: the cells, and per cell a state
 * that says who holds it. With several threads inserting at once, a cell is read or
 * written only by the builder that holds it. */
struct SharedCells {
  explicit SharedCells(BuildCells& c) : cells(c) {}

  /** A live cell that no builder holds. */
  static constexpr std::uint8_t FREE_TO_TAKE = 0;
  /** A freed cell, or one not handed out yet: not part of the triangulation. */
  static constexpr std::uint8_t DEAD = 0xff;

  BuildCells& cells;
  /** Per cell: FREE_TO_TAKE, DEAD, or the holder's tag or'ed with its mark. */
  std::vector<std::uint8_t> state;
  /** Cells [0, used) have been handed out to the builders, in blocks. */
  std::atomic<std::size_t> used{0};
};

/** The corners of the facet opposite corner i of a positively oriented cell, in
 * CGAL's order: corner i lies on its positive side. */
constexpr int FACET[4][3] = {{2, 1, 3}, {2, 3, 0}, {0, 3, 1}, {0, 1, 2}};

/** Bowyer-Watson insertion: find the cells whose circumsphere contains the new
 * point (its conflict region, a star-shaped hole), free them and fill the hole with
 * a cone of new cells from its boundary facets to the point. */
class Builder {
public:
  /** Builders that can tell their cells apart: a state holds (id + 1) << 2 | mark
   * below SharedCells::DEAD. */
  static constexpr int MAX_BUILDERS = 62;

  /** \param[in] id this builder's number, below MAX_BUILDERS
   *  \param[in] concurrent whether other builders insert at the same time */
  Builder(const std::vector<Point>& points,
          SharedCells& shared,
          int id,
          bool concurrent)
  : points_(points)
  , shared_(shared)
  , cells_(shared.cells)
  , tag_(static_cast<std::uint8_t>((id + 1) << 2))
  , concurrent_(concurrent)
  , hole_vertex_(points.size())
  , directed_(std::size_t(HOLE_VERTICES) * HOLE_VERTICES)
  {}

  /** Start from a tetrahedron of four points and its four infinite cells. */
  void
  start(std::array<int, 4> s)
  {
    if (Kernel::Orientation_3()(point(s[0]), point(s[1]), point(s[2]), point(s[3])) ==
        CGAL::NEGATIVE)
      std::swap(s[0], s[1]);
    reserveCells(5);
    std::array<int, 5> c;
    for (int& x : c)
      x = allocate();
    cells_[c[0]].v = s;
    // The infinite cell across the facet opposite s[i]: that facet's other side,
    // so two of its vertices trade places.
    for (int i = 0; i < 4; ++i) {
      auto& v = cells_[c[i + 1]].v;
      v = s;
      v[i] = INFINITE;
      std::swap(v[(i + 1) & 3], v[(i + 2) & 3]);
    }
    // Adjacencies by matching vertex sets: five cells, done once.
    for (int x = 0; x < 5; ++x)
      for (int i = 0; i < 4; ++i)
        for (int y = 0; y < 5; ++y)
          for (int j = 0; y != x && j < 4; ++j)
            if (facetKey(cells_[c[x]].v, i) == facetKey(cells_[c[y]].v, j))
              cells_[c[x]].n[i] = static_cast<std::uint32_t>(c[y] * 4 + j);
    for (const int x : c)
      letGo(x);
    start_ = c[0];
  }

  /** Insert vertex q. False, with nothing changed, if a cell that the insertion
   * needs is held by another builder. \a next: the vertex this builder inserts
   * next (-1 if none), which the next walk starts towards. */
  bool
  insert(int q, int next)
  {
    const Point& p = point(q);
    const int first = locate(p);
    if (first < 0)
      return false;
    // A point already there (the points should be unique) stays out: a cell of
    // four distinct points cannot be flat.
    for (const int v : cells_[first].v)
      if (v != INFINITE && point(v) == p) {
        letGo(first);
        return true;
      }
    prefetchNeighbors(first);
    mark(first, IN_CONFLICT);
    // Breadth first, the conflict cells in the order found: a cell's neighbours
    // are fetched when it is found and read only after the cells found before it.
    // Branches on what a neighbour is are coin flips to the branch predictor (a
    // surface sample's conflict regions are large, some 30 cells with as many
    // tested around them), so there are few: the neighbours to test are sorted out
    // first, and a tested cell is written to both the conflict and the touched
    // list, the one it belongs to growing; so is each facet to the boundary.
    std::size_t found = 0, outside = 0, facets = 0;
    const auto room = [](auto& list, std::size_t used) {
      if (list.size() < used + 4)
        list.resize(std::max(2 * list.size(), used + 4));
    };
    const auto trim = [&]() {
      conflict_.resize(found);
      touched_.resize(outside);
      boundary_.resize(facets);
    };
    room(conflict_, 0);
    conflict_[found++] = first;
    for (std::size_t head = 0; head < found; ++head) {
      room(conflict_, found);
      room(touched_, outside);
      room(boundary_, facets);
      const int c = conflict_[head];
      const BuildCell& cell = cells_[c];
      const auto add_facet = [&](int i, bool border) {
        BoundaryFacet& facet = boundary_[facets];
        facet.v = cell.v;
        facet.v[i] = q;
        facet.i = i;
        facet.across = cell.n[i];
        facets += border;
      };
      // The neighbours to test, sorted out first: one loop of as many tests
      // instead of a branch per facet on what its neighbour was.
      std::array<int, 4> untested;
      int count = 0;
      for (int i = 0; i < 4; ++i) {
        const std::uint8_t seen = stateOf(static_cast<int>(cell.n[i] >> 2));
        const bool border = seen == (tag_ | OUTSIDE);
        untested[count] = i;
        count += !border && seen != (tag_ | IN_CONFLICT);
        add_facet(i, border);
      }
      for (int k = 0; k < count; ++k) {
        const int i = untested[k];
        const int other = static_cast<int>(cell.n[i] >> 2);
        if (!take(other, OUTSIDE)) {
          trim();
          return abandon();
        }
        const bool in = inConflict(cells_[other].v, p);
        mark(other, in ? IN_CONFLICT : OUTSIDE);
        prefetchNeighbors(other);
        conflict_[found] = other;
        found += in;
        touched_[outside] = other;
        outside += !in;
        add_facet(i, !in);
      }
    }
    trim();
    // The conflict cells are reused first: the rest must be at hand before any
    // cell changes.
    if (boundary_.size() > conflict_.size() &&
        !reserveCells(boundary_.size() - conflict_.size()))
      return abandon();
    for (const int c : conflict_)
      freeCell(c);
    starHole();
    if (next >= 0)
      startTowards(point(next));
    else
      start_ = star_.front();
    for (const int c : touched_)
      letGo(c);
    for (const int c : star_)
      letGo(c);
    return true;
  }

  /** Start the next walk from the cell of the latest star nearest to \a p. Only
   * while no other builder runs, or while this one holds the star. */
  void
  startTowards(const Point& p)
  {
    // The finite cell whose corners are nearest to p on average, not any cell of
    // it: about a point of a sampled surface the cells are thin, and a walk from
    // the far side circles the point.
    int start = star_.empty() ? start_ : star_.front();
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
    start_ = start;
  }

  /** The cell the next walk starts from. */
  int
  startCell() const
  {
    return start_;
  }

  /** Start the next walk from cell \a c. */
  void
  setStartCell(int c)
  {
    start_ = c;
  }

  /** Work alone from now on (\a concurrent false), or with others. */
  void
  setConcurrent(bool concurrent)
  {
    concurrent_ = concurrent;
  }

  /** Give up the cells handed out and not used: marked freed, as orderCells() skips
   * them. */
  void
  finish()
  {
    for (; next_ < end_; ++next_)
      cells_[next_].v[0] = BuildCell::FREE;
  }

private:
  /** A cell's mark, or'ed with its holder's tag. */
  enum Mark : std::uint8_t { HELD = 1, IN_CONFLICT = 2, OUTSIDE = 3 };
  static_assert((MAX_BUILDERS << 2 | OUTSIDE) < SharedCells::DEAD,
                "every builder's marks fit below DEAD");
  /** Cells handed out to a builder at a time. */
  static constexpr std::size_t BLOCK = 4096;

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
      __builtin_prefetch(&shared_.state[across >> 2]);
    }
  }

  std::uint8_t
  stateOf(int c) const
  {
    return __atomic_load_n(&shared_.state[c], __ATOMIC_RELAXED);
  }

  /** Hold cell c, which no builder held before (then its contents may be read),
   * with mark \a m. False if another builder holds it or it is dead. */
  bool
  take(int c, Mark m)
  {
    const std::uint8_t mine = tag_ | m;
    if (!concurrent_) {
      shared_.state[c] = mine;
      return true;
    }
    std::uint8_t expected = SharedCells::FREE_TO_TAKE;
    return __atomic_compare_exchange_n(
        &shared_.state[c], &expected, mine, false, __ATOMIC_ACQUIRE, __ATOMIC_RELAXED);
  }

  /** Mark a cell this builder holds. */
  void
  mark(int c, Mark m)
  {
    __atomic_store_n(
        &shared_.state[c], static_cast<std::uint8_t>(tag_ | m), __ATOMIC_RELAXED);
  }

  /** Stop holding cell c: what this builder wrote to it is seen by the next one to
   * take it. */
  void
  letGo(int c, std::uint8_t state = SharedCells::FREE_TO_TAKE)
  {
    __atomic_store_n(&shared_.state[c], state, __ATOMIC_RELEASE);
  }

  /** Let go of every cell of an insertion that cannot go on; returns false. */
  bool
  abandon()
  {
    for (const int c : conflict_)
      letGo(c);
    for (const int c : touched_)
      letGo(c);
    return false;
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

  /** The largest absolute value of \a first and \a rest, without a branch. */
  template <typename... Rest>
  static double
  maxAbs(double first, Rest... rest)
  {
    double m = std::abs(first);
    ((m = std::max(m, std::abs(rest))), ...);
    return m;
  }

  /** A semi-static filter's answer: the sign of \a det where its error bound \a eps
   * decides it, else 0; without a branch on the sign. */
  static int
  filteredSign(double det, double eps)
  {
    return (det > eps) - (det < -eps);
  }

  /** CGAL's semi-static filter of Side_of_oriented_sphere_3 (the same determinant,
   * the same error bound) with its maxima taken without branches: +1 or -1 where the
   * bound decides the sign, 0 where only CGAL's predicate can. */
  static int
  quickSideOfOrientedSphere(
      const Point& p, const Point& q, const Point& r, const Point& s, const Point& t)
  {
    const double ptx = p.x() - t.x(), pty = p.y() - t.y(), ptz = p.z() - t.z();
    const double qtx = q.x() - t.x(), qty = q.y() - t.y(), qtz = q.z() - t.z();
    const double rtx = r.x() - t.x(), rty = r.y() - t.y(), rtz = r.z() - t.z();
    const double stx = s.x() - t.x(), sty = s.y() - t.y(), stz = s.z() - t.z();
    const double pt2 = ptx * ptx + pty * pty + ptz * ptz;
    const double qt2 = qtx * qtx + qty * qty + qtz * qtz;
    const double rt2 = rtx * rtx + rty * rty + rtz * rtz;
    const double st2 = stx * stx + sty * sty + stz * stz;
    const double maxx = maxAbs(ptx, qtx, rtx, stx);
    const double maxy = maxAbs(pty, qty, rty, sty);
    const double maxz = maxAbs(ptz, qtz, rtz, stz);
    const double lo = std::min(std::min(maxx, maxy), maxz);
    const double hi = std::max(std::max(maxx, maxy), maxz);
    // Outside CGAL's range against underflow and overflow: its predicate decides.
    if (!(lo >= 1e-58 && hi < 1e61))
      return 0;
    const double eps = 1.2466136531027298e-13 * maxx * maxy * maxz * (hi * hi);
    // CGAL::determinant's expansion by 2x2 and 3x3 minors, operation for operation
    // (the bound is for its rounding), of the rows pt, rt, qt, st; spelled out to
    // be inlined.
    const double m01 = rtx * pty - ptx * rty;
    const double m02 = qtx * pty - ptx * qty;
    const double m03 = stx * pty - ptx * sty;
    const double m12 = qtx * rty - rtx * qty;
    const double m13 = stx * rty - rtx * sty;
    const double m23 = stx * qty - qtx * sty;
    const double m012 = m12 * ptz - m02 * rtz + m01 * qtz;
    const double m013 = m13 * ptz - m03 * rtz + m01 * stz;
    const double m023 = m23 * ptz - m03 * qtz + m02 * stz;
    const double m123 = m23 * rtz - m13 * qtz + m12 * stz;
    return filteredSign(m123 * pt2 - m023 * rt2 + m013 * qt2 - m012 * st2, eps);
  }

  /** CGAL's semi-static filter of Orientation_3 in the same way: +1 or -1 where its
   * bound decides the sign of the orientation of p, q, r, s, 0 where only CGAL's
   * predicate can. */
  static int
  quickOrientation(const Point& p, const Point& q, const Point& r, const Point& s)
  {
    const double pqx = q.x() - p.x(), pqy = q.y() - p.y(), pqz = q.z() - p.z();
    const double prx = r.x() - p.x(), pry = r.y() - p.y(), prz = r.z() - p.z();
    const double psx = s.x() - p.x(), psy = s.y() - p.y(), psz = s.z() - p.z();
    const double maxx = maxAbs(pqx, prx, psx);
    const double maxy = maxAbs(pqy, pry, psy);
    const double maxz = maxAbs(pqz, prz, psz);
    const double lo = std::min(std::min(maxx, maxy), maxz);
    const double hi = std::max(std::max(maxx, maxy), maxz);
    if (!(lo >= 1e-97 && hi < 1e102))
      return 0;
    const double eps = 5.1107127829973299e-15 * maxx * maxy * maxz;
    // CGAL::determinant's expansion of the rows pq, pr, ps, operation for operation.
    const double m01 = pqx * pry - prx * pqy;
    const double m02 = pqx * psy - psx * pqy;
    const double m12 = prx * psy - psx * pry;
    return filteredSign(m01 * psz - m02 * prz + m12 * pqz, eps);
  }

  /** Orientation_3 with the filter above inlined: > 0 positive. */
  static int
  orientationSign(const Point& p, const Point& q, const Point& r, const Point& s)
  {
    const int quick = quickOrientation(p, q, r, s);
    return quick != 0 ? quick : Kernel::Orientation_3()(p, q, r, s);
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
    const int quick = quickSideOfOrientedSphere(p0, p1, p2, p3, p);
    if (quick != 0)
      return quick;
    const auto side = Kernel::Side_of_oriented_sphere_3()(p0, p1, p2, p3, p);
    if (side != CGAL::ON_ORIENTED_BOUNDARY)
      return side;
    // Co-spherical: perturb the points, the lexicographically largest most.
    std::array<const Point*, 5> sorted{&p0, &p1, &p2, &p3, &p};
    std::sort(sorted.begin(), sorted.end(), perturbationOrder);
    // (CGAL's predicate itself: this rare path is kept small, out of the way of
    // the inlined filters.)
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
    // The finite facet, the infinite vertex on its positive side.
    const auto& f = FACET[i3];
    const Point &a = point(v[f[0]]), &b = point(v[f[1]]), &c = point(v[f[2]]);
    const int o = orientationSign(a, b, c, p);
    if (o != 0)
      return o > 0;
    return coplanarSideOfBoundedCircle(a, b, c, p) > 0;
  }

  /** Walk towards p from the start cell: first with plain floating-point
   * orientations, cheap and possibly wrong near p (it only chooses where to start),
   * then with exact ones, each step through a facet that p lies beyond, tried from a
   * random facet (a walk that cannot cycle). Ends in a cell containing p, or in an
   * infinite cell in conflict with p when p lies outside the hull: held. A walk
   * holds one cell at a time, taking the next before it lets go of the last; -1
   * (nothing held) where another builder holds a cell on the way. */
  int
  locate(const Point& p)
  {
    if (!takeStart())
      return -1;
    int c = roughWalk(p, start_);
    if (c < 0)
      return -1;
    int previous = -1;
    for (;;) {
      const BuildCell& cell = cells_[c];
      const int i3 = infiniteCorner(cell.v);
      int next;
      if (i3 >= 0) {
        if (inConflict(cell.v, p))
          return c;
        // p is not beyond this hull facet: back inside.
        next = static_cast<int>(cell.n[i3] >> 2);
      }
      else {
        next = step(cell, p, previous, [&](const auto& q) {
          return orientationSign(*q[0], *q[1], *q[2], *q[3]) < 0;
        });
        if (next < 0)
          return c;
      }
      if (!moveTo(c, next))
        return -1;
      previous = c;
      c = next;
    }
  }

  /** Take the start cell; if another builder holds it or freed it, a cell of the
   * latest star, or the latest cell handed out to this builder that is free. */
  bool
  takeStart()
  {
    const auto taken = [&](std::size_t c) {
      if (stateOf(static_cast<int>(c)) != SharedCells::FREE_TO_TAKE ||
          !take(static_cast<int>(c), HELD))
        return false;
      start_ = static_cast<int>(c);
      return true;
    };
    if (taken(start_))
      return true;
    for (const int c : star_)
      if (taken(c))
        return true;
    // Alone, any live cell will do; with others, one of this builder's latest, or
    // before it has any (its first start was taken by another builder, which may
    // have freed it), one of the latest handed out.
    const std::size_t used = std::min(shared_.used.load(), cells_.size());
    const std::size_t from = concurrent_ && next_ > 0 ? next_ : used;
    const std::size_t reach = concurrent_ ? 16 * BLOCK : used;
    for (std::size_t c = from; c-- > 0 && from - c <= reach;)
      if (taken(c))
        return true;
    return false;
  }

  /** One step of a walk: take cell \a next, let go of \a c. */
  bool
  moveTo(int c, int next)
  {
    const bool taken = take(next, HELD);
    letGo(c);
    return taken;
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
      if (!moveTo(c, next))
        return -1;
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

  /** Make sure \a count cells can be allocated, from the freed ones and this
   * builder's block of cells handed out; false if no block is left (then nothing
   * changed). Alone, a builder grows the cells instead. */
  bool
  reserveCells(std::size_t count)
  {
    while (free_.size() + (end_ - next_) < count) {
      const std::size_t size = std::max(BLOCK, count);
      std::size_t first = shared_.used.load(std::memory_order_relaxed);
      do {
        // Codes are cell * 4 + facet in 32 bits.
        if (first + size > (std::size_t(1) << 30)) {
          if (concurrent_)
            return false;
          throw std::bad_alloc();
        }
        if (first + size > cells_.size()) {
          if (concurrent_)
            return false;
          const std::size_t grown = std::max(first + size, cells_.size() * 3 / 2);
          cells_.resize(grown);
          shared_.state.resize(grown, SharedCells::DEAD);
        }
      }
      while (!shared_.used.compare_exchange_weak(
          first, first + size, std::memory_order_relaxed));
      // A block right after the last one extends it; else the last one's rest is
      // freed.
      if (first != end_) {
        for (; next_ < end_; ++next_)
          freeCell(static_cast<int>(next_));
        next_ = first;
      }
      end_ = first + size;
    }
    return true;
  }

  /** Put cell c on this builder's stack of freed cells (dead to the others). */
  void
  freeCell(int c)
  {
    cells_[c].v[0] = BuildCell::FREE;
    free_.push_back(c);
    letGo(c, SharedCells::DEAD);
  }

  /** A new cell, held; reserveCells() made room for it. */
  int
  allocate()
  {
    int c;
    if (!free_.empty()) {
      c = free_.back();
      free_.pop_back();
    }
    else
      c = static_cast<int>(next_++);
    mark(c, HELD);
    return c;
  }

  /** Fill the hole with one new cell per boundary facet. */
  void
  starHole()
  {
    star_.clear();
    for (const BoundaryFacet& b : boundary_) {
      const int id = allocate();
      BuildCell& cell = cells_[id];
      cell.v = b.v;
      cell.n[b.i] = b.across;
      cells_[b.across >> 2].n[b.across & 3] = static_cast<std::uint32_t>(id * 4 + b.i);
      star_.push_back(id);
    }
    if (!linkStarByNumbers())
      linkStarByHashing();
  }

  /** The new cells meet along the hole's boundary edges. Seen from the new point, the
   * hole's boundary is a closed surface, and its facets (each new cell's facet
   * opposite the point, its corners in FACET order) run through a shared edge in
   * opposite directions: the new cell across the facet opposite A of boundary facet
   * A B C is the one whose boundary facet runs from C to B. With the boundary's
   * vertices numbered 1, 2, ... (0: the infinite vertex), a table of the directed
   * edges finds it without a search. False, with nothing linked, where the hole has
   * more vertices than the table. */
  bool
  linkStarByNumbers()
  {
    // Every vertex of the hole marked unnumbered first: no clearing between holes.
    for (const BoundaryFacet& b : boundary_)
      for (const int k : FACET[b.i])
        if (b.v[k] != INFINITE)
          hole_vertex_[b.v[k]] = UNNUMBERED;
    int count = 1;
    numbers_.resize(boundary_.size());
    for (std::size_t f = 0; f < boundary_.size(); ++f) {
      const BoundaryFacet& b = boundary_[f];
      for (int m = 0; m < 3; ++m) {
        const int w = b.v[FACET[b.i][m]];
        if (w == INFINITE) {
          numbers_[f][m] = 0;
          continue;
        }
        // A vertex met for the first time takes the next number, without a branch
        // (which vertex is new is a coin flip to the branch predictor).
        std::uint8_t& number = hole_vertex_[w];
        const bool fresh = number == UNNUMBERED;
        number = fresh ? static_cast<std::uint8_t>(count) : number;
        count += fresh;
        numbers_[f][m] = number;
      }
    }
    // Numbers up to 63 (beyond, they were not used).
    if (count > HOLE_VERTICES)
      return false;
    const auto edge = [](std::uint8_t from, std::uint8_t to) {
      return std::size_t(from) * HOLE_VERTICES + to;
    };
    for (std::size_t f = 0; f < boundary_.size(); ++f) {
      const auto& o = FACET[boundary_[f].i];
      const auto& x = numbers_[f];
      const auto cell = static_cast<std::uint32_t>(star_[f]) * 4;
      directed_[edge(x[1], x[2])] = cell + o[0];
      directed_[edge(x[2], x[0])] = cell + o[1];
      directed_[edge(x[0], x[1])] = cell + o[2];
    }
    for (std::size_t f = 0; f < boundary_.size(); ++f) {
      const auto& o = FACET[boundary_[f].i];
      const auto& x = numbers_[f];
      auto& n = cells_[star_[f]].n;
      n[o[0]] = directed_[edge(x[2], x[1])];
      n[o[1]] = directed_[edge(x[0], x[2])];
      n[o[2]] = directed_[edge(x[1], x[0])];
    }
    return true;
  }

  /** linkStarByNumbers() for a hole of any size: the new cells' edges opposite the
   * point, each shared by two of them, matched in a hash table. */
  void
  linkStarByHashing()
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
    for (std::size_t f = 0; f < boundary_.size(); ++f) {
      const BoundaryFacet& b = boundary_[f];
      const int id = star_[f];
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
    }
  }

  struct Edge {
    std::uint64_t key = 0;
    std::uint32_t code = 0;
    std::uint32_t stamp = 0;
  };

  const std::vector<Point>& points_;
  SharedCells& shared_;
  BuildCells& cells_;
  /** This builder's tag in the cells' states. */
  const std::uint8_t tag_;
  bool concurrent_;
  /** Sized ahead of use by the conflict search: default-initialized. */
  std::vector<int, DefaultInitAllocator<int>> conflict_, touched_;
  /** The cells made by the latest insertion. */
  std::vector<int> star_;
  std::vector<BoundaryFacet, DefaultInitAllocator<BoundaryFacet>> boundary_;
  std::vector<Edge> edges_;
  std::uint32_t stamp_ = 0;
  /** Vertices a hole's boundary may have for linkStarByNumbers(), the infinite one
   * included: 16 KB of directed edges. */
  static constexpr int HOLE_VERTICES = 64;
  static constexpr std::uint8_t UNNUMBERED = 0xff;
  /** Per vertex its number on the latest hole's boundary; written before read, so
   * never cleared (nor, until used, in memory). */
  std::vector<std::uint8_t, DefaultInitAllocator<std::uint8_t>> hole_vertex_;
  /** Per boundary facet, its FACET vertices' numbers. */
  std::vector<std::array<std::uint8_t, 3>> numbers_;
  /** Per directed edge of the hole's boundary (by its ends' numbers), the new cell's
   * facet that contains it, as in BuildCell::n. */
  std::vector<std::uint32_t> directed_;
  std::uint32_t random_ = 12345;
  /** Where the next walk starts. */
  int start_ = 0;
  /** The freed cells, the latest last (in the cache, reused first): a stack of ids
   * rather than a list through the cells, whose next link would be a load from a
   * cell long out of the cache for each one taken. */
  std::vector<int> free_;
  /** The cells of this builder's block not used yet. */
  std::size_t next_ = 0, end_ = 0;
};

/** Insert rest[lo, hi), one round of the insertion order, with up to \a threads
 * builders (\a main is the first), a stretch of the round each. */
void
insertRound(const std::vector<Point>& points,
            const std::vector<int>& rest,
            std::size_t lo,
            std::size_t hi,
            int threads,
            SharedCells& shared,
            Builder& main)
{
  const auto next = [&](std::size_t k, std::size_t end) {
    return k + 1 < end ? rest[k + 1] : -1;
  };
  // Threads pay once each stretch holds some ten thousand points; a state byte
  // tells up to 62 builders apart.
  const int team = std::max(
      1,
      std::min({threads, Builder::MAX_BUILDERS, static_cast<int>((hi - lo) / 10000)}));
  if (team == 1) {
    for (std::size_t k = lo; k < hi; ++k)
      main.insert(rest[k], next(k, hi));
    return;
  }
  std::vector<std::size_t> bound(team + 1);
  for (int t = 0; t <= team; ++t)
    bound[t] = lo + (hi - lo) * t / team;
  // Each builder starts next to its stretch's first point, from the latest star
  // (main's own start chosen last).
  std::vector<std::unique_ptr<Builder>> builders;
  for (int t = 1; t < team; ++t) {
    main.startTowards(points[rest[bound[t]]]);
    builders.push_back(std::make_unique<Builder>(points, shared, t, true));
    builders.back()->setStartCell(main.startCell());
  }
  main.startTowards(points[rest[bound[0]]]);
  main.setConcurrent(true);
  std::vector<std::vector<std::size_t>> left(team);
  std::atomic<bool> failed{false};
  const auto work = [&](int t) {
    Builder& builder = t == 0 ? main : *builders[t - 1];
    try {
      for (std::size_t k = bound[t]; k < bound[t + 1]; ++k)
        if (!builder.insert(rest[k], next(k, bound[t + 1])))
          left[t].push_back(k);
    }
    catch (const std::bad_alloc&) {
      failed = true;
    }
    if (t > 0)
      builder.finish();
  };
  // A stretch whose thread could not be started is inserted after the others.
  std::vector<std::thread> workers;
  int started = 1;
  try {
    for (; started < team; ++started)
      workers.emplace_back(work, started);
  }
  catch (const std::system_error&) {
  }
  work(0);
  for (auto& worker : workers)
    worker.join();
  if (failed)
    throw std::bad_alloc();
  for (int t = started; t < team; ++t)
    for (std::size_t k = bound[t]; k < bound[t + 1]; ++k)
      left[t].push_back(k);
  // What met another thread, in the insertion order.
  main.setConcurrent(false);
  std::vector<std::size_t> after;
  for (const auto& l : left)
    after.insert(after.end(), l.begin(), l.end());
  for (std::size_t j = 0; j < after.size(); ++j)
    main.insert(rest[after[j]], j + 1 < after.size() ? rest[after[j + 1]] : -1);
}

} // namespace

int
buildDelaunay(const std::vector<Eigen::Vector3d>& input, BuildCells& cells, int threads)
{
  cells.clear();
  const int n = static_cast<int>(input.size());
  std::vector<Point> points;
  points.reserve(input.size());
  for (const auto& p : input)
    points.emplace_back(p.x(), p.y(), p.z());

  // A biased randomized insertion order (Amenta, Choi and Rote): rounds of growing
  // size drawn by a seeded shuffle, a round the last eighth (ROUND_RATIO) of what is
  // left, down to 64 points (ROUND_FROM), as in CGAL's spatial sort; inside a round
  // the points go by id, which makeUniquePoints() numbers along a Morton curve, so
  // each walk starts near its point without a sort (CGAL sorts each round along a
  // Hilbert curve: 0.17 s on a million points, for walks a little shorter). The
  // order changes the time only: the triangulation is unique.
  constexpr double ROUND_RATIO = 0.125;
  constexpr int ROUND_FROM = 64;
  std::vector<int> round_end{n};
  while (round_end.back() >= ROUND_FROM)
    round_end.push_back(static_cast<int>(double(round_end.back()) * ROUND_RATIO));
  std::reverse(round_end.begin(), round_end.end());
  std::vector<int> order(n);
  {
    for (int i = 0; i < n; ++i)
      order[i] = i;
    boost::rand48 random;
    boost::random_number_generator<boost::rand48, std::ptrdiff_t> rng(random);
    CGAL::cpp98::random_shuffle(order.begin(), order.end(), rng);
    // Per point its round, then the rounds one after another, each by id.
    std::vector<std::uint8_t> round(n);
    for (int k = 0, r = 0; k < n; ++k) {
      while (k >= round_end[r])
        ++r;
      round[order[k]] = static_cast<std::uint8_t>(r);
    }
    countingSort(
        n,
        round_end.size(),
        threads,
        [&](std::size_t i) { return round[i]; },
        [&](std::size_t i, std::uint32_t place) {
          order[place] = static_cast<int>(i);
        });
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

  // The points left to insert, and where the rounds begin among them; a round long
  // enough is cut below into a stretch per thread.
  std::vector<int> rest;
  rest.reserve(input.size());
  std::vector<std::size_t> rounds{0}; // in rest
  for (int k = 2, r = 0; k < n; ++k) {
    for (; k >= round_end[r]; ++r)
      rounds.push_back(rest.size());
    if (k != third && k != fourth)
      rest.push_back(order[k]);
  }
  rounds.push_back(rest.size());
  const std::array<int, 4> tetrahedron{order[0], order[1], order[third], order[fourth]};
  std::vector<int>().swap(order);

  // About 7 cells per point in a volume, up to 15 on a sampled surface: sized
  // ahead, the cells cost no memory until they are used.
  cells.resize(std::size_t(n) * 16 + 64);
  SharedCells shared(cells);
  shared.state.assign(cells.size(), SharedCells::DEAD);
  Builder main(points, shared, 0, false);
  main.start(tetrahedron);
  for (std::size_t r = 0; r + 1 < rounds.size(); ++r)
    insertRound(points, rest, rounds[r], rounds[r + 1], threads, shared, main);
  main.finish();
  cells.resize(std::min(shared.used.load(), cells.size()));
  return 3;
}

} // namespace detail
} // namespace cocone
} // namespace pcl
