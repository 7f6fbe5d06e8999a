/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/boundary.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace pcl {
namespace cocone {

BoundaryLabels
detectBoundary(const VoronoiCells& cells, const FlatnessParameters& parameters)
{
  const std::size_t n = cells.pole.size();
  BoundaryLabels out;
  out.ratio_ok.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    const double w = cells.width[v];
    out.ratio_ok[v] = std::isfinite(w) && parameters.ratio * w <= cells.height(v);
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
