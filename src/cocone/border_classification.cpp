/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/border_classification.h>

#include "loop_plane.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl {
namespace cocone {

namespace {

double
circumradius(const Eigen::Vector3d& a,
             const Eigen::Vector3d& b,
             const Eigen::Vector3d& c)
{
  const double twice_area = (b - a).cross(c - a).norm();
  if (twice_area <= 0.0)
    return std::numeric_limits<double>::infinity();
  return (b - c).norm() * (a - c).norm() * (a - b).norm() / (2.0 * twice_area);
}

} // namespace

std::vector<std::uint8_t>
classifyBorderLoops(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Triangle>& triangles,
                    const std::vector<std::vector<int>>& loops,
                    const std::vector<CoconeTriangle>& cocone_triangles,
                    double max_width,
                    std::size_t max_edges)
{
  std::vector<std::uint8_t> border(loops.size(), 1);
  // The repaired mesh has one fan per vertex: a vertex is on at most one loop.
  std::vector<int> loop_of(points.size(), -1);
  bool any = false;
  for (std::size_t l = 0; l < loops.size(); ++l)
    if (loops[l].size() >= 3 && loops[l].size() <= max_edges) {
      any = true;
      for (const int v : loops[l])
        loop_of[v] = static_cast<int>(l);
    }
  if (max_width <= 0.0)
    return std::vector<std::uint8_t>(loops.size(), 0);
  if (!any)
    return border;

  // The triangles at each loop's rim, by their circumradii.
  std::vector<std::vector<double>> rim_radii(loops.size());
  for (const auto& t : triangles) {
    int last = -1;
    for (const int v : t) {
      const int l = loop_of[v];
      if (l >= 0 && l != last) { // counted once per loop
        rim_radii[l].push_back(circumradius(points[t[0]], points[t[1]], points[t[2]]));
        last = l;
      }
    }
  }
  // The vertices next to each loop (sharing a co-cone triangle with it),
  // candidates for points in the hole.
  std::vector<std::vector<int>> near(loops.size());
  for (const auto& t : cocone_triangles)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int l = loop_of[t.v[j]];
        if (j != i && l >= 0 && loop_of[t.v[i]] != l)
          near[l].push_back(t.v[i]);
      }

  for (std::size_t l = 0; l < loops.size(); ++l) {
    const auto& loop = loops[l];
    auto& radii = rim_radii[l];
    if (loop.size() < 3 || loop.size() > max_edges || radii.empty())
      continue;
    const detail::LoopPlane hole = detail::projectLoop(points, loop);
    auto& candidates = near[l];
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()),
                     candidates.end());
    const auto inside = std::count_if(candidates.begin(), candidates.end(), [&](int v) {
      return hole.contains(points[v]);
    });
    double area = 0.0, length = 0.0;
    for (std::size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
      const Eigen::Vector2d &a = hole.polygon[j], &b = hole.polygon[i];
      area += a.x() * b.y() - b.x() * a.y();
      length += (points[loop[i]] - points[loop[j]]).norm();
    }
    // 4 A / P (A = |area| / 2), shared among the points inside: m points split the
    // hole into about m + 1 openings, each 1 / sqrt(m + 1) as wide.
    const double width =
        2.0 * std::abs(area) / length / std::sqrt(static_cast<double>(inside + 1));
    auto middle = radii.begin() + radii.size() / 2;
    std::nth_element(radii.begin(), middle, radii.end());
    border[l] = width > max_width * 2.0 * *middle;
  }
  return border;
}

} // namespace cocone
} // namespace pcl
