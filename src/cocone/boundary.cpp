/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/boundary.h>
#include <pcl/surface/cocone/complex.h>

#include "edge_sort.h"
#include "points.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace pcl {
namespace cocone {

std::vector<double>
meanSpacing(const std::vector<Eigen::Vector3d>& points,
            const VoronoiCells& cells,
            int threads)
{
  const auto n = static_cast<std::ptrdiff_t>(points.size());
  std::vector<double> mean(n, 0.0);
#pragma omp parallel for num_threads(threads) schedule(static, 16384)
  for (std::ptrdiff_t v = 0; v < n; ++v)
    mean[v] = detail::meanNeighbourDistance(
        points, cells.nearest[v], static_cast<int>(v), detail::SPACING_NEIGHBOURS);
  return mean;
}

std::vector<double>
localSpacing(const VoronoiCells& cells, const std::vector<double>& mean, int threads)
{
  const auto n = static_cast<std::ptrdiff_t>(mean.size());
  std::vector<double> s = mean;
#pragma omp parallel for num_threads(threads) schedule(static, 16384)
  for (std::ptrdiff_t v = 0; v < n; ++v)
    for (int k = 0; k < detail::SPACING_NEIGHBOURS && cells.nearest[v][k] >= 0; ++k)
      s[v] = std::max(s[v], mean[cells.nearest[v][k]]);
  return s;
}

std::vector<double>
localSpacing(const std::vector<Eigen::Vector3d>& points,
             const VoronoiCells& cells,
             int threads)
{
  return localSpacing(cells, meanSpacing(points, cells, threads), threads);
}

HalfDisk
halfDiskTest(const std::vector<Eigen::Vector3d>& points,
             const VoronoiCells& cells,
             const std::vector<double>& spacing,
             double reach,
             double gap_angle,
             int threads,
             const std::vector<std::uint8_t>& counted)
{
  const std::size_t n = points.size();
  const auto near = [&](std::size_t p, int q) {
    const double r = reach * spacing[p];
    return q >= 0 && (points[q] - points[p]).squaredNorm() <= r * r;
  };
  // The short Delaunay edges at p: its nearest neighbours within reach.
  const auto& nearest = cells.nearest;
  std::vector<std::uint8_t> degree(n, 0);
#pragma omp parallel for num_threads(threads) schedule(static, 4096)
  for (std::ptrdiff_t p = 0; p < static_cast<std::ptrdiff_t>(n); ++p)
    while (degree[p] < nearest[p].size() && near(p, nearest[p][degree[p]]))
      ++degree[p];

  // The gap of p seen through its one-ring (\a two_ring false) or its two-ring.
  // The one-ring alone leaves gaps of up to 120 degrees inside an even sample (an
  // obtuse Delaunay triangle at p); the two-ring closes them. The two-ring holds the
  // one-ring, so its gap is never larger: a one-ring gap at most the gap angle
  // settles the test, and only the few points above it (1-2 % on random samples,
  // 3-10 % on even ones) need the two-ring.
  struct Scratch {
    std::vector<int> ring;
    std::vector<Eigen::Vector2d> directions;
    std::vector<int> taken; // per vertex, the last p whose ring took it
  };
  const auto gap = [&](int p, bool two_ring, Scratch& s) {
    s.ring.assign(nearest[p].begin(), nearest[p].begin() + degree[p]);
    if (two_ring) {
      if (s.taken.empty())
        s.taken.assign(n, -1);
      s.taken[p] = p;
      for (const int q : s.ring)
        s.taken[q] = p;
      for (int k = 0; k < degree[p]; ++k) {
        const int q = nearest[p][k];
        for (int j = 0; j < degree[q]; ++j) {
          const int r = nearest[q][j];
          if (s.taken[r] != p && near(p, r)) {
            s.taken[r] = p;
            s.ring.push_back(r);
          }
        }
      }
    }
    if (s.ring.size() < 2)
      return 2.0 * M_PI;
    const Eigen::Vector3d& pole = cells.pole[p];
    const Eigen::Vector3d e1 = pole.unitOrthogonal(), e2 = pole.cross(e1);
    s.directions.clear();
    for (const int q : s.ring) {
      const Eigen::Vector3d d = points[q] - points[p];
      s.directions.emplace_back(d.dot(e1), d.dot(e2));
    }
    return largestDirectionGap(s.directions);
  };

  HalfDisk out;
  out.gap.assign(n, 2.0 * M_PI);
  // Inside a surface the gaps grow with the irregularity of the sample: the median
  // gap is about 50 degrees on range grids and even samples, 75 on area-uniform
  // random ones, whose voids would pass for borders at 80 degrees. The angle grows
  // with the square of the median's excess. The median is that of every stride-th
  // vertex (ids follow a space-filling curve): all of them in a cloud of fewer than
  // 2 * MEDIAN_SAMPLE, at least MEDIAN_SAMPLE of them in a larger one.
  constexpr std::size_t MEDIAN_SAMPLE = 65536;
  std::vector<int> median_sample;
  {
    const std::size_t m = counted.empty() ? n
                                          : n - static_cast<std::size_t>(std::count(
                                                    counted.begin(), counted.end(), 0));
    const std::size_t stride = std::max<std::size_t>(1, m / MEDIAN_SAMPLE);
    median_sample.reserve((m + stride - 1) / stride);
    for (std::size_t p = 0, k = 0; p < n; ++p)
      if ((counted.empty() || counted[p]) && k++ % stride == 0)
        median_sample.push_back(static_cast<int>(p));
  }
  const auto sampled = static_cast<std::ptrdiff_t>(median_sample.size());
  std::vector<double> g(sampled);
  std::vector<std::uint8_t> in_sample(n, 0);
#pragma omp parallel num_threads(threads)
  {
    Scratch scratch;
#pragma omp for schedule(dynamic, 256)
    for (std::ptrdiff_t i = 0; i < sampled; ++i) {
      const int p = median_sample[i];
      in_sample[p] = 1;
      out.gap[p] = g[i] = gap(p, true, scratch);
    }
  }
  out.angle = gap_angle;
  if (sampled > 0) {
    std::nth_element(g.begin(), g.begin() + sampled / 2, g.end());
    const double irregular = g[sampled / 2] / (50.0 * M_PI / 180.0);
    out.angle = std::max(gap_angle, gap_angle * irregular * irregular);
  }
  // The other vertices: their exact gap where the one-ring's exceeds the angle.
#pragma omp parallel num_threads(threads)
  {
    Scratch scratch;
#pragma omp for schedule(dynamic, 1024)
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
      const auto p = static_cast<int>(i);
      if (in_sample[p])
        continue;
      out.gap[p] = gap(p, false, scratch);
      if (out.gap[p] > out.angle)
        out.gap[p] = gap(p, true, scratch);
    }
  }
  out.rim.assign(n, 0);
  for (std::size_t p = 0; p < n; ++p) {
    if (!(out.gap[p] > out.angle))
      continue;
    int support = 0;
    for (int k = 0; k < degree[p]; ++k)
      support += out.gap[nearest[p][k]] > out.angle;
    out.rim[p] = support >= 2;
  }
  return out;
}

