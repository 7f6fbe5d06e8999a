/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Small helpers on points shared by the stages' sources (not installed).
 */

#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

inline bool
isFinite(const Eigen::Vector3d& p)
{
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

/** A neighbour more than this many local spacings away is across a hole or along
 * the convex hull, not a sample of the surface round a point: the sampling density
 * is assumed to change by less than this within a point's neighbourhood. */
constexpr double FAR_NEIGHBOUR = 10.0;

/** Nearest neighbours whose mean distance is a point's spacing (meanSpacing()). */
constexpr int SPACING_NEIGHBOURS = 6;

/** Mean distance from \a p to its nearest Delaunay neighbours \a list (nearest
 * first, -1 after the last), the first \a k of them, leaving out those more than
 * FAR_NEIGHBOUR times as far as their median: an edge across a hole or along the convex
 * hull is not one of the samples round p. Measured on a random terrain (1M points): a
 * rim point of a flat hole 30 spacings wide had 4 neighbours within 1.5 spacings and 2
 * at 270 and 1,000 (hull edges); their mean made the hole pass for sampled at its
 * own scale and the walk covered it with triangles 55 spacings long (3 of 6 holes;
 * at 100k and 300k points 3 and 1). At 10 or 20 none is covered, at 50 the 100k
 * terrain's are again; at 4 the casting's vertex set (faces sampled along their
 * outlines only) keeps 3 more loops, at 10 one more. */
template <std::size_t N>
double
meanNeighbourDistance(const std::vector<Eigen::Vector3d>& points,
                      const std::array<int, N>& list,
                      int p,
                      int k)
{
  std::array<double, N> d;
  int count = 0;
  for (; count < k && count < static_cast<int>(N) && list[count] >= 0; ++count)
    d[count] = (points[list[count]] - points[p]).norm();
  if (count == 0)
    return 0.0;
  const double bound = FAR_NEIGHBOUR * d[(count - 1) / 2];
  double sum = 0.0;
  int kept = 0;
  for (; kept < count && d[kept] <= bound; ++kept)
    sum += d[kept];
  return sum / kept;
}

/** The circumradius of triangle abc; infinite if it is degenerate. */
inline double
circumradius(const Eigen::Vector3d& a,
             const Eigen::Vector3d& b,
             const Eigen::Vector3d& c)
{
  const double twice_area = (b - a).cross(c - a).norm();
  if (twice_area <= 0.0)
    return std::numeric_limits<double>::infinity();
  return (b - c).norm() * (a - c).norm() * (a - b).norm() / (2.0 * twice_area);
}

/** The diameter of the median circumcircle of \a radii (circumradii of the triangles
 * at a loop's rim, reordered here): the scale of the sampling round a hole, which
 * classifyBorderLoops() and fillUndersampledHoles() measure it in. */
inline double
rimDiameter(std::vector<double>& radii)
{
  const auto middle = radii.begin() + static_cast<std::ptrdiff_t>(radii.size() / 2);
  std::nth_element(radii.begin(), middle, radii.end());
  return 2.0 * *middle;
}

/** Whether edge ab is at most \a reach times the larger local spacing of its ends
 * long: as short as the triangles of the sampling there. */
inline bool
withinReach(const std::vector<Eigen::Vector3d>& points,
            const std::vector<double>& spacing,
            double reach,
            int a,
            int b)
{
  const double longest = reach * std::max(spacing[a], spacing[b]);
  return (points[a] - points[b]).squaredNorm() <= longest * longest;
}

/** Whether every edge of \a t is withinReach(). */
template <typename Corners>
inline bool
triangleWithinReach(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<double>& spacing,
                    double reach,
                    const Corners& t)
{
  return withinReach(points, spacing, reach, t[0], t[1]) &&
         withinReach(points, spacing, reach, t[1], t[2]) &&
         withinReach(points, spacing, reach, t[2], t[0]);
}

/** Lexicographic order of coordinates: the canonical order for tie-breaks. */
inline bool
lexLess(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

/** Sort the first \a n (3 or 4) entries of \a a by \a key with compare-exchanges
 * (a sorting network): the per-cell and per-facet orders of the passes over the
 * cells, where a call of std::sort costs more than the sorting. */
template <typename Array, typename Key>
inline void
sortCorners(Array& a, int n, Key key)
{
  const auto order = [&](int i, int j) {
    if (key(a[j]) < key(a[i]))
      std::swap(a[i], a[j]);
  };
  if (n == 4) {
    order(0, 1);
    order(2, 3);
    order(0, 2);
    order(1, 3);
    order(1, 2);
  }
  else {
    order(0, 1);
    order(1, 2);
    order(0, 1);
  }
}

/** The facet of cell \a v opposite its vertex v[i]: the other three ids ascending,
 * and the parity of the permutation from v to (those three, v[i]), +1 even, -1
 * odd. For a positively oriented cell, +1 means v[i] lies where (p1 - p0) x
 * (p2 - p0) of the facet's points points: CGAL's orientations, read exactly. */
struct OppositeFacet {
  std::array<int, 3> ids;
  int parity;
};

inline OppositeFacet
oppositeFacet(const std::array<int, 4>& v, int i)
{
  OppositeFacet f;
  for (int k = 0, m = 0; k < 4; ++k)
    if (k != i)
      f.ids[m++] = v[k];
  // v[i] moved last: 3 - i transpositions; then the inversions among the rest.
  const int swaps =
      3 - i + (f.ids[0] > f.ids[1]) + (f.ids[0] > f.ids[2]) + (f.ids[1] > f.ids[2]);
  f.parity = swaps % 2 == 0 ? 1 : -1;
  sortCorners(f.ids, 3, [](int id) { return id; });
  return f;
}

} // namespace detail
} // namespace cocone
} // namespace pcl
