/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/triangulation.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include "points.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>;
using CellBase = CGAL::Triangulation_cell_base_with_info_3<
    int,
    Kernel,
    CGAL::Delaunay_triangulation_cell_base_3<Kernel>>;
using Tds = CGAL::Triangulation_data_structure_3<VertexBase, CellBase>;
using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, Tds>;

using detail::isFinite;
using detail::lexLess;

Eigen::Vector3d
toEigen(const CGAL::Exact_predicates_exact_constructions_kernel::Point_3& p)
{
  return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
}

/** The cell's vertex ids sorted ascending, the canonical order for constructions. */
template <std::size_t N>
std::array<int, N>
sortedIds(const std::array<int, 4>& cell)
{
  std::array<int, N> ids;
  std::copy_n(cell.begin(), N, ids.begin());
  std::sort(ids.begin(), ids.end());
  return ids;
}

} // namespace

UniquePoints
makeUniquePoints(const std::vector<Eigen::Vector3d>& input)
{
  std::vector<int> order;
  order.reserve(input.size());
  for (std::size_t i = 0; i < input.size(); ++i)
    if (isFinite(input[i]))
      order.push_back(static_cast<int>(i));
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return lexLess(input[a], input[b]) || (input[a] == input[b] && a < b);
  });

  std::vector<Eigen::Vector3d> sorted;
  std::vector<int> sorted_of_input(input.size(), -1);
  for (const int i : order) {
    if (sorted.empty() || sorted.back() != input[i])
      sorted.push_back(input[i]);
    sorted_of_input[i] = static_cast<int>(sorted.size()) - 1;
  }

  // Number the vertices along a Morton (Z-order) curve, ties in lexicographic order:
  // neighbours in space get nearby ids, which keeps the per-cell passes cache
  // friendly, and the numbering still depends only on the point set.
  UniquePoints out;
  if (sorted.empty()) {
    out.vertex_of_input.assign(input.size(), -1);
    return out;
  }
  Eigen::Vector3d lo = sorted.front(), hi = sorted.front();
  for (const auto& p : sorted) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent =
      std::max((hi - lo).maxCoeff(), std::numeric_limits<double>::min());
  const auto spread = [](std::uint64_t v) { // 21 bits -> every third bit
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  std::vector<std::pair<std::uint64_t, int>> keys(sorted.size());
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double t = (sorted[i][k] - lo[k]) / extent * 2097151.0;
      code |= spread(static_cast<std::uint64_t>(std::clamp(t, 0.0, 2097151.0))) << k;
    }
    keys[i] = {code, static_cast<int>(i)};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<int> vertex_of_sorted(sorted.size());
  out.points.resize(sorted.size());
  for (std::size_t v = 0; v < keys.size(); ++v) {
    vertex_of_sorted[keys[v].second] = static_cast<int>(v);
    out.points[v] = sorted[keys[v].second];
  }
  out.vertex_of_input.resize(input.size());
  for (std::size_t i = 0; i < input.size(); ++i)
    out.vertex_of_input[i] =
        sorted_of_input[i] < 0 ? -1 : vertex_of_sorted[sorted_of_input[i]];
  return out;
}

Eigen::Vector3d
tetrahedronCircumcenter(const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c,
                        const Eigen::Vector3d& d)
{
  const Eigen::Vector3d u = b - a, v = c - a, w = d - a;
  const Eigen::Vector3d vw = v.cross(w), wu = w.cross(u), uv = u.cross(v);
  const double den = 2.0 * u.dot(vw);
  const Eigen::Vector3d num =
      u.squaredNorm() * vw + v.squaredNorm() * wu + w.squaredNorm() * uv;
  if (den != 0.0) {
    Eigen::Vector3d cc = a + num / den;
    if (isFinite(cc))
      return cc;
  }
  // The cell is flat to rounding but not exactly (CGAL's predicates guarantee a
  // positive volume): construct exactly, then round.
  using EK = CGAL::Exact_predicates_exact_constructions_kernel;
  const auto p = [](const Eigen::Vector3d& x) { return EK::Point_3(x[0], x[1], x[2]); };
  return toEigen(CGAL::circumcenter(p(a), p(b), p(c), p(d)));
}

