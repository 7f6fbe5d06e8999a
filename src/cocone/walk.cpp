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
  const auto num_triangles = static_cast<std::ptrdiff_t>(m);
  const auto num_edges = static_cast<std::ptrdiff_t>(complex.numEdges());
  WalkResult out;

  // At an edge of exactly two candidate triangles (99.6 % of them) the walk's choice
  // does not depend on the way it arrives: it crosses to the other triangle if that
  // one is present and the two make an angle above pi / 2 (a link), else nowhere.
  // The triangles joined by links form patches, which a walk that reaches one of
  // their triangles floods. They are found in parallel, by a union-find whose parity
  // tells whether a triangle is turned relative to its patch's lowest triangle; a
  // triangle's reference orientation is its vertices in ascending order, which runs
  // the edge opposite its corner 1 downwards and the other two upwards. The walk
  // proper then goes from patch to patch across the other edges, in the paper's way.
  const auto is_link = [&](int e) {
    const std::size_t i = complex.edgeBegin(e);
    return complex.edgeEnd(e) - i == 2 && present[complex.edgeTriangle(i)] &&
           present[complex.edgeTriangle(i + 1)] && !complex.acutePair(e);
  };
  const auto across_link = [&](int e, int t) {
    const std::size_t i = complex.edgeBegin(e);
    return complex.edgeTriangle(i) == t ? complex.edgeTriangle(i + 1)
                                        : complex.edgeTriangle(i);
  };
  // Whether the link at edge e, edge k of a triangle, joins it to t2 turned against
  // it: their reference orientations run e the same way.
  const auto link_parity = [&](int k, int t2, int e) {
    const auto& edges = complex.triangleEdges(t2);
    const int k2 = edges[0] == e ? 0 : edges[1] == e ? 1 : 2;
    return static_cast<int>((k == 1) == (k2 == 1));
  };
  std::vector<int> patch(m, -1);
  std::vector<std::uint8_t> parity(m, 0);
  {
    detail::ConcurrentParitySets sets(m, threads);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t t = 0; t < num_triangles; ++t) {
      if (!present[t])
        continue;
      for (int k = 0; k < 3; ++k) {
        const int e = complex.triangleEdges(static_cast<int>(t))[k];
        const int t2 = across_link(e, static_cast<int>(t));
        if (t2 > t && is_link(e))
          sets.unite(static_cast<int>(t), t2, link_parity(k, t2, e));
      }
    }
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t t = 0; t < num_triangles; ++t)
      if (present[t]) {
        const auto found = sets.find(static_cast<int>(t));
        patch[t] = found.root;
        parity[t] = static_cast<std::uint8_t>(found.parity);
      }
  }
  // Per edge its present triangles; per patch root whether it is twisted (a link
  // whose parities disagree: a band with a half turn).
  std::vector<int> edge_count(num_edges, 0);
  std::vector<std::uint8_t> twisted(m, 0);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
  for (std::ptrdiff_t e = 0; e < num_edges; ++e) {
    for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i)
      edge_count[e] += present[complex.edgeTriangle(i)];
    if (!is_link(static_cast<int>(e)))
      continue;
    const int t = complex.edgeTriangle(complex.edgeBegin(e));
    const int t2 = across_link(static_cast<int>(e), t);
    const auto& edges = complex.triangleEdges(t);
    const int k = edges[0] == e ? 0 : edges[1] == e ? 1 : 2;
    if ((parity[t] ^ parity[t2]) != link_parity(k, t2, static_cast<int>(e)))
      __atomic_store_n(&twisted[patch[t]], 1, __ATOMIC_RELAXED);
  }

  // The connected components of the present triangles through any shared edge: the
  // patches joined across the edges that are not links.
  std::vector<int> component(m, -1);
  {
    detail::ConcurrentParitySets sets(m, threads);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t e = 0; e < num_edges; ++e) {
      if (edge_count[e] < 2 || is_link(static_cast<int>(e)))
        continue;
      int first = -1;
      for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i) {
        const int t = complex.edgeTriangle(i);
        if (!present[t])
          continue;
        if (first < 0)
          first = patch[t];
        else
          sets.unite(first, patch[t], 0);
      }
    }
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t t = 0; t < num_triangles; ++t)
      if (present[t])
        component[t] = sets.find(patch[t]).root;
  }
  const auto score = [&](int t) {
    const auto& v = complex.triangle(t);
    const bool umbrellas = !boundary[v[0]] && !boundary[v[1]] && !boundary[v[2]];
    bool manifold = true;
    for (const int e : complex.triangleEdges(t))
      manifold = manifold && edge_count[e] == 2;
    return 2 * umbrellas + manifold;
  };
  // Per component (at its root, its lowest triangle) its seed: the best score, then
  // the lowest triangle; the components in the order of their roots.
  std::vector<int> seeds;
  {
    std::vector<std::uint64_t> best(m, 0);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t t = 0; t < num_triangles; ++t) {
      if (!present[t])
        continue;
      const std::uint64_t key = std::uint64_t(score(static_cast<int>(t)) + 1) << 32 |
                                static_cast<std::uint32_t>(m - t);
      std::uint64_t* target = &best[component[t]];
      std::uint64_t seen = __atomic_load_n(target, __ATOMIC_RELAXED);
      while (key > seen &&
             !__atomic_compare_exchange_n(
                 target, &seen, key, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
      }
    }
    for (int t = 0; t < m; ++t)
      if (present[t] && component[t] == t)
        seeds.push_back(m - static_cast<int>(best[t] & 0xffffffffu));
  }
  std::vector<int>().swap(component);
  out.components = seeds.size();

  // Per patch its triangles in ascending order (those not present come first).
  std::vector<int> members(m);
  const std::vector<std::uint32_t> member_first = detail::countingSort(
      static_cast<std::size_t>(m),
      static_cast<std::size_t>(m) + 1,
      threads,
      [&](std::size_t t) {
        return patch[t] < 0 ? std::size_t(0) : static_cast<std::size_t>(patch[t]) + 1;
      },
      [&](std::size_t t, std::uint32_t place) {
        members[place] = static_cast<int>(t);
      });
  const auto patch_begin = [&](int root) { return member_first[root + 1]; };
  const auto patch_end = [&](int root) { return member_first[root + 2]; };

  // The walk proper, from patch to patch across the edges of three or more candidate
  // triangles, each edge processed once. A triangle's orientation: its reference,
  // turned over where its patch's turn (set as the walk enters the patch) differs
  // from its parity; in a twisted patch its own turn, set by a breadth-first flood
  // of the links from where the walk entered.
  std::vector<std::uint8_t> entered(m, 0), turn(m, 0), reached, processed(num_edges, 0);
  std::vector<std::uint8_t> used(complex.points().size(), 0);
  std::vector<int> order; // the patches in the order entered
  const auto oriented = [&](int t) {
    Triangle v = complex.triangle(t);
    if ((twisted[patch[t]] ? turn[t] : turn[patch[t]] ^ parity[t]) != 0)
      std::swap(v[1], v[2]);
    return v;
  };
  struct Pending {
    int t, k;
  };
  std::vector<Pending> pending;
  std::vector<int> queue;
  bool marking = false; // the vertices used are marked as the walk enters patches
  const auto enter = [&](int t, bool t_turned) {
    const int root = patch[t];
    entered[root] = 1;
    order.push_back(root);
    if (!twisted[root])
      turn[root] = static_cast<std::uint8_t>(t_turned ^ (parity[t] != 0));
    else {
      // A triangle reached again turned the other way is a conflict of the walk.
      if (reached.empty())
        reached.assign(m, 0);
      queue.assign(1, t);
      turn[t] = t_turned;
      reached[t] = 1;
      for (std::size_t q = 0; q < queue.size(); ++q) {
        const int u = queue[q];
        for (int k = 0; k < 3; ++k) {
          const int e = complex.triangleEdges(u)[k];
          if (!is_link(e))
            continue;
          const int u2 = across_link(e, u);
          const int want = turn[u] ^ link_parity(k, u2, e);
          if (reached[u2]) {
            out.conflicts += u < u2 && turn[u2] != want;
            continue;
          }
          reached[u2] = 1;
          turn[u2] = static_cast<std::uint8_t>(want);
          queue.push_back(u2);
        }
      }
    }
    // Its edges to process wait, to be taken in the order of the triangles.
    for (std::uint32_t i = patch_end(root); i-- > patch_begin(root);) {
      const int s = members[i];
      if (marking)
        for (const int v : complex.triangle(s))
          used[v] = 1;
      for (int k = 3; k-- > 0;) {
        const int e = complex.triangleEdges(s)[k];
        if (complex.edgeEnd(e) - complex.edgeBegin(e) > 2)
          pending.push_back({s, k});
      }
    }
  };
  const auto walk_from = [&](int seed) {
    enter(seed, false);
    while (!pending.empty()) {
      const Pending p = pending.back();
      pending.pop_back();
      const int e = complex.triangleEdges(p.t)[p.k];
      if (processed[e])
        continue;
      processed[e] = 1;
      // The edge as p.t, oriented, runs it: x -> y, z the third vertex.
      const Triangle o = oriented(p.t);
      const int z = complex.triangle(p.t)[p.k];
      const int i = o[0] == z ? 0 : o[1] == z ? 1 : 2;
      const int x = o[(i + 1) % 3], y = o[(i + 2) % 3];
      int a = -1;
      const int t2 = neighborAcross(complex, present, p.t, e, x, y, z, a);
      if (t2 < 0)
        continue;
      if (entered[patch[t2]]) {
        // Reached again: keep the first orientation, count a disagreement.
        const Triangle q = oriented(t2);
        for (int k = 0; k < 3; ++k)
          if (q[k] == x && q[(k + 1) % 3] == y)
            ++out.conflicts;
        continue;
      }
      // t2 oriented (y, x, a): turned unless that is a rotation of its reference.
      const Triangle& r = complex.triangle(t2);
      const int j = r[0] == y ? 0 : r[1] == y ? 1 : 2;
      enter(t2, r[(j + 1) % 3] != x);
    }
  };
  for (const int s : seeds)
    walk_from(s);

  // Then a walk from every present triangle none of whose vertices the surface uses
  // yet: a component joined to another by stray candidate triangles that the walk
  // does not cross still gets its own walk. A triangle not free now never becomes
  // free (the surface and its vertices only grow), and mostly none is.
  const auto in_surface = [&](int t) { return present[t] && entered[patch[t]]; };
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
  for (std::ptrdiff_t t = 0; t < num_triangles; ++t)
    if (in_surface(static_cast<int>(t)))
      for (const int v : complex.triangle(static_cast<int>(t)))
        __atomic_store_n(&used[v], 1, __ATOMIC_RELAXED);
  const auto free = [&](int t) {
    const auto& v = complex.triangle(t);
    return !in_surface(t) && !used[v[0]] && !used[v[1]] && !used[v[2]];
  };
  std::vector<int> reseeds;
  for (int t = 0; t < m; ++t)
    if (present[t] && free(t))
      reseeds.push_back(t);
  std::stable_sort(reseeds.begin(), reseeds.end(), [&](int a, int b) {
    return score(a) > score(b);
  });
  marking = true;
  for (const int t : reseeds)
    if (free(t)) {
      ++out.reseeds;
      walk_from(t);
    }

  // The triangles of the patches in the order entered, each patch's in ascending
  // order.
  std::vector<std::uint32_t> offset(m, 0);
  std::uint32_t total = 0;
  for (const int root : order) {
    offset[root] = total;
    total += patch_end(root) - patch_begin(root);
  }
  out.triangles.resize(total);
  out.ids.resize(total);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
  for (std::ptrdiff_t i = member_first[1]; i < num_triangles; ++i) {
    const int t = members[i];
    const int root = patch[t];
    if (!entered[root])
      continue;
    const std::uint32_t at =
        offset[root] + static_cast<std::uint32_t>(i) - patch_begin(root);
    out.triangles[at] = oriented(t);
    out.ids[at] = t;
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
