/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include "benchmark_advancing_front.h"

#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <array>
#include <iterator>

namespace cocone_app {

std::vector<pcl::cocone::Triangle>
advancingFront(const std::vector<Eigen::Vector3d>& points)
{
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  std::vector<Point> p;
  p.reserve(points.size());
  for (const auto& q : points)
    p.emplace_back(q.x(), q.y(), q.z());
  std::vector<std::array<std::size_t, 3>> facets;
  CGAL::advancing_front_surface_reconstruction(
      p.begin(), p.end(), std::back_inserter(facets));
  std::vector<pcl::cocone::Triangle> triangles;
  triangles.reserve(facets.size());
  for (const auto& f : facets)
    triangles.push_back(
        {static_cast<int>(f[0]), static_cast<int>(f[1]), static_cast<int>(f[2])});
  return triangles;
}

} // namespace cocone_app
