/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The advancing front in a translation unit of its own: its header alone takes
 * longer to compile than the rest of the hole filling.
 */

#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/repair.h>

#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <array>
#include <iterator>

namespace pcl {
namespace cocone {

std::vector<Triangle>
advancingFrontMesh(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<std::uint8_t>& region,
                   int threads)
{
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  std::vector<Point> p;
  std::vector<int> vertex;
  for (std::size_t v = 0; v < points.size(); ++v)
    if (region[v]) {
      p.emplace_back(points[v].x(), points[v].y(), points[v].z());
      vertex.push_back(static_cast<int>(v));
    }
  std::vector<Triangle> triangles;
  if (p.size() < 4)
    return triangles;
  std::vector<std::array<std::size_t, 3>> facets;
  CGAL::advancing_front_surface_reconstruction(
      p.begin(), p.end(), std::back_inserter(facets));
  triangles.reserve(facets.size());
  for (const auto& f : facets)
    triangles.push_back({vertex[f[0]], vertex[f[1]], vertex[f[2]]});
  // The advancing front's output is a manifold but not always oriented throughout.
  RepairCounts counts;
  repairManifold(points, triangles, counts, threads);
  return triangles;
}

} // namespace cocone
} // namespace pcl
