/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include "border_truth.h"

#include <pcl/common/point_tests.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <algorithm>

namespace cocone_app {

BorderTruth
gridBorderTruth(const pcl::PointCloud<pcl::PointXYZ>& organized,
                const std::vector<int>& compact_of)
{
  const int w = organized.width, h = organized.height;
  const auto valid = [&](int r, int c) { return pcl::isFinite(organized(c, r)); };
  std::vector<double> lengths;
  for (int r = 0; r + 1 < h; ++r)
    for (int c = 0; c + 1 < w; ++c)
      if (valid(r, c) && valid(r, c + 1))
        lengths.push_back(
            (organized(c, r).getVector3fMap() - organized(c + 1, r).getVector3fMap())
                .norm());
  BorderTruth truth;
  if (lengths.empty())
    return truth;
  std::nth_element(
      lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  truth.spacing = lengths[lengths.size() / 2];
  const double longest = 4.0 * truth.spacing; // longer edges jump across depth gaps
  const auto close = [&](int r0, int c0, int r1, int c1) {
    return (organized(c0, r0).getVector3fMap() - organized(c1, r1).getVector3fMap())
               .norm() < longest;
  };
  std::vector<pcl::cocone::Triangle> triangles;
  for (int r = 0; r + 1 < h; ++r)
    for (int c = 0; c + 1 < w; ++c) {
      const int a[2] = {r, c}, b[2] = {r, c + 1}, d[2] = {r + 1, c},
                e[2] = {r + 1, c + 1};
      const auto id = [&](const int* p) { return compact_of[p[0] * w + p[1]]; };
      const auto ok = [&](const int* p, const int* q, const int* s) {
        return valid(p[0], p[1]) && valid(q[0], q[1]) && valid(s[0], s[1]) &&
               close(p[0], p[1], q[0], q[1]) && close(q[0], q[1], s[0], s[1]) &&
               close(s[0], s[1], p[0], p[1]);
      };
      if (ok(a, b, d))
        triangles.push_back({id(a), id(d), id(b)});
      if (ok(b, e, d))
        triangles.push_back({id(b), id(d), id(e)});
    }
  std::size_t n = 0;
  for (const int i : compact_of)
    n = std::max<std::size_t>(n, i + 1);
  // Border half-edges, traced into loops; a grid mesh can touch itself at a corner,
  // so a vertex may start several.
  const pcl::cocone::EdgeIncidences inc(triangles);
  std::vector<std::vector<int>> out(n);
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (inc.count(e) == 1) {
      const bool fwd = inc.forward[inc.first[e]];
      out[fwd ? inc.edges[e][0] : inc.edges[e][1]].push_back(fwd ? inc.edges[e][1]
                                                                 : inc.edges[e][0]);
    }
  for (std::size_t s = 0; s < n; ++s)
    while (!out[s].empty()) {
      std::vector<int> loop;
      int v = static_cast<int>(s);
      while (!out[v].empty()) {
        loop.push_back(v);
        const int next = out[v].back();
        out[v].pop_back();
        v = next;
      }
      // Holes of a few missing pixels are below the sampling resolution: a surface
      // reconstruction is right to close them.
      if (loop.size() > MIN_GRID_LOOP) {
        ++truth.loops;
        truth.border.insert(truth.border.end(), loop.begin(), loop.end());
      }
    }
  std::sort(truth.border.begin(), truth.border.end());
  truth.border.erase(std::unique(truth.border.begin(), truth.border.end()),
                     truth.border.end());
  return truth;
}

BorderScore
scoreBorder(const pcl::PointCloud<pcl::PointXYZ>& cloud,
            const std::vector<int>& reported,
            const BorderTruth& truth)
{
  const double r = 2.0 * truth.spacing;
  // How many points of `from` have a point of `to` within r.
  const auto count_close = [&](const std::vector<int>& from,
                               const std::vector<int>& to) {
    if (from.empty() || to.empty())
      return std::size_t(0);
    pcl::PointCloud<pcl::PointXYZ>::Ptr sub(new pcl::PointCloud<pcl::PointXYZ>);
    for (const int i : to)
      sub->push_back(cloud[i]);
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(sub);
    std::size_t n = 0;
    pcl::Indices k(1);
    std::vector<float> d(1);
    for (const int i : from)
      if (tree.nearestKSearch(cloud[i], 1, k, d) > 0 && d[0] <= r * r)
        ++n;
    return n;
  };
  BorderScore s;
  if (!reported.empty())
    s.precision = double(count_close(reported, truth.border)) / double(reported.size());
  if (!truth.border.empty())
    s.recall =
        double(count_close(truth.border, reported)) / double(truth.border.size());
  if (s.precision + s.recall > 0.0)
    s.f1 = 2.0 * s.precision * s.recall / (s.precision + s.recall);
  return s;
}

} // namespace cocone_app
