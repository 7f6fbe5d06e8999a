/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/voronoi_cell.h>

#include "points.h"
#ifdef _OPENMP
#include <omp.h>
#endif

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

/** Coplanar points: every Voronoi cell is a prism over the planar Voronoi polygon. */
VoronoiCells
planarCells(const Triangulation& dt, double cocone_angle)
{
  const auto& P = dt.points;
  const std::size_t n = P.size();
  VoronoiCells vc;
  // Plane normal from the first triangle, signed canonically for reproducibility.
  const auto f0 = facetIds(dt.cells.front(), 3);
  Eigen::Vector3d normal =
      (P[f0[1]] - P[f0[0]]).cross(P[f0[2]] - P[f0[0]]).normalized();
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
  vc.on_hull.assign(n, 0);
  std::vector<double> radius(n, 0.0);
  for (std::size_t c = 0; c < dt.cells.size(); ++c) {
    const auto& cell = dt.cells[c];
    for (int i = 0; i < 3; ++i) {
      const int v = cell[i];
      radius[v] = std::max(radius[v], (dt.circumcenters[c] - P[v]).norm());
      // An outline edge: its two vertices have unbounded planar cells.
      if (dt.neighbors[c][i] < 0) {
        vc.on_hull[cell[(i + 1) % 3]] = 1;
        vc.on_hull[cell[(i + 2) % 3]] = 1;
      }
    }
    // The dual of a planar triangle is the line through its circumcenter along the
    // normal; it passes through the plane, where every co-cone contains it.
    vc.triangles.push_back({facetIds(cell, 3), 7});
  }
  const double s = std::sin(cocone_angle);
  vc.width.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    vc.width[v] = vc.on_hull[v] ? INF : radius[v] / s;
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

/** Replace *target by x atomically if *target is -1 or less(*target, x). */
template <typename Less>
void
atomicRaise(int* target, int x, const Less& less)
{
  int seen = __atomic_load_n(target, __ATOMIC_RELAXED);
  while ((seen < 0 || less(seen, x)) &&
         !__atomic_compare_exchange_n(
             target, &seen, x, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
  }
}

} // namespace

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
  if (dt.dimension == 2 && !dt.cells.empty())
    return planarCells(dt, cocone_angle);
  VoronoiCells vc;
  if (dt.dimension != 3)
    return vc;

  const auto& P = dt.points;
  const auto& cc = dt.circumcenters;
  const std::size_t n = P.size(), m = dt.cells.size();
  vc.on_hull.assign(n, 0);

  // Hull facets, summed per vertex in facet order so the sum is reproducible.
  struct HullFacet {
    std::array<int, 3> f;
    Eigen::Vector3d normal;
  };
  std::vector<HullFacet> hull;
  for (std::size_t c = 0; c < m; ++c)
    for (int i = 0; i < 4; ++i)
      if (dt.neighbors[c][i] < 0) {
        const auto f = facetIds(dt.cells[c], i);
        hull.push_back({f, outwardNormal(P, f, dt.cells[c][i])});
      }
  std::sort(hull.begin(), hull.end(), [](const HullFacet& a, const HullFacet& b) {
    return a.f < b.f;
  });
  std::vector<Eigen::Vector3d> hull_sum(n, Eigen::Vector3d::Zero());
  for (const auto& h : hull)
    for (const int v : h.f) {
      hull_sum[v] += h.normal;
      vc.on_hull[v] = 1;
    }

  // The per-vertex maxima below are taken with atomic updates, so the cells can be
  // visited in parallel: a maximum does not depend on the order of the updates.
  const int threads = resolveThreads(num_threads);

  // Positive pole: the farthest Voronoi vertex (ties broken by position).
  std::vector<std::uint64_t> far2(n, 0); // bits of non-negative doubles
  std::vector<int> far_cell(n, -1);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(m); ++c) {
    if (!isFinite(cc[c]))
      continue;
    for (const int v : dt.cells[c])
      atomicMax(&far2[v], (cc[c] - P[v]).squaredNorm());
  }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(m); ++c) {
    if (!isFinite(cc[c]))
      continue;
    for (const int v : dt.cells[c])
      if (bitsOf((cc[c] - P[v]).squaredNorm()) == far2[v])
        atomicRaise(&far_cell[v], static_cast<int>(c), [&](int a, int b) {
          return lexLess(cc[a], cc[b]) || (cc[a] == cc[b] && a < b);
        });
  }
  vc.pole.assign(n, Eigen::Vector3d::Zero());
  vc.height_plus.assign(n, INF);
  for (std::size_t v = 0; v < n; ++v) {
    const double d2 = doubleOf(far2[v]);
    if (vc.on_hull[v] && hull_sum[v].norm() > 0.0)
      vc.pole[v] = hull_sum[v].normalized();
    else if (far_cell[v] >= 0 && d2 > 0.0) {
      vc.height_plus[v] = std::sqrt(d2);
      vc.pole[v] = (cc[far_cell[v]] - P[v]) / vc.height_plus[v];
    }
  }

  // Negative pole: the farthest Voronoi vertex on the other side of p.
  std::vector<std::uint64_t> neg2(n, 0);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(m); ++c) {
    if (!isFinite(cc[c]))
      continue;
    for (const int v : dt.cells[c]) {
      const Eigen::Vector3d y = cc[c] - P[v];
      if (y.dot(vc.pole[v]) < 0.0)
        atomicMax(&neg2[v], y.squaredNorm());
    }
  }
  vc.height_minus.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    vc.height_minus[v] = std::sqrt(doubleOf(neg2[v]));
  // An unbounded Voronoi edge going to the negative side puts v- at infinity.
  for (const auto& h : hull)
    for (const int v : h.f)
      if (h.normal.dot(vc.pole[v]) < 0.0)
        vc.height_minus[v] = INF;

  // Width and the co-cone triangles: one pass over the Voronoi edges, i.e. over the
  // Delaunay triangles, each visited from its lower-numbered cell. Each thread
  // collects its triangles; the sort below fixes their order.
  const double cos_angle = std::cos(cocone_angle);
  std::vector<std::uint64_t> width(n, 0);
  std::vector<std::uint8_t> met(n, 0);
  std::vector<std::vector<CoconeTriangle>> found(threads);
