/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/walk.h>

#include <Eigen/Geometry>

#include "edge_sort.h"
#include "parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

/** The edge of triangle t opposite its vertex z. */
int
edgeOpposite(const TriangleComplex& complex, int t, int z)
{
  const auto& v = complex.triangle(t);
  return complex.triangleEdges(t)[v[0] == z ? 0 : v[1] == z ? 1 : 2];
}

/** surfaceNeighbor() across edge e (x y) of t. */
int
neighborAcross(const TriangleComplex& complex,
               const std::vector<std::uint8_t>& present,
               int t,
               int e,
               int x,
               int y,
               int z,
               int& apex)
{
  if (complex.edgeEnd(e) - complex.edgeBegin(e) == 2) {
    // Most edges: the other triangle, where it is present and the two make an angle
    // above pi / 2 (the complex knows); no frame, no rotation.
    const std::size_t i = complex.edgeBegin(e);
    const int t2 = complex.edgeTriangle(i) == t ? complex.edgeTriangle(i + 1)
                                                : complex.edgeTriangle(i);
    if (!present[t2] || complex.acutePair(e))
      return -1;
    const auto& v = complex.triangle(t2);
    apex = v[0] + v[1] + v[2] - x - y;
    return t2;
  }
  const auto& P = complex.points();
  // Frame of the edge: u in t's plane towards z, n along t's normal.
  const Eigen::Vector3d d = (P[y] - P[x]).normalized();
  Eigen::Vector3d u = P[z] - P[x];
  u = (u - u.dot(d) * d).normalized();
  const Eigen::Vector3d n = d.cross(u);
  int best = -1;
  double best_phi = 0.0;
  for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i) {
    const int t2 = complex.edgeTriangle(i);
    if (t2 == t || !present[t2])
      continue;
    const auto& v = complex.triangle(t2);
    const int a = v[0] + v[1] + v[2] - x - y;
    const Eigen::Vector3d w = P[a] - P[x];
    // (y, x, a)'s normal makes an angle below pi/2 with t's exactly when a lies
    // beyond the edge, on the side away from z.
    const double cx = w.dot(u);
    if (cx >= 0.0)
      continue;
    // The angle from u about the edge lies in (pi/2, 3pi/2), where its tangent
    // w.n / cx grows with it: the smallest tangent is the smallest angle.
    const double phi = w.dot(n) / cx;
    if (best < 0 || phi < best_phi) {
      best = t2;
      best_phi = phi;
      apex = a;
    }
  }
  return best;
}

} // namespace

int
surfaceNeighbor(const TriangleComplex& complex,
                const std::vector<std::uint8_t>& present,
                int t,
                int x,
                int y,
                int z,
                int& apex)
{
  return neighborAcross(
      complex, present, t, edgeOpposite(complex, t, z), x, y, z, apex);
}

