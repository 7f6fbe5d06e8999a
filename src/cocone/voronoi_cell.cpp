/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/voronoi_cell.h>

#include "points.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace pcl {
namespace cocone {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

using detail::isFinite;
using detail::lexLess;

/** The facet of cell c opposite its vertex i, as ascending vertex ids. */
std::array<int, 3>
facetIds(const std::array<int, 4>& cell, int i)
{
  std::array<int, 3> f;
  for (int k = 0, j = 0; k < 4; ++k)
    if (k != i)
      f[j++] = cell[k];
  std::sort(f.begin(), f.end());
  return f;
}

/** Outward unit normal of the hull facet f of a cell whose remaining vertex is o. */
Eigen::Vector3d
outwardNormal(const std::vector<Eigen::Vector3d>& P, const std::array<int, 3>& f, int o)
{
  Eigen::Vector3d n = (P[f[1]] - P[f[0]]).cross(P[f[2]] - P[f[0]]);
  if (n.dot(P[o] - P[f[0]]) > 0.0)
    n = -n;
  const double len = n.norm();
  return len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

/** Gathers VoronoiCells::nearest: per vertex the nearest Delaunay neighbours offered
 * so far, with their squared distances in float beside them (the order only has to
 * be reproducible). */
class NearestNeighbours {
public:
  static constexpr int K = VoronoiCells::NEAREST;

  /** Fill \a ids, one list per vertex, -1 padded. */
  NearestNeighbours(std::vector<std::array<int, K>>& ids, std::size_t n) : ids_(ids)
  {
    std::array<int, K> none;
    none.fill(-1);
    ids_.assign(n, none);
    std::array<float, K> far;
    far.fill(std::numeric_limits<float>::infinity());
    d2_.assign(n, far);
  }

  /** Offer w, joined to v by a Delaunay edge, to the list of v. */
  void
  offer(const std::vector<Eigen::Vector3d>& P, int v, int w)
  {
    const float d2 = static_cast<float>((P[w] - P[v]).squaredNorm());
    auto& ids = ids_[v];
    auto& d2s = d2_[v];
    if (d2 > d2s[K - 1]) // the common case: farther than the K kept
      return;
    const auto after = [&](int k) {
      return d2 < d2s[k] || (d2 == d2s[k] && w < ids[k]);
    };
    int k = K;
    while (k > 0 && after(k - 1))
      --k;
    // Already kept: it sits just before the insertion point (same distance, same id).
    if (k == K || (k > 0 && ids[k - 1] == w))
      return;
    for (int j = K - 1; j > k; --j) {
      d2s[j] = d2s[j - 1];
      ids[j] = ids[j - 1];
    }
    d2s[k] = d2;
    ids[k] = w;
  }

  /** Free the distances; the lists stay. */
  void
  release()
  {
    std::vector<std::array<float, K>>().swap(d2_);
  }

private:
  std::vector<std::array<int, K>>& ids_;
  std::vector<std::array<float, K>> d2_;
};

/** Coplanar points: every Voronoi cell is a prism over the planar Voronoi polygon. */
VoronoiCells
planarCells(const Triangulation& dt, double cocone_angle)
{
  const auto& P = dt.points;
  const std::size_t n = P.size();
  VoronoiCells vc;
  vc.on_hull.assign(n, 0);
  std::vector<double> radius(n, 0.0);
  std::array<int, 3> first{std::numeric_limits<int>::max(), 0, 0};
  NearestNeighbours nearest(vc.nearest, n);
  forEachCell(
      dt, CellView::CIRCUMCENTER | CellView::FACETS, 1, [&](const CellView& cell, int) {
        for (int i = 0; i < 3; ++i) {
          const int v = cell.v[i];
          nearest.offer(P, v, cell.v[(i + 1) % 3]);
          nearest.offer(P, v, cell.v[(i + 2) % 3]);
          radius[v] = std::max(radius[v], (cell.circumcenter - P[v]).norm());
          // An outline edge: its two vertices have unbounded planar cells.
          if (cell.facet[i] == FacetRole::HULL) {
            vc.on_hull[cell.v[(i + 1) % 3]] = 1;
            vc.on_hull[cell.v[(i + 2) % 3]] = 1;
          }
        }
        // The dual of a planar triangle is the line through its circumcenter along the
        // normal; it passes through the plane, where every co-cone contains it.
        const auto f = facetIds(cell.v, 3);
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

/** Bits of a non-negative double: they order as the values do (+inf included). */
std::uint64_t
bitsOf(double x)
{
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof(b));
  return b;
}

double
doubleOf(std::uint64_t b)
{
  double x;
  std::memcpy(&x, &b, sizeof(x));
  return x;
}

/** Raise *target to x (x >= 0) atomically. */
void
atomicMax(std::uint64_t* target, double x)
{
  const std::uint64_t bits = bitsOf(x);
  std::uint64_t seen = __atomic_load_n(target, __ATOMIC_RELAXED);
  while (bits > seen &&
         !__atomic_compare_exchange_n(
             target, &seen, bits, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
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
  // f(t) = ((y - p).u)^2 - c^2 |y - p|^2 <= 0 with y = a + t d.
  const Eigen::Vector3d e = a - p;
  const double eu = e.dot(pole), du = d.dot(pole);
  const double ee = e.squaredNorm(), dd = d.squaredNorm(), ed = e.dot(d);
  const double c2 = cos_angle * cos_angle;
  const double A = du * du - c2 * dd;
  const double B = 2.0 * (eu * du - c2 * ed);
  const double C = eu * eu - c2 * ee;
  const double t_max = ray ? INF : 1.0;

  CoconeHit hit;
  // Most Voronoi edges lie in one nappe of the double cone around the pole line, the
  // complement of the co-cone: both ends there (for a ray, its start and its
  // direction), on the same side of p. A nappe is convex, so the edge misses.
  const bool start_out = C > 0.0;
  const bool end_out = ray ? A > 0.0 : A + B + C > 0.0;
  const double end_side = ray ? du : eu + du;
  // (Outside the co-cone, neither eu nor end_side can be 0.)
  if (start_out && end_out && (eu > 0.0) == (end_side > 0.0))
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
  // broken by position, so the choice does not depend on the visiting order). With
  // several threads a vertex's record is updated under its own spin lock.
  std::vector<double> far2(n, -1.0);
  std::vector<Eigen::Vector3d> far(n);
  std::vector<std::uint8_t> lock(threads > 1 ? n : 0, 0);
  NearestNeighbours nearest(vc.nearest, n);
  forEachCell(dt, CellView::CIRCUMCENTER, threads, [&](const CellView& cell, int) {
    const Eigen::Vector3d& cc = cell.circumcenter;
    const bool finite = isFinite(cc);
    for (int i = 0; i < 4; ++i) {
      const int v = cell.v[i];
      const double d2 = (cc - P[v]).squaredNorm();
      if (threads > 1)
        while (__atomic_test_and_set(&lock[v], __ATOMIC_ACQUIRE)) {
        }
      for (int j = 1; j < 4; ++j)
        nearest.offer(P, v, cell.v[(i + j) % 4]);
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

  // The hull facets' outward normals, summed per vertex in facet order so that the
  // sum is reproducible.
  struct HullFacet {
    std::array<int, 3> f;
    Eigen::Vector3d normal;
  };
  std::vector<HullFacet> hull;
  for (const auto& h : hullFacets(dt)) {
    const std::array<int, 3> f{h[0], h[1], h[2]};
    hull.push_back({f, outwardNormal(P, f, h[3])});
  }
  std::vector<Eigen::Vector3d> hull_sum(n, Eigen::Vector3d::Zero());
  for (const auto& h : hull)
    for (const int v : h.f) {
      hull_sum[v] += h.normal;
      vc.on_hull[v] = 1;
    }
  vc.pole.assign(n, Eigen::Vector3d::Zero());
  vc.height_plus.assign(n, INF);
  for (std::size_t v = 0; v < n; ++v) {
    if (vc.on_hull[v] && hull_sum[v].norm() > 0.0)
      vc.pole[v] = hull_sum[v].normalized();
    else if (far2[v] > 0.0) {
      vc.height_plus[v] = std::sqrt(far2[v]);
      vc.pole[v] = (far[v] - P[v]) / vc.height_plus[v];
    }
  }
  std::vector<double>().swap(far2);
  std::vector<Eigen::Vector3d>().swap(far);
  std::vector<Eigen::Vector3d>().swap(hull_sum);

  // Pass 2: the negative pole (the farthest Voronoi vertex on the other side of p),
  // then the width and the co-cone triangles over the Voronoi edges, i.e. over the
  // Delaunay facets, each visited from one of its cells. The maxima are taken with
  // atomic updates and each thread collects its triangles; the sort below fixes
  // their order.
  const double cos_angle = std::cos(cocone_angle);
  std::vector<std::uint64_t> neg2(n, 0), width(n, 0); // bits of non-negative doubles
  std::vector<std::uint8_t> met(n, 0);
  std::vector<std::vector<CoconeTriangle>> found(threads);
  forEachCell(dt,
              CellView::CIRCUMCENTER | CellView::NEIGHBORS,
              threads,
              [&](const CellView& cell, int thread) {
                const Eigen::Vector3d& cc = cell.circumcenter;
                if (isFinite(cc))
                  for (const int v : cell.v) {
                    const Eigen::Vector3d y = cc - P[v];
                    if (y.dot(vc.pole[v]) < 0.0)
                      atomicMax(&neg2[v], y.squaredNorm());
                  }
                for (int i = 0; i < 4; ++i) {
                  if (cell.facet[i] == FacetRole::SHARED)
                    continue;
                  const auto f = facetIds(cell.v, i);
                  Eigen::Vector3d a = cc, d;
                  const bool ray = cell.facet[i] == FacetRole::HULL;
                  if (ray)
                    d = outwardNormal(P, f, cell.v[i]);
                  else {
                    // Orient the segment canonically so the test is bitwise
                    // reproducible.
                    Eigen::Vector3d b = cell.neighbor_circumcenter[i];
                    if (lexLess(b, a))
                      std::swap(a, b);
                    d = b - a;
                  }
                  if (!isFinite(a) || !isFinite(d))
                    continue;
                  std::uint8_t meets = 0;
                  for (int k = 0; k < 3; ++k) {
                    const int v = f[k];
                    const CoconeHit hit =
                        intersectCocone(P[v], vc.pole[v], cos_angle, a, d, ray);
                    if (hit.meets) {
                      meets |= static_cast<std::uint8_t>(1u << k);
                      atomicMax(&width[v], hit.max_distance);
                      if (!met[v])
                        __atomic_store_n(&met[v], 1, __ATOMIC_RELAXED);
                    }
                  }
                  if (meets)
                    found[thread].push_back({f, meets});
                }
              });
  vc.height_minus.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    vc.height_minus[v] = std::sqrt(doubleOf(neg2[v]));
  // An unbounded Voronoi edge going to the negative side puts v- at infinity.
  for (const auto& h : hull)
    for (const int v : h.f)
      if (h.normal.dot(vc.pole[v]) < 0.0)
        vc.height_minus[v] = INF;

  std::size_t total = 0;
  for (const auto& t : found)
    total += t.size();
  vc.triangles.reserve(total);
  for (auto& t : found) {
    vc.triangles.insert(vc.triangles.end(), t.begin(), t.end());
    std::vector<CoconeTriangle>().swap(t);
  }
  vc.width.resize(n);
  // A co-cone that meets no Voronoi edge tells nothing about flatness: not flat.
  for (std::size_t v = 0; v < n; ++v)
    vc.width[v] = met[v] ? doubleOf(width[v]) : INF;
  std::sort(vc.triangles.begin(),
            vc.triangles.end(),
            [](const CoconeTriangle& a, const CoconeTriangle& b) { return a.v < b.v; });
  return vc;
}

} // namespace cocone
} // namespace pcl
