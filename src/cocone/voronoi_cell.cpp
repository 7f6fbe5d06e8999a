/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/voronoi_cell.h>

#include "allocator.h"
#include "edge_sort.h"
#include "points.h"

#include <algorithm>
#include <cmath>
#include <mutex>

namespace pcl {
namespace cocone {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

using detail::isFinite;
using detail::lexLess;

/** Outward unit normal of the hull facet f (ids ascending) whose outside is on the
 * side \a outward (CellView::outwardSide()). Only the sign depends on it: the same
 * bits from either cell. */
Eigen::Vector3d
outwardNormal(const std::vector<Eigen::Vector3d>& P,
              const std::array<int, 3>& f,
              int outward)
{
  Eigen::Vector3d n = (P[f[1]] - P[f[0]]).cross(P[f[2]] - P[f[0]]);
  if (outward < 0)
    n = -n;
  const double len = n.norm();
  return len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

/** Gathers VoronoiCells::nearest: per vertex the nearest Delaunay neighbours offered
 * so far, ties by id, with their squared distances in float beside them (the order
 * only has to be reproducible). Most offers are of a neighbour too far or already
 * kept (several cells stand for an edge): both are rejected without a search. */
class NearestNeighbours {
public:
  static constexpr int K = VoronoiCells::NEAREST;

  /** Fill \a ids, one list per vertex, -1 padded. */
  NearestNeighbours(const std::vector<Eigen::Vector3d>& points,
                    std::vector<std::array<int, K>>& ids)
  : P_(points), ids_(ids)
  {
    std::array<int, K> none;
    none.fill(-1);
    ids_.assign(P_.size(), none);
    std::array<float, K> far;
    far.fill(std::numeric_limits<float>::infinity());
    d2_.assign(P_.size(), far);
  }

  /** Squared length of the edge vw, as the lists compare it: the same bits from
   * either end. */
  float
  distance2(int v, int w) const
  {
    return static_cast<float>((P_[w] - P_[v]).squaredNorm());
  }

  /** Offer w, joined to v by a Delaunay edge of squared length d2, to the list of
   * v. */
  void
  offer(int v, int w, float d2)
  {
    auto& d2s = d2_[v];
    if (d2 > d2s[K - 1])
      return;
    auto& ids = ids_[v];
    bool kept = false; // one vector compare
    for (int k = 0; k < K; ++k)
      kept |= ids[k] == w;
    if (kept)
      return;
    int k = K;
    while (k > 0 && (d2 < d2s[k - 1] || (d2 == d2s[k - 1] && w < ids[k - 1])))
      --k;
    if (k == K)
      return;
    for (int j = K - 1; j > k; --j) {
      d2s[j] = d2s[j - 1];
      ids[j] = ids[j - 1];
    }
    d2s[k] = d2;
    ids[k] = w;
  }

  /** Fetch the list of v into the cache. */
  void
  prefetch(int v) const
  {
    __builtin_prefetch(&ids_[v].front()); // a list may straddle two cache lines
    __builtin_prefetch(&ids_[v].back());
    __builtin_prefetch(&d2_[v].front());
    __builtin_prefetch(&d2_[v].back());
  }

  /** Free the distances; the lists stay. */
  void
  release()
  {
    detail::LargeVector<std::array<float, K>>().swap(d2_);
  }

private:
  const std::vector<Eigen::Vector3d>& P_;
  std::vector<std::array<int, K>>& ids_;
  detail::LargeVector<std::array<float, K>> d2_;
};

/** Coplanar points: every Voronoi cell is a prism over the planar Voronoi polygon. */
VoronoiCells
planarCells(const Triangulation& dt, double cocone_angle)
{
  const auto& P = dt.points;
  const std::size_t n = P.size();
  VoronoiCells vc;
  vc.on_hull.assign(n, 0);
  detail::LargeVector<double> radius(n, 0.0);
  std::array<int, 3> first{std::numeric_limits<int>::max(), 0, 0};
  NearestNeighbours nearest(P, vc.nearest);
  forEachCell(
      dt, CellView::CIRCUMCENTER | CellView::FACETS, 1, [&](const CellView& cell, int) {
        for (int i = 0; i < 3; ++i) {
          const int v = cell.v[i], a = cell.v[(i + 1) % 3], b = cell.v[(i + 2) % 3];
          nearest.offer(v, a, nearest.distance2(v, a));
          nearest.offer(v, b, nearest.distance2(v, b));
          radius[v] = std::max(radius[v], (cell.circumcenter - P[v]).norm());
          // An outline edge: its two vertices have unbounded planar cells.
          if (cell.facet[i] == FacetRole::HULL) {
            vc.on_hull[cell.v[(i + 1) % 3]] = 1;
            vc.on_hull[cell.v[(i + 2) % 3]] = 1;
          }
        }
        // The dual of a planar triangle is the line through its circumcenter along the
        // normal; it passes through the plane, where every co-cone contains it.
        const auto f = detail::oppositeFacet(cell.v, 3).ids;
        vc.triangles.push_back({f, 7});
        first = std::min(first, f);
      });
  // Plane normal from the triangle of lowest ids, signed canonically.
  Eigen::Vector3d normal =
      (P[first[1]] - P[first[0]]).cross(P[first[2]] - P[first[0]]).normalized();
  for (int k = 0; k < 3; ++k)
    if (normal[k] != 0.0) {
      if (normal[k] < 0.0)
        normal = -normal;
      break;
    }
  // Both poles are at infinity along the normal: h+ = h- = infinity. The co-cone of
  // p reaches r / sin(cocone angle) at a polygon corner at distance r.
  vc.pole.assign(n, normal);
  vc.height_plus.assign(n, INF);
  vc.height_minus.assign(n, INF);
  const double s = std::sin(cocone_angle);
  vc.width.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    vc.width[v] = vc.on_hull[v] ? INF : radius[v] / s;
  nearest.release();
  std::sort(vc.triangles.begin(),
            vc.triangles.end(),
            [](const CoconeTriangle& a, const CoconeTriangle& b) { return a.v < b.v; });
  return vc;
}

/** Per corner of a cell, the bits of its three edges in CellView::edges. */
constexpr std::array<unsigned, 4> EDGES_AT = [] {
  std::array<unsigned, 4> at{};
  for (unsigned e = 0; e < 6; ++e)
    for (const int i : CellView::EDGE_ENDS[e])
      at[i] |= 1u << e;
  return at;
}();

/** Where a point y lies from p, seen along the pole line: its component along the
 * pole, and (along^2 - c^2 |y - p|^2, c the co-cone angle's cosine) whether it is off
 * the co-cone (> 0), in one nappe of the double cone around the pole line. */
struct ConeSide {
  double along, off;
};

ConeSide
coneSide(double along, double length2, double c2)
{
  return {along, along * along - c2 * length2};
}

/** Both ends of a segment in one nappe, which is convex: the segment misses the
 * co-cone. (Off the co-cone, along is not 0.) */
bool
inOneNappe(const ConeSide& a, const ConeSide& b)
{
  return a.off > 0.0 && b.off > 0.0 && (a.along > 0.0) == (b.along > 0.0);
}

/** Raise *target to x atomically. */
void
atomicMax(double* target, double x)
{
  double seen;
  __atomic_load(target, &seen, __ATOMIC_RELAXED);
  while (x > seen && !__atomic_compare_exchange(
                         target, &seen, &x, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
  }
}

} // namespace

CoconeHit
intersectCocone(const Eigen::Vector3d& p,
                const Eigen::Vector3d& pole,
                double cos_angle,
                const Eigen::Vector3d& a,
                const Eigen::Vector3d& d,
                bool ray)
{
  // A segment is followed from its end nearer to p (a on a tie): where it crosses
  // the co-cone near p, a far end (a flat cell's circumcenter lies thousands of
  // spacings away) would drown the crossing in the quadratic's rounding.
  if (!ray) {
    const Eigen::Vector3d b = a + d;
    if ((b - p).squaredNorm() < (a - p).squaredNorm())
      return intersectCocone(p, pole, cos_angle, b, -d, false);
  }
  // f(t) = ((y - p).u)^2 - c^2 |y - p|^2 <= 0 with y = a + t d.
  const Eigen::Vector3d e = a - p;
  const double c2 = cos_angle * cos_angle;
  const double eu = e.dot(pole), du = d.dot(pole);
  const double ee = e.squaredNorm(), dd = d.squaredNorm(), ed = e.dot(d);
  const ConeSide start = coneSide(eu, ee, c2);
  const double A = du * du - c2 * dd;
  const double B = 2.0 * (eu * du - c2 * ed);
  const double C = start.off;
  const double t_max = ray ? INF : 1.0;

  CoconeHit hit;
  // Most Voronoi edges lie in one nappe of the double cone around the pole line, the
  // complement of the co-cone: both ends there (for a ray, its start and its
  // direction), on the same side of p.
  if (inOneNappe(start, ray ? ConeSide{du, A} : ConeSide{eu + du, A + B + C}))
    return hit;
  const auto consider = [&](double t) {
    if (!(t >= 0.0 && t <= t_max))
      return;
    hit.meets = true;
    hit.max_distance = std::max(hit.max_distance,
                                std::sqrt(std::max(0.0, ee + t * (2.0 * ed + t * dd))));
  };
  if (C <= 0.0)
    consider(0.0);
  if (!ray && A + B + C <= 0.0)
    consider(1.0);
  // Where the edge enters or leaves the co-cone: the roots of f, computed stably.
  if (A != 0.0) {
    const double disc = B * B - 4.0 * A * C;
    if (disc >= 0.0) {
      const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
      consider(q / A);
      if (q != 0.0)
        consider(C / q);
    }
  }
  else if (B != 0.0)
    consider(-C / B);
  // A ray whose far part lies in the co-cone makes it unbounded.
  if (ray && (A < 0.0 || (A == 0.0 && (B < 0.0 || (B == 0.0 && C <= 0.0))))) {
    hit.meets = true;
    hit.max_distance = INF;
  }
  return hit;
}

VoronoiCells
computeVoronoiCells(const Triangulation& dt,
                    double cocone_angle,
                    unsigned int num_threads)
{
  VoronoiCells vc = computePoles(dt, cocone_angle, num_threads);
  computeCocones(dt, cocone_angle, num_threads, vc);
  return vc;
}

VoronoiCells
computePoles(const Triangulation& dt, double cocone_angle, unsigned int num_threads)
{
  if (dt.dimension == 2 && dt.number_of_cells > 0)
    return planarCells(dt, cocone_angle);
  VoronoiCells vc;
  if (dt.dimension != 3)
    return vc;

  const auto& P = dt.points;
  const std::size_t n = P.size();
  const int threads = resolveThreads(num_threads);
  vc.on_hull.assign(n, 0);

  // Pass 1 over the cells: the positive pole, the farthest Voronoi vertex (ties
  // broken by position, so the choice does not depend on the visiting order), and
  // the nearest neighbours, offered the edges each cell stands for (a third of the
  // offers of all six edges of every cell, most of which repeat an edge kept
  // already). With several threads a vertex's record is updated under its own spin
  // lock. The squared distance and the vertex are kept where h+ and the pole go.
  std::vector<double>& far2 = vc.height_plus;
  std::vector<Eigen::Vector3d>& far = vc.pole;
  far2.assign(n, -1.0);
  far.assign(n, Eigen::Vector3d::Zero());
  std::vector<std::uint8_t> lock(threads > 1 ? n : 0, 0);
  NearestNeighbours nearest(P, vc.nearest);
  forEachCell(
      dt,
      CellView::CIRCUMCENTER | CellView::EDGES,
      threads,
      [&](const CellView& cell, int) {
        for (const int a : cell.ahead)
          if (a >= 0) {
            nearest.prefetch(a);
            __builtin_prefetch(&far2[a]);
            __builtin_prefetch(&far[a]);
            __builtin_prefetch(&P[a]);
          }
        const Eigen::Vector3d& cc = cell.circumcenter;
        const bool finite = isFinite(cc);
        // The lengths of the edges offered, each to both its ends.
        std::array<std::array<float, 4>, 4> edge2;
        for (int e = 0; e < 6; ++e)
          if (cell.edges & (1u << e)) {
            const int i = CellView::EDGE_ENDS[e][0], j = CellView::EDGE_ENDS[e][1];
            edge2[i][j] = edge2[j][i] = nearest.distance2(cell.v[i], cell.v[j]);
          }
        for (int i = 0; i < 4; ++i) {
          const int v = cell.v[i];
          const double d2 = (cc - P[v]).squaredNorm();
          if (threads > 1)
            while (__atomic_test_and_set(&lock[v], __ATOMIC_ACQUIRE)) {
            }
          // The offered edges at v, in the order of EDGE_ENDS.
          for (unsigned at = cell.edges & EDGES_AT[i]; at != 0; at &= at - 1) {
            const auto& ends = CellView::EDGE_ENDS[__builtin_ctz(at)];
            const int j = ends[0] + ends[1] - i;
            nearest.offer(v, cell.v[j], edge2[i][j]);
          }
          if (finite && (d2 > far2[v] || (d2 == far2[v] && lexLess(far[v], cc)))) {
            far2[v] = d2;
            far[v] = cc;
          }
          if (threads > 1)
            __atomic_clear(&lock[v], __ATOMIC_RELEASE);
        }
      });
  std::vector<std::uint8_t>().swap(lock);
  nearest.release();

  // The convex hull, its facets once each: per hull vertex the sum of the outward
  // normals of its hull facets, the pole of its unbounded Voronoi cell. The sum is
  // taken in fixed point: exact, so it does not depend on the facets' order (the
  // order the triangulation made them in), and 2^-32 is far finer than a pole
  // direction needs. (A sampled closed surface can have half its points on the
  // hull.)
  constexpr double FIXED = 4294967296.0;
  detail::LargeVector<int> slot(n, -1);
  std::vector<std::array<std::int64_t, 3>> sum;
  forEachHullFacet(dt, [&](const HullFacet& h) {
    const Eigen::Vector3d normal = outwardNormal(P, h.v, h.outward);
    std::array<std::int64_t, 3> fixed;
    for (int m = 0; m < 3; ++m)
      fixed[m] = std::llround(normal[m] * FIXED);
    for (const int a : h.v) {
      if (slot[a] < 0) {
        slot[a] = static_cast<int>(sum.size());
        sum.push_back({0, 0, 0});
        vc.on_hull[a] = 1;
      }
      for (int m = 0; m < 3; ++m)
        sum[slot[a]][m] += fixed[m];
    }
  });

  for (std::size_t v = 0; v < n; ++v) {
    const Eigen::Vector3d normal =
        vc.on_hull[v] ? Eigen::Vector3d(static_cast<double>(sum[slot[v]][0]),
                                        static_cast<double>(sum[slot[v]][1]),
                                        static_cast<double>(sum[slot[v]][2]))
                      : Eigen::Vector3d::Zero();
    if (normal != Eigen::Vector3d::Zero()) {
      far2[v] = INF;
      far[v] = normal.normalized();
    }
    else if (far2[v] > 0.0) {
      far2[v] = std::sqrt(far2[v]);
      far[v] = (far[v] - P[v]) / far2[v];
    }
    else {
      far2[v] = INF;
      far[v].setZero();
    }
  }
  return vc;
}

void
computeCocones(const Triangulation& dt,
               double cocone_angle,
               unsigned int num_threads,
               VoronoiCells& vc)
{
  if (dt.dimension != 3)
    return; // done in one pass with the poles (dimension 2), or nothing to do
  const auto& P = dt.points;
  const std::size_t n = P.size();
  const int threads = resolveThreads(num_threads);

  // Pass 2: the negative pole (the farthest Voronoi vertex on the other side of p),
  // then the width and the co-cone triangles over the Voronoi edges, i.e. over the
  // Delaunay facets, each visited from one of its cells. The maxima are taken with
  // atomic updates and each thread collects its triangles; the sort below fixes
  // their order.
  const double cos_angle = std::cos(cocone_angle);
  const double c2 = cos_angle * cos_angle;
  // The squared distance to v- and the width are raised in place.
  std::vector<double>& neg2 = vc.height_minus;
  std::vector<double>& width = vc.width;
  neg2.assign(n, 0.0);
  width.assign(n, 0.0);
  detail::LargeVector<std::uint8_t> met(n, 0);
  // Collected straight into the result, a batch per thread at a time: a sampled
  // surface has about two per point, which the reservation mostly holds, and no
  // second copy of them is ever made.
  vc.triangles.reserve(n * 9 / 4);
  std::vector<std::vector<CoconeTriangle>> batch(threads);
  std::mutex appending;
  const auto append = [&](int thread) {
    const std::lock_guard<std::mutex> lock(appending);
    vc.triangles.insert(vc.triangles.end(), batch[thread].begin(), batch[thread].end());
    batch[thread].clear();
  };
  forEachCell(
      dt,
      CellView::CIRCUMCENTER | CellView::NEIGHBORS,
      threads,
      [&](const CellView& cell, int thread) {
        for (const int a : cell.ahead)
          if (a >= 0) {
            __builtin_prefetch(&P[a]);
            __builtin_prefetch(&vc.pole[a]);
            __builtin_prefetch(&neg2[a]);
            __builtin_prefetch(&width[a]);
          }
        // Per corner: where the Voronoi vertex lies from it (coneSide), a
        // candidate for the negative pole and one end of the Voronoi edges
        // of the corner's facets.
        const Eigen::Vector3d& cc = cell.circumcenter;
        const bool finite = isFinite(cc);
        std::array<ConeSide, 4> side{};
        if (finite)
          for (int j = 0; j < 4; ++j) {
            const int v = cell.v[j];
            const Eigen::Vector3d y = cc - P[v];
            const double yy = y.squaredNorm();
            side[j] = coneSide(y.dot(vc.pole[v]), yy, c2);
            if (side[j].along < 0.0)
              atomicMax(&neg2[v], yy);
          }
        for (int i = 0; i < 4; ++i) {
          if (cell.facet[i] == FacetRole::SHARED)
            continue;
          const bool ray = cell.facet[i] == FacetRole::HULL;
          // Most Voronoi edges have both ends in one nappe of each of their
          // corners' double cones, which is convex: they miss the co-cones.
          // intersectCocone rejects them so too, but only after setting up
          // the edge; here the ends' values above decide (the same bits at
          // the edge's first end, its far end read directly instead of off
          // the expanded quadratic). The corners left get the whole test.
          unsigned test = 0xfu & ~(1u << i);
          const Eigen::Vector3d& other = cell.neighbor_circumcenter[i];
          if (!ray) {
            if (!finite || !isFinite(other))
              continue;
            for (int j = 0; j < 4; ++j) {
              if (j == i || !(side[j].off > 0.0))
                continue; // in the co-cone: no need to look at the far end
              const int v = cell.v[j];
              const Eigen::Vector3d y = other - P[v];
              if (inOneNappe(side[j], coneSide(y.dot(vc.pole[v]), y.squaredNorm(), c2)))
                test &= ~(1u << j);
            }
            if (!test)
              continue;
          }
          const auto f = detail::oppositeFacet(cell.v, i).ids;
          Eigen::Vector3d a = cc, d;
          if (ray) {
            d = outwardNormal(P, f, cell.outwardSide(i));
            // An unbounded Voronoi edge going to the negative side puts
            // v- at infinity.
            for (const int v : f)
              if (d.dot(vc.pole[v]) < 0.0)
                atomicMax(&neg2[v], INF);
          }
          else {
            // Orient the segment canonically so the test is bitwise
            // reproducible.
            Eigen::Vector3d b = other;
            if (lexLess(b, a))
              std::swap(a, b);
            d = b - a;
          }
          if (!isFinite(a) || !isFinite(d))
            continue;
          std::uint8_t meets = 0;
          for (int k = 0; k < 3; ++k) {
            const int v = f[k];
            int j = 0;
            while (cell.v[j] != v)
              ++j;
            if (!(test >> j & 1u))
              continue;
            const CoconeHit hit =
                intersectCocone(P[v], vc.pole[v], cos_angle, a, d, ray);
            if (hit.meets) {
              meets |= static_cast<std::uint8_t>(1u << k);
              atomicMax(&width[v], hit.max_distance);
              if (!met[v])
                __atomic_store_n(&met[v], 1, __ATOMIC_RELAXED);
            }
          }
          if (meets) {
            batch[thread].push_back({f, meets});
            if (batch[thread].size() == 4096)
              append(thread);
          }
        }
      });
  for (std::size_t v = 0; v < n; ++v)
    vc.height_minus[v] = std::sqrt(neg2[v]);

  for (int thread = 0; thread < threads; ++thread)
    append(thread);
  // A co-cone that meets no Voronoi edge tells nothing about flatness: not flat.
  for (std::size_t v = 0; v < n; ++v)
    if (!met[v])
      vc.width[v] = INF;
  detail::sortByVertexIds(
      vc.triangles, n, [](const CoconeTriangle& t) { return t.v; }, threads);
}

} // namespace cocone
} // namespace pcl
