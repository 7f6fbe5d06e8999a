/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/boundary.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace pcl {
namespace cocone {

std::vector<double>
localSpacing(const Triangulation& dt)
{
  constexpr int K = 6;
  const std::size_t n = dt.points.size();
  // Per vertex its K nearest Delaunay neighbours so far, as (distance, id).
  std::vector<std::array<std::pair<double, int>, K>> near(n);
  for (auto& a : near)
    a.fill({std::numeric_limits<double>::infinity(), -1});
  const auto offer = [&](int a, int b, double d) {
    auto& list = near[a];
    if (d >= list[K - 1].first)
      return;
    for (const auto& e : list)
      if (e.second == b)
        return;
    int k = K - 1;
    for (; k > 0 && list[k - 1].first > d; --k)
      list[k] = list[k - 1];
    list[k] = {d, b};
  };
  forEachCell(dt, 0, 1, [&](const CellView& cell, int) {
    for (int i = 0; i < cell.corners; ++i)
      for (int j = i + 1; j < cell.corners; ++j) {
        const int a = cell.v[i], b = cell.v[j];
        const double d = (dt.points[a] - dt.points[b]).norm();
        offer(a, b, d);
        offer(b, a, d);
      }
  });
  std::vector<double> mean(n, 0.0);
  for (std::size_t v = 0; v < n; ++v) {
    int count = 0;
    for (const auto& e : near[v])
      if (e.second >= 0) {
        mean[v] += e.first;
        ++count;
      }
    mean[v] = count ? mean[v] / count : 0.0;
  }
  std::vector<double> s = mean;
  for (std::size_t v = 0; v < n; ++v)
    for (const auto& e : near[v])
      if (e.second >= 0)
        s[v] = std::max(s[v], mean[e.second]);
  return s;
}

double
automaticRatio(const VoronoiCells& cells)
{
  std::vector<double> r;
  r.reserve(cells.width.size());
  for (std::size_t v = 0; v < cells.width.size(); ++v) {
    const double q = cells.width[v] / cells.height(v);
    if (std::isfinite(q) && cells.height(v) > 0.0)
      r.push_back(q);
  }
  if (r.empty())
    return 1.5;
  const std::size_t k = (r.size() - 1) * 95 / 100;
  std::nth_element(r.begin(), r.begin() + k, r.end());
  const double q95 = r[k];
  return q95 > 0.0 ? std::clamp(1.0 / (2.0 * q95), 0.5, 4.0) : 4.0;
}

BoundaryLabels
detectBoundary(const VoronoiCells& cells,
               const FlatnessParameters& parameters,
               const std::vector<double>& spacing)
{
  const std::size_t n = cells.pole.size();
  BoundaryLabels out;
  out.ratio = parameters.ratio > 0.0 ? parameters.ratio : automaticRatio(cells);
  const double a = spacing.size() == n ? parameters.spacing_factor : 0.0;
  out.ratio_ok.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    const double w = cells.width[v];
    out.ratio_ok[v] = std::isfinite(w) && out.ratio * w <= cells.height(v) &&
                      (a <= 0.0 || w <= a * spacing[v]);
  }

  // Angles are between pole lines: compare |cos|.
  const double cos_theta = std::cos(parameters.normal_angle);
  const auto aligned = [&](int p, int q) {
    return std::abs(cells.pole[p].dot(cells.pole[q])) >= cos_theta;
  };
  // Normal condition, read in the paper's direction: p fails it if some q with
  // p in N_q (the dual edge of a triangle pq. meets C_q) has a pole line too far off.
  std::vector<std::uint8_t> normal_bad(n, 0);
  for (const auto& t : cells.triangles)
    for (int k = 0; k < 3; ++k)
      if (t.meets & (1u << k))
        for (int j = 1; j < 3; ++j) {
          const int p = t.v[(k + j) % 3];
          if (!normal_bad[p] && !aligned(p, t.v[k]))
            normal_bad[p] = 1;
        }
  out.flat.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    out.flat[v] = out.ratio_ok[v] && !normal_bad[v];

  // Growth: only a vertex that passes the ratio test but not the normal condition
  // can join R, so only edges q -> p into such vertices are stored.
  std::vector<std::pair<int, int>> arcs; // (q, p)
  for (const auto& t : cells.triangles)
    for (int k = 0; k < 3; ++k)
      if (t.meets & (1u << k))
        for (int j = 1; j < 3; ++j) {
          const int p = t.v[(k + j) % 3], q = t.v[k];
          if (out.ratio_ok[p] && !out.flat[p] && aligned(p, q))
            arcs.emplace_back(q, p);
        }
  std::sort(arcs.begin(), arcs.end());
  std::vector<std::size_t> first(n + 1, 0);
  for (const auto& a : arcs)
    ++first[a.first + 1];
  for (std::size_t v = 0; v < n; ++v)
    first[v + 1] += first[v];

  out.interior = out.flat;
  std::vector<int> queue;
  for (std::size_t v = 0; v < n; ++v)
    if (out.interior[v])
      queue.push_back(static_cast<int>(v));
  while (!queue.empty()) {
    const int q = queue.back();
    queue.pop_back();
    for (std::size_t k = first[q]; k < first[q + 1]; ++k) {
      const int p = arcs[k].second;
      if (!out.interior[p]) {
        out.interior[p] = 1;
        queue.push_back(p);
      }
    }
  }
  return out;
}

} // namespace cocone
} // namespace pcl
