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

#include <algorithm>
#include <cmath>
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

bool
isFinite(const Eigen::Vector3d& p)
{
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

bool
lexLess(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

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

  UniquePoints out;
  out.vertex_of_input.assign(input.size(), -1);
  for (const int i : order) {
    if (out.points.empty() || out.points.back() != input[i])
      out.points.push_back(input[i]);
    out.vertex_of_input[i] = static_cast<int>(out.points.size()) - 1;
  }
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
  const Eigen::Vector3d num = u.squaredNorm() * vw + v.squaredNorm() * wu +
                              w.squaredNorm() * uv;
  if (den != 0.0) {
    const Eigen::Vector3d cc = a + num / den;
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
    const Eigen::Vector3d cc =
        a + (u.squaredNorm() * v - v.squaredNorm() * u).cross(n) / den;
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

  // Recentre in double so that georeferenced coordinates keep their precision.
  Eigen::Vector3d lo = points.front(), hi = points.front();
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  out.offset = 0.5 * (lo + hi);
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
      out.circumcenters[c] = tetrahedronCircumcenter(P[s[0]], P[s[1]], P[s[2]], P[s[3]]);
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
