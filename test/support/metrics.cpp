/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <support/metrics.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace cocone_test {

NearQuery::NearQuery(const std::vector<Eigen::Vector3d>& points, double cell)
: points_(points), cell_(cell)
{
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    grid_[key(std::lround(std::floor(p.x() / cell_)),
              std::lround(std::floor(p.y() / cell_)),
              std::lround(std::floor(p.z() / cell_)))]
        .push_back(static_cast<int>(i));
  }
}

std::int64_t
NearQuery::key(long x, long y, long z) const
{
  return (static_cast<std::int64_t>(x) * 73856093) ^
         (static_cast<std::int64_t>(y) * 19349663) ^
         (static_cast<std::int64_t>(z) * 83492791);
}

double
NearQuery::nearest(const Eigen::Vector3d& q, double radius) const
{
  const long r = static_cast<long>(std::ceil(radius / cell_));
  const long x = std::lround(std::floor(q.x() / cell_));
  const long y = std::lround(std::floor(q.y() / cell_));
  const long z = std::lround(std::floor(q.z() / cell_));
  double best = std::numeric_limits<double>::infinity();
  for (long i = x - r; i <= x + r; ++i)
    for (long j = y - r; j <= y + r; ++j)
      for (long k = z - r; k <= z + r; ++k) {
        const auto it = grid_.find(key(i, j, k));
        if (it == grid_.end())
          continue;
        for (const int p : it->second)
          best = std::min(best, (points_[p] - q).norm());
      }
  return best <= radius ? best : std::numeric_limits<double>::infinity();
}

std::string
BoundaryScore::str() const
{
  char buf[160];
  std::snprintf(buf,
                sizeof(buf),
                "recall %.3f precision %.3f reported %zu (%.2f %%)",
                recall,
                precision,
                reported,
                100.0 * reported_share);
  return buf;
}

BoundaryScore
scoreBoundary(const Sample& s, const std::vector<int>& reported)
{
  BoundaryScore score;
  score.reported = reported.size();
  score.reported_share =
      s.points.empty() ? 0.0 : double(reported.size()) / double(s.points.size());
  const double h = s.spacing;
  if (!s.boundary_curve.empty()) {
    std::vector<Eigen::Vector3d> found;
    for (const int i : reported)
      found.push_back(s.points[i]);
    const NearQuery near_found(found, h);
    std::size_t covered = 0;
    for (const auto& c : s.boundary_curve)
      covered += std::isfinite(near_found.nearest(c, 2.5 * h));
    score.recall = double(covered) / double(s.boundary_curve.size());
    const NearQuery near_curve(s.boundary_curve, h);
    std::size_t close = 0;
    for (const int i : reported)
      close += std::isfinite(near_curve.nearest(s.points[i], 3.0 * h));
    score.precision = reported.empty() ? 1.0 : double(close) / double(reported.size());
  }
  else {
    score.recall = 1.0;
    score.precision = reported.empty() ? 1.0 : 0.0;
  }
  return score;
}

} // namespace cocone_test
