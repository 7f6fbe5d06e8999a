/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/hole_reopening.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl {
namespace cocone {

std::vector<std::uint8_t>
trianglesRoundLoop(const std::vector<Triangle>& triangles,
                   const std::vector<int>& loop,
                   int rings,
                   std::size_t num_vertices,
                   std::vector<std::uint8_t>* corners)
{
  std::vector<std::uint8_t> reached(num_vertices, 0), within(triangles.size(), 0);
  for (const int v : loop)
    reached[v] = 1;
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<std::uint8_t> next = reached;
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const Triangle& tri = triangles[t];
      if (reached[tri[0]] || reached[tri[1]] || reached[tri[2]]) {
        within[t] = 1;
        next[tri[0]] = next[tri[1]] = next[tri[2]] = 1;
      }
    }
    reached = std::move(next);
  }
  // After the last ring: the loop and every corner of the triangles within.
  if (corners != nullptr)
    *corners = std::move(reached);
  return within;
}

double
farthestLeftOut(const std::vector<Eigen::Vector3d>& points,
                const std::vector<double>& spacing,
                const std::vector<Triangle>& before,
                const std::vector<Triangle>& after,
                const std::vector<std::uint8_t>& region)
{
  // Exact distances are not needed (a length compared with a tolerance), so the
  // plain double kernel.
  using Kernel = CGAL::Simple_cartesian<double>;
  const auto point = [&](int v) {
    return Kernel::Point_3(points[v].x(), points[v].y(), points[v].z());
  };
  const std::vector<std::uint8_t> used_before = usedVertices(before, points.size()),
                                  used_after = usedVertices(after, points.size());
  std::vector<int> left_out;
  for (std::size_t v = 0; v < points.size(); ++v)
    if (used_before[v] && !used_after[v])
      left_out.push_back(static_cast<int>(v));
  if (left_out.empty())
    return 0.0;
  std::vector<Kernel::Triangle_3> round;
  for (const Triangle& t : after)
    if (region[t[0]] || region[t[1]] || region[t[2]])
      round.emplace_back(point(t[0]), point(t[1]), point(t[2]));
  double farthest = 0.0;
  for (const int v : left_out) {
    double nearest2 = std::numeric_limits<double>::infinity();
    const Kernel::Point_3 p = point(v);
    for (const auto& t : round)
      nearest2 = std::min(nearest2, CGAL::squared_distance(p, t));
    farthest = std::max(farthest, std::sqrt(nearest2) / spacing[v]);
  }
  return farthest;
}

} // namespace cocone
} // namespace pcl