WalkResult
walk(const TriangleComplex& complex,
     const std::vector<std::uint8_t>& present,
     const std::vector<std::uint8_t>& boundary,
     int threads)
{
  const int m = static_cast<int>(complex.numTriangles());
  WalkResult out;

  // Connected components of the present triangles (through shared edges), by a
  // union-find over the edges in parallel: a set's root is its lowest triangle.
  const auto num_edges = static_cast<std::ptrdiff_t>(complex.numEdges());
  std::vector<int> edge_count(num_edges, 0);
  const auto score = [&](int t) {
    const auto& v = complex.triangle(t);
    const bool umbrellas = !boundary[v[0]] && !boundary[v[1]] && !boundary[v[2]];
    bool manifold = true;
    for (const int e : complex.triangleEdges(t))
      manifold = manifold && edge_count[e] == 2;
    return 2 * umbrellas + manifold;
  };
  std::vector<int> seeds;
  {
    detail::ConcurrentParitySets sets(m, threads);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t e = 0; e < num_edges; ++e) {
      int first = -1;
      for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i) {
        const int t = complex.edgeTriangle(i);
        if (!present[t])
          continue;
        ++edge_count[e];
        if (first < 0)
          first = t;
        else
          sets.unite(first, t, 0);
      }
    }
    // Per component (at its root) its seed: the best score, then the lowest triangle.
    std::vector<std::uint64_t> best(m, 0);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (int t = 0; t < m; ++t) {
      if (!present[t])
        continue;
      const std::uint64_t key =
          std::uint64_t(score(t) + 1) << 32 | static_cast<std::uint32_t>(m - t);
      std::uint64_t* target = &best[sets.find(t).root];
      std::uint64_t seen = __atomic_load_n(target, __ATOMIC_RELAXED);
      while (key > seen &&
             !__atomic_compare_exchange_n(
                 target, &seen, key, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
      }
    }
    // The components in the order of their lowest triangles.
    for (int t = 0; t < m; ++t)
      if (present[t] && sets.find(t).root == t)
        seeds.push_back(m - static_cast<int>(best[t] & 0xffffffffu));
  }
  out.components = seeds.size();

  // The walk, as in the paper: every edge is processed once.
  std::vector<std::uint8_t> processed(complex.numEdges(), 0);
  std::vector<Triangle> oriented(m);
  std::vector<std::uint8_t> in_surface(m, 0);
  struct Pending {
    int x, y, t;
  };
  std::vector<Pending> pending;
  // After one walk per component, a walk from every present triangle none of whose
  // vertices the surface uses yet: a component joined to another by stray
  // candidate triangles that the walk does not cross still gets its own walk.
  std::vector<std::uint8_t> used(complex.points().size(), 0);
  const auto free = [&](int t) {
    const auto& v = complex.triangle(t);
    return !in_surface[t] && !used[v[0]] && !used[v[1]] && !used[v[2]];
  };
  // Gathered once the component walks are done: a triangle not free then never
  // becomes free (the surface and its vertices only grow), and mostly none is.
  std::vector<int> reseeds;
  bool gathered = false;
  std::size_t next_component = 0, next_reseed = 0;
  const auto next_seed = [&]() {
    if (next_component < seeds.size())
      return seeds[next_component++];
    if (!gathered) {
      gathered = true;
      for (int t = 0; t < m; ++t)
        if (present[t] && free(t))
          reseeds.push_back(t);
      std::stable_sort(reseeds.begin(), reseeds.end(), [&](int a, int b) {
        return score(a) > score(b);
      });
    }
    for (; next_reseed < reseeds.size(); ++next_reseed) {
      const int t = reseeds[next_reseed];
      if (free(t)) {
        ++out.reseeds;
        return t;
      }
    }
    return -1;
  };
  for (int s = next_seed(); s >= 0; s = next_seed()) {
    const auto& v = complex.triangle(s);
    oriented[s] = v;
    in_surface[s] = 1;
    out.triangles.push_back(v);
    out.ids.push_back(s);
    used[v[0]] = used[v[1]] = used[v[2]] = 1;
    pending = {{v[2], v[0], s}, {v[1], v[2], s}, {v[0], v[1], s}};
    while (!pending.empty()) {
      const Pending p = pending.back();
      pending.pop_back();
      const auto& o = oriented[p.t];
      const int z = o[0] + o[1] + o[2] - p.x - p.y;
      const int e = edgeOpposite(complex, p.t, z);
      if (processed[e])
        continue;
      processed[e] = 1;
      int a = -1;
      const int t2 = neighborAcross(complex, present, p.t, e, p.x, p.y, z, a);
      if (t2 < 0)
        continue;
      const Triangle next{p.y, p.x, a};
      if (in_surface[t2]) {
        // Reached again: keep the first orientation, count a disagreement.
        const auto& q = oriented[t2];
        for (int k = 0; k < 3; ++k)
          if (q[k] == p.x && q[(k + 1) % 3] == p.y)
            ++out.conflicts;
        continue;
      }
      oriented[t2] = next;
      in_surface[t2] = 1;
      out.triangles.push_back(next);
      out.ids.push_back(t2);
      used[a] = 1;
      pending.push_back({a, p.y, t2});
      pending.push_back({p.x, a, t2});
    }
  }
  return out;
}

EdgeIncidences
walkedIncidences(const TriangleComplex& complex, const WalkResult& walked, int threads)
{
  std::vector<int> index(complex.numTriangles(), -1);
  for (std::size_t i = 0; i < walked.ids.size(); ++i)
    index[walked.ids[i]] = static_cast<int>(i);
  // Per part of the complex's edges: its edges and incidences in the walk, counted,
  // then filled in; at an edge in the order of the walk's triangles.
  const std::size_t num_edges = complex.numEdges();
  const int parts = detail::partsFor(num_edges, threads);
  std::vector<std::size_t> edges_before(parts + 1, 0), incidences_before(parts + 1, 0);
  detail::forEachRange(
      num_edges, parts, [&](std::size_t begin, std::size_t end, int part) {
        for (std::size_t e = begin; e < end; ++e) {
          std::size_t here = 0;
          for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i)
            here += index[complex.edgeTriangle(i)] >= 0;
          edges_before[part + 1] += here > 0;
          incidences_before[part + 1] += here;
        }
      });
  std::partial_sum(edges_before.begin(), edges_before.end(), edges_before.begin());
  std::partial_sum(
      incidences_before.begin(), incidences_before.end(), incidences_before.begin());
  EdgeIncidences out;
  out.edges.resize(edges_before[parts]);
  out.first.resize(edges_before[parts] + 1);
  out.triangle.resize(incidences_before[parts]);
  out.forward.resize(incidences_before[parts]);
  detail::forEachRange(
      num_edges, parts, [&](std::size_t begin, std::size_t end, int part) {
        std::size_t w = edges_before[part], iw = incidences_before[part];
        for (std::size_t e = begin; e < end; ++e) {
          const std::size_t from = iw;
          for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i) {
            const int t = index[complex.edgeTriangle(i)];
            if (t < 0)
              continue;
            std::size_t j = iw++;
            for (; j > from && out.triangle[j - 1] > t; --j)
              out.triangle[j] = out.triangle[j - 1];
            out.triangle[j] = t;
          }
          if (iw == from)
            continue;
          const auto& edge = complex.edge(static_cast<int>(e));
          for (std::size_t i = from; i < iw; ++i) {
            const Triangle& v = walked.triangles[out.triangle[i]];
            out.forward[i] = (v[0] == edge[0] && v[1] == edge[1]) ||
                             (v[1] == edge[0] && v[2] == edge[1]) ||
                             (v[2] == edge[0] && v[0] == edge[1]);
          }
          out.edges[w] = edge;
          out.first[w++] = from;
        }
      });
  out.first.back() = out.triangle.size();
  return out;
}

} // namespace cocone
} // namespace pcl