Eigen::Vector3d
triangleCircumcenter(const Eigen::Vector3d& a,
                     const Eigen::Vector3d& b,
                     const Eigen::Vector3d& c)
{
  const Eigen::Vector3d u = b - a, v = c - a;
  const Eigen::Vector3d n = u.cross(v);
  const double den = 2.0 * n.squaredNorm();
  if (den != 0.0) {
    Eigen::Vector3d cc = a + (u.squaredNorm() * v - v.squaredNorm() * u).cross(n) / den;
    if (isFinite(cc))
      return cc;
  }
  using EK = CGAL::Exact_predicates_exact_constructions_kernel;
  const auto p = [](const Eigen::Vector3d& x) { return EK::Point_3(x[0], x[1], x[2]); };
  return toEigen(CGAL::circumcenter(p(a), p(b), p(c)));
}

Triangulation
triangulate(const std::vector<Eigen::Vector3d>& points)
{
  Triangulation out;
  if (points.empty())
    return out;

  // Recentre in double so that georeferenced coordinates keep their precision. The
  // origin is an input point (the lexicographically smallest): differences of float
  // coordinates are exact in double, so a translated cloud gives the very same
  // recentred points, and the same triangulation even where it is degenerate.
  out.offset = *std::min_element(points.begin(), points.end(), lexLess);
  out.points.reserve(points.size());
  for (const auto& p : points)
    out.points.push_back(p - out.offset);

  std::vector<std::pair<Kernel::Point_3, int>> sites;
  sites.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto& p = out.points[i];
    sites.emplace_back(Kernel::Point_3(p.x(), p.y(), p.z()), static_cast<int>(i));
  }
  Delaunay dt;
  // Range insertion spatially sorts the sites; CGAL's symbolic perturbation makes the
  // triangulation of degenerate (co-spherical) input independent of that order.
  dt.insert(sites.begin(), sites.end());
  out.dimension = dt.dimension();

  if (out.dimension == 3) {
    const std::size_t n = dt.number_of_finite_cells();
    out.cells.reserve(n);
    int id = 0;
    for (auto c : dt.finite_cell_handles())
      c->info() = id++;
    for (auto c : dt.finite_cell_handles()) {
      std::array<int, 4> v, nb;
      for (int i = 0; i < 4; ++i) {
        v[i] = c->vertex(i)->info();
        const auto other = c->neighbor(i);
        nb[i] = dt.is_infinite(other) ? -1 : other->info();
      }
      out.cells.push_back(v);
      out.neighbors.push_back(nb);
    }
    dt.clear(); // release the CGAL structure before the per-cell arrays grow
    out.circumcenters.resize(out.cells.size());
    for (std::size_t c = 0; c < out.cells.size(); ++c) {
      const auto s = sortedIds<4>(out.cells[c]);
      const auto& P = out.points;
      out.circumcenters[c] =
          tetrahedronCircumcenter(P[s[0]], P[s[1]], P[s[2]], P[s[3]]);
    }
  }
  else if (out.dimension == 2) {
    // In dimension 2 CGAL stores each triangle as a cell with vertices 0..2; the
    // finite facets (c, 3) enumerate them.
    int id = 0;
    for (auto f : dt.finite_facets())
      f.first->info() = id++;
    for (auto f : dt.finite_facets()) {
      const auto c = f.first;
      std::array<int, 4> v{-1, -1, -1, -1}, nb{-1, -1, -1, -1};
      for (int i = 0; i < 3; ++i) {
        v[i] = c->vertex(i)->info();
        const auto other = c->neighbor(i);
        nb[i] = dt.is_infinite(other) ? -1 : other->info();
      }
      out.cells.push_back(v);
      out.neighbors.push_back(nb);
    }
    dt.clear();
    out.circumcenters.resize(out.cells.size());
    for (std::size_t c = 0; c < out.cells.size(); ++c) {
      const auto s = sortedIds<3>(out.cells[c]);
      const auto& P = out.points;
      out.circumcenters[c] = triangleCircumcenter(P[s[0]], P[s[1]], P[s[2]]);
    }
  }
  return out;
}

} // namespace cocone
} // namespace pcl