double
automaticRatio(const VoronoiCells& cells, const std::vector<std::uint8_t>& counted)
{
  std::vector<double> r;
  r.reserve(cells.width.size());
  for (std::size_t v = 0; v < cells.width.size(); ++v) {
    if (!counted.empty() && !counted[v])
      continue;
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
               const std::vector<double>& spacing,
               int threads)
{
  const std::size_t n = cells.pole.size();
  BoundaryLabels out;
  out.ratio = parameters.ratio > 0.0 ? parameters.ratio : automaticRatio(cells);
  const double a = spacing.size() == n ? parameters.spacing_factor : 0.0;
  out.ratio_ok.assign(n, 0);
#pragma omp parallel for num_threads(threads) schedule(static, 16384)
  for (std::ptrdiff_t v = 0; v < static_cast<std::ptrdiff_t>(n); ++v) {
    const double w = cells.width[v];
    out.ratio_ok[v] = std::isfinite(w) && out.ratio * w <= cells.height(v) &&
                      (a <= 0.0 || w <= a * spacing[v]);
  }

  // Angles are between pole lines: compare |cos|.
  const double cos_theta = std::cos(parameters.normal_angle);
  const auto aligned = [&](int p, int q) {
    return std::abs(cells.pole[p].dot(cells.pole[q])) >= cos_theta;
  };
  // Per co-cone neighbour relation q -> p (the dual edge of a triangle pq. meets
  // C_q), in the order of the triangles.
  const auto& triangles = cells.triangles;
  const auto for_each_arc = [&](std::size_t begin, std::size_t end, const auto& arc) {
    for (std::size_t i = begin; i < end; ++i) {
      const CoconeTriangle& t = triangles[i];
      for (int k = 0; k < 3; ++k)
        if (t.meets & (1u << k))
          for (int j = 1; j < 3; ++j)
            arc(t.v[k], t.v[(k + j) % 3]);
    }
  };
  const int parts = detail::partsFor(triangles.size(), threads);
  // Normal condition, read in the paper's direction: p fails it if some q with
  // p in N_q has a pole line too far off. (Every writer writes 1.)
  std::vector<std::uint8_t> normal_bad(n, 0);
  detail::forEachRange(triangles.size(), parts, [&](std::size_t b, std::size_t e, int) {
    for_each_arc(b, e, [&](int q, int p) {
      if (!__atomic_load_n(&normal_bad[p], __ATOMIC_RELAXED) && !aligned(p, q))
        __atomic_store_n(&normal_bad[p], 1, __ATOMIC_RELAXED);
    });
  });
  out.flat.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    out.flat[v] = out.ratio_ok[v] && !normal_bad[v];

  // Growth: only a vertex that passes the ratio test but not the normal condition
  // can join R, so only arcs q -> p into such vertices are kept, grouped by q.
  std::vector<std::vector<std::pair<int, int>>> found(parts);
  detail::forEachRange(
      triangles.size(), parts, [&](std::size_t b, std::size_t e, int part) {
        for_each_arc(b, e, [&](int q, int p) {
          if (out.ratio_ok[p] && !out.flat[p] && aligned(p, q))
            found[part].emplace_back(q, p);
        });
      });
  std::vector<std::pair<int, int>> arcs;
  for (const auto& f : found)
    arcs.insert(arcs.end(), f.begin(), f.end());
  std::vector<std::vector<std::pair<int, int>>>().swap(found);
  std::vector<int> head(arcs.size());
  const detail::LargeVector<std::uint32_t> first = detail::countingSort(
      arcs.size(),
      n,
      threads,
      [&](std::size_t i) { return arcs[i].first; },
      [&](std::size_t i, std::uint32_t place) { head[place] = arcs[i].second; });

  out.interior = out.flat;
  std::vector<int> queue;
  for (std::size_t v = 0; v < n; ++v)
    if (out.interior[v])
      queue.push_back(static_cast<int>(v));
  while (!queue.empty()) {
    const int q = queue.back();
    queue.pop_back();
    for (std::size_t k = first[q]; k < first[q + 1]; ++k) {
      const int p = head[k];
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
