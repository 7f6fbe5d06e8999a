/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <Eigen/Geometry>

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

template <typename Visit>
void
NearQuery::visit(const Eigen::Vector3d& q, double radius, const Visit& f) const
{
  const long r = static_cast<long>(std::ceil(radius / cell_));
  const long x = std::lround(std::floor(q.x() / cell_));
  const long y = std::lround(std::floor(q.y() / cell_));
  const long z = std::lround(std::floor(q.z() / cell_));
  for (long i = x - r; i <= x + r; ++i)
    for (long j = y - r; j <= y + r; ++j)
      for (long k = z - r; k <= z + r; ++k) {
        const auto it = grid_.find(key(i, j, k));
        if (it != grid_.end())
          for (const int p : it->second)
            f(p, (points_[p] - q).norm());
      }
}

double
NearQuery::nearest(const Eigen::Vector3d& q, double radius) const
{
  double best = std::numeric_limits<double>::infinity();
  visit(q, radius, [&](int, double d) { best = std::min(best, d); });
  return best <= radius ? best : std::numeric_limits<double>::infinity();
}

std::vector<int>
NearQuery::within(const Eigen::Vector3d& q, double radius) const
{
  std::vector<int> out;
  visit(q, radius, [&](int p, double d) {
    if (d <= radius)
      out.push_back(p);
  });
  return out;
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
    // Local spacing: mean nearest-neighbour distance of the samples around.
    const NearQuery near_sample(s.points, h);
    std::vector<double> nn(s.points.size());
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      double d = std::numeric_limits<double>::infinity();
      for (const int j : near_sample.within(s.points[i], 4.0 * h))
        if (j != static_cast<int>(i))
          d = std::min(d, (s.points[j] - s.points[i]).norm());
      nn[i] = std::isfinite(d) ? d : h;
    }
    const auto local = [&](const Eigen::Vector3d& q) {
      double sum = 0.0;
      std::size_t count = 0;
      for (const int j : near_sample.within(q, 4.0 * h)) {
        sum += nn[j];
        ++count;
      }
      return count ? sum / double(count) : h;
    };
    std::vector<Eigen::Vector3d> found;
    for (const int i : reported)
      found.push_back(s.points[i]);
    const NearQuery near_found(found, h);
    std::size_t covered = 0;
    for (const auto& c : s.boundary_curve)
      covered += std::isfinite(near_found.nearest(c, 2.5 * local(c)));
    score.recall = double(covered) / double(s.boundary_curve.size());
    const NearQuery near_curve(s.boundary_curve, h);
    std::size_t close = 0;
    for (const int i : reported)
      close += std::isfinite(near_curve.nearest(s.points[i], 3.0 * local(s.points[i])));
    score.precision = reported.empty() ? 1.0 : double(close) / double(reported.size());
  }
  else {
    score.recall = 1.0;
    score.precision = reported.empty() ? 1.0 : 0.0;
  }
  return score;
}

std::string
MeshScore::str() const
{
  char buf[320];
  std::snprintf(buf,
                sizeof(buf),
                "triangles %zu loops %zu euler %ld components %zu (closed %zu) used "
                "%.2f %% max distance %.2f spacings volume %.4f; manifold %d "
                "(nm edges %zu, nm vertices %zu, conflicts %zu)",
                topology.triangles,
                loops,
                topology.euler,
                topology.components,
                topology.closed_components,
                100.0 * used_share,
                max_distance,
                volume,
                int(topology.manifold()),
                topology.nonmanifold_edges,
                topology.nonmanifold_vertices,
                topology.orientation_conflicts);
  return buf;
}

MeshScore
scoreMesh(const Sample& s, const pcl::cocone::Result& r)
{
  MeshScore score;
  score.topology = pcl::cocone::analyzeMesh(r.triangles, r.vertices);
  score.loops = r.border_loops.size();
  std::vector<std::uint8_t> used(s.points.size(), 0);
  for (const auto& t : r.polygons)
    for (const int i : t)
      used[i] = 1;
  // Duplicates stand for each other.
  std::vector<std::uint8_t> vertex_used(r.vertices, 0);
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (used[i])
      vertex_used[r.vertex_of_input[i]] = 1;
  std::size_t count = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    count += r.vertex_of_input[i] >= 0 && vertex_used[r.vertex_of_input[i]];
  score.used_share = s.points.empty() ? 0.0 : double(count) / double(s.points.size());
  for (const auto& t : r.polygons) {
    const Eigen::Vector3d a = s.points[t[0]], b = s.points[t[1]], c = s.points[t[2]];
    for (const Eigen::Vector3d& q : {Eigen::Vector3d((a + b + c) / 3.0),
                                     Eigen::Vector3d((a + b) / 2.0),
                                     Eigen::Vector3d((b + c) / 2.0),
                                     Eigen::Vector3d((c + a) / 2.0)})
      score.max_distance = std::max(score.max_distance, s.distance(q) / s.spacing);
    score.volume += a.dot(b.cross(c)) / 6.0;
  }
  return score;
}

} // namespace cocone_test
