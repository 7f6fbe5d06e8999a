/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include <algorithm>
#include <array>
#include <iterator>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/** A patch triangle as CGAL hands it over: indices into the loop. */
struct LoopTriangle {
  LoopTriangle(int a, int b, int c) : v{a, b, c} {}
  std::array<int, 3> v;
};

Kernel::Point_3
toCgal(const Eigen::Vector3d& p)
{
  return {p.x(), p.y(), p.z()};
}

} // namespace

HoleFilling
fillUndersampledHoles(const std::vector<Eigen::Vector3d>& points,
                      const std::vector<double>& spacing,
                      std::vector<Triangle>& triangles,
                      EdgeIncidences& incidences,
                      std::vector<std::vector<int>>& loops,
                      double reach,
                      std::size_t max_edges)
{
  HoleFilling out;
  const std::size_t before = triangles.size();
  std::vector<std::vector<int>> open;
  std::vector<Kernel::Point_3> polyline, third;
  std::vector<LoopTriangle> patch;
  for (auto& loop : loops) {
    const std::size_t k = loop.size();
    if (k < 3 || k > max_edges) {
      open.push_back(std::move(loop));
      continue;
    }
    // The hole runs against the loop, which has the mesh on its left: a triangle
    // of the hole's polygon with its corners in the hole's order faces as the mesh.
    std::vector<int> hole(loop.rbegin(), loop.rend());
    polyline.clear();
    third.clear();
    for (std::size_t i = 0; i < k; ++i) {
      const int a = hole[i], b = hole[(i + 1) % k];
      polyline.push_back(toCgal(points[a]));
      // The third corner of the mesh's triangle at the loop's edge ab.
      const auto e = incidences.find(a, b);
      const Triangle& t = triangles[incidences.triangle[incidences.first[e]]];
      const int c = t[0] != a && t[0] != b   ? t[0]
                    : t[1] != a && t[1] != b ? t[1]
                                             : t[2];
      third.push_back(toCgal(points[c]));
    }
    patch.clear();
    CGAL::Polygon_mesh_processing::triangulate_hole_polyline(
        polyline,
        third,
        std::back_inserter(patch),
        CGAL::parameters::use_delaunay_triangulation(true).do_not_use_cubic_algorithm(
            true));
    // Plausible: every new edge short and not in the mesh yet.
    const auto plausible = [&](int i, int j) {
      if (j < i)
        std::swap(i, j);
      if (j == i + 1 || (i == 0 && j == static_cast<int>(k) - 1))
        return true; // an edge of the loop
      const int a = hole[i], b = hole[j];
      const double longest = reach * std::max(spacing[a], spacing[b]);
      return (points[a] - points[b]).squaredNorm() <= longest * longest &&
             incidences.find(a, b) < 0;
    };
    bool closed = patch.size() == k - 2;
    for (const auto& t : patch)
      closed = closed && plausible(t.v[0], t.v[1]) && plausible(t.v[1], t.v[2]) &&
               plausible(t.v[0], t.v[2]);
    if (!closed) {
      open.push_back(std::move(loop));
      continue;
    }
    for (auto t : patch) {
      std::sort(t.v.begin(), t.v.end());
      triangles.push_back({hole[t.v[0]], hole[t.v[1]], hole[t.v[2]]});
    }
    ++out.holes;
    out.triangles += patch.size();
    out.sizes.push_back(k);
  }
  loops = std::move(open);
  if (triangles.size() > before)
    incidences.add(triangles, before);
  return out;
}

} // namespace cocone
} // namespace pcl
