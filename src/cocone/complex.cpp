/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/complex.h>

#include <Eigen/Geometry>

#include "edge_sort.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace pcl {
namespace cocone {

double
largestAngularGap(const std::vector<double>& angles)
{
  const std::size_t k = angles.size();
  if (k < 2)
    return 2.0 * M_PI;
  // Few angles (about an edge nearly always two) are sorted on the stack: the
  // buckets pay from about ten angles on.
  constexpr std::size_t FEW = 8;
  if (k <= FEW) {
    std::array<double, FEW> a;
    for (std::size_t i = 0; i < k; ++i) {
      std::size_t j = i;
      for (; j > 0 && a[j - 1] > angles[i]; --j)
        a[j] = a[j - 1];
      a[j] = angles[i];
    }
    double gap = a[0] + 2.0 * M_PI - a[k - 1];
    for (std::size_t i = 1; i < k; ++i)
      gap = std::max(gap, a[i] - a[i - 1]);
    return gap;
  }
  const auto [lo, hi] = std::minmax_element(angles.begin(), angles.end());
  double gap = *lo + 2.0 * M_PI - *hi; // the gap across +-pi
  if (!(*hi > *lo))
    return gap;
  // k buckets of equal width from the lowest angle to the highest: the largest of
  // the k - 1 gaps between them is wider than a bucket, so it lies between the
  // highest angle of a bucket and the lowest of the next one that is not empty. No
  // sort: linear in k.
  thread_local std::vector<std::pair<double, double>> bucket; // lowest, highest
  bucket.assign(k,
                {std::numeric_limits<double>::infinity(),
                 -std::numeric_limits<double>::infinity()});
  const double scale = static_cast<double>(k) / (*hi - *lo);
  for (const double a : angles) {
    auto& b = bucket[std::min(k - 1, static_cast<std::size_t>((a - *lo) * scale))];
    b.first = std::min(b.first, a);
    b.second = std::max(b.second, a);
  }
  double previous = bucket[0].second; // holds the lowest angle
  for (std::size_t b = 1; b < k; ++b)
    if (bucket[b].first <= bucket[b].second) {
      gap = std::max(gap, bucket[b].first - previous);
      previous = bucket[b].second;
    }
  return gap;
}

namespace {

/** The diamond angle of (x, y), in [0, 4): it grows with the angle from the x axis
 * over [0, 2 pi) and costs a division. */
double
pseudoAngle(double x, double y)
{
  const double s = std::abs(x) + std::abs(y);
  if (s == 0.0)
    return 0.0;
  const double r = y / s;
  if (x < 0.0)
    return 2.0 - r;
  return y < 0.0 ? 4.0 + r : r;
}

} // namespace

double
largestDirectionGap(const std::vector<Eigen::Vector2d>& directions)
{
  const std::size_t k = directions.size();
  if (k < 2)
    return 2.0 * M_PI;
  struct Direction {
    double key;
    Eigen::Vector2d d;
  };
  thread_local std::vector<Direction> sorted;
  sorted.resize(k);
  for (std::size_t i = 0; i < k; ++i) {
    const Eigen::Vector2d& d = directions[i];
    // atan2 (0, 0) is 0: the zero vector points along the x axis.
    const Eigen::Vector2d u = d.isZero(0.0) ? Eigen::Vector2d::UnitX() : d;
    // Insertion: a ring has a few dozen directions.
    std::size_t j = i;
    const double key = pseudoAngle(u.x(), u.y());
    for (; j > 0 && sorted[j - 1].key > key; --j)
      sorted[j] = sorted[j - 1];
    sorted[j] = {key, u};
  }
  // The gap from a to the next direction b, turning anticlockwise, is the angle of
  // (a.b, a x b), which its pseudo-angle orders. Near a whole turn or none, where
  // the cross product's sign may be rounding's, the turn of the keys tells the two
  // apart: below pi a turn of keys stays below 2, above it rises above 2.
  constexpr double WHOLE = 4.0;
  double best_key = -1.0, best_dot = 0.0, best_cross = 0.0;
  for (std::size_t i = 0; i < k; ++i) {
    const bool last = i + 1 == k;
    const Direction& a = sorted[i];
    const Direction& b = sorted[last ? 0 : i + 1];
    const double turn = b.key - a.key + (last ? WHOLE : 0.0);
    const double dot = a.d.dot(b.d), cross = a.d.x() * b.d.y() - a.d.y() * b.d.x();
    double key = pseudoAngle(dot, cross);
    if (dot > 0.0 && cross < 0.0 && turn < 2.0)
      key = 0.0;
    else if (dot > 0.0 && cross >= 0.0 && turn > 2.0)
      key = WHOLE;
    if (key > best_key) {
      best_key = key;
      best_dot = dot;
      best_cross = cross;
    }
  }
  if (best_key == WHOLE)
    return 2.0 * M_PI;
  const double gap = std::atan2(best_cross, best_dot);
  return gap < 0.0 ? gap + 2.0 * M_PI : gap;
}

TriangleComplex::TriangleComplex(const std::vector<Eigen::Vector3d>& points,
                                 std::vector<Triangle> triangles,
                                 int threads)
: points_(points), triangles_(std::move(triangles))
{
  for (auto& t : triangles_)
    std::sort(t.begin(), t.end());
  // The candidates arrive sorted: check before sorting.
  if (!std::is_sorted(triangles_.begin(), triangles_.end()))
    std::sort(triangles_.begin(), triangles_.end());
  const std::size_t m = triangles_.size();

  // Edges: the incidences grouped by edge once. Incidence (t, k) runs from corner k
  // to corner k + 1, so it is the edge opposite corner k + 2.
  const detail::LargeVector<std::uint64_t> word =
      detail::groupEdgeIncidences(triangles_, edges_, edge_first_, threads);
  triangle_edges_.resize(m);
  edge_triangles_.resize(word.size());
  const auto num_edges = static_cast<std::ptrdiff_t>(edges_.size());
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
  for (std::ptrdiff_t e = 0; e < num_edges; ++e)
    for (std::size_t i = edge_first_[e]; i < edge_first_[e + 1]; ++i) {
      const int t = detail::incidenceTriangle(word[i]);
      triangle_edges_[t][(detail::incidenceCorner(word[i]) + 2) % 3] =
          static_cast<int>(e);
      edge_triangles_[i] = t;
    }

  // At an edge of two triangles, the sign of the dot product of their directions
  // from the edge (orthogonal to it) tells whether they make an angle below pi / 2.
  // (The rare edges of more than two compute their angles when asked.)
  acute_pair_.assign(edges_.size(), 0);
#pragma omp parallel for num_threads(threads) schedule(static, 4096)
  for (std::ptrdiff_t e = 0; e < num_edges; ++e)
    if (edge_first_[e + 1] - edge_first_[e] == 2) {
      const Eigen::Vector3d& a = points_[edges_[e][0]];
      const Eigen::Vector3d d = points_[edges_[e][1]] - a;
      const Eigen::Vector3d u = apexFrom(static_cast<int>(e), edge_first_[e]),
                            w = apexFrom(static_cast<int>(e), edge_first_[e] + 1);
      acute_pair_[e] = u.dot(w) * d.squaredNorm() > u.dot(d) * w.dot(d);
    }

  // Vertex -> triangles, in ascending order.
  vertex_triangles_.resize(3 * m);
  const detail::LargeVector<std::uint32_t> start = detail::groupCorners(
      triangles_,
      points_.size(),
      threads,
      [](const Triangle& t, int k) { return t[k]; },
      [&](std::size_t t, int, std::uint32_t place) {
        vertex_triangles_[place] = static_cast<int>(t);
      });
  vertex_first_.assign(start.begin(), start.end());
}

Eigen::Vector3d
TriangleComplex::apexFrom(int e, std::size_t i) const
{
  const auto& v = triangles_[edge_triangles_[i]];
  return points_[v[0] + v[1] + v[2] - edges_[e][0] - edges_[e][1]] -
         points_[edges_[e][0]];
}

void
TriangleComplex::edgeAngles(int e, std::vector<double>& angles) const
{
  const Eigen::Vector3d d =
      (points_[edges_[e][1]] - points_[edges_[e][0]]).normalized();
  int axis = 0;
  d.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d x = d.cross(Eigen::Vector3d::Unit(axis)).normalized();
  const Eigen::Vector3d y = d.cross(x);
  angles.clear();
  for (std::size_t i = edgeBegin(e); i < edgeEnd(e); ++i) {
    const Eigen::Vector3d w = apexFrom(e, i);
    angles.push_back(std::atan2(w.dot(y), w.dot(x)));
  }
}

} // namespace cocone
} // namespace pcl
