/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/repair.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>

namespace pcl {
namespace cocone {

std::size_t
peelBorderSlivers(const std::vector<Eigen::Vector3d>& points,
                  std::vector<Triangle>& triangles,
                  EdgeIncidences& incidences,
                  std::vector<std::vector<int>>& loops)
{
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  const auto point = [&](int v) {
    return Point(points[v].x(), points[v].y(), points[v].z());
  };
  // The border's vertices and, once taken, the peeled triangles' apexes.
  std::vector<std::uint8_t> taken(points.size(), 0);
  for (const auto& loop : loops)
    for (const int v : loop)
      taken[v] = 1;
  std::vector<std::uint8_t> peeled(triangles.size(), 0);
  std::size_t count = 0;
  for (const auto& loop : loops)
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const int a = loop[i], b = loop[(i + 1) % loop.size()];
      const std::ptrdiff_t e = incidences.find(a, b);
      if (e < 0 || incidences.count(e) != 1)
        continue;
      const int t = incidences.triangle[incidences.first[e]];
      const int x = thirdCorner(triangles[t], a, b);
      if (taken[x] || CGAL::angle(point(a), point(x), point(b)) != CGAL::OBTUSE)
        continue;
      taken[x] = 1;
      peeled[t] = 1;
      ++count;
    }
  if (count == 0)
    return 0;
  removeTriangles(triangles, peeled, &incidences);
  loops = boundaryLoops(incidences, points.size());
  return count;
}

} // namespace cocone
} // namespace pcl