#pragma omp parallel num_threads(threads)
  {
#ifdef _OPENMP
    auto& mine = found[omp_get_thread_num()];
#else
    auto& mine = found[0];
#endif
#pragma omp for schedule(static)
    for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(m); ++c) {
      for (int i = 0; i < 4; ++i) {
        const int other = dt.neighbors[c][i];
        if (other >= 0 && other < c)
          continue;
        const auto f = facetIds(dt.cells[c], i);
        Eigen::Vector3d a = cc[c], d;
        const bool ray = other < 0;
        if (ray)
          d = outwardNormal(P, f, dt.cells[c][i]);
        else {
          // Orient the segment canonically so the test is bitwise reproducible.
          Eigen::Vector3d b = cc[other];
          if (lexLess(b, a))
            std::swap(a, b);
          d = b - a;
        }
        if (!isFinite(a) || !isFinite(d))
          continue;
        std::uint8_t meets = 0;
        for (int k = 0; k < 3; ++k) {
          const int v = f[k];
          const CoconeHit hit = intersectCocone(P[v], vc.pole[v], cos_angle, a, d, ray);
          if (hit.meets) {
            meets |= static_cast<std::uint8_t>(1u << k);
            atomicMax(&width[v], hit.max_distance);
            if (!met[v])
              __atomic_store_n(&met[v], 1, __ATOMIC_RELAXED);
          }
        }
        if (meets)
          mine.push_back({f, meets});
      }
    }
  }
  std::size_t total = 0;
  for (const auto& t : found)
    total += t.size();
  vc.triangles.reserve(total);
  for (auto& t : found) {
    vc.triangles.insert(vc.triangles.end(), t.begin(), t.end());
    std::vector<CoconeTriangle>().swap(t);
  }
  vc.width.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    vc.width[v] = met[v] ? doubleOf(width[v]) : -INF;
  // A co-cone that meets no Voronoi edge tells nothing about flatness: not flat.
  for (auto& w : vc.width)
    if (w < 0.0)
      w = INF;
  std::sort(vc.triangles.begin(),
            vc.triangles.end(),
            [](const CoconeTriangle& a, const CoconeTriangle& b) { return a.v < b.v; });
  return vc;
}

} // namespace cocone
} // namespace pcl
