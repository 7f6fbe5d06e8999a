/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/repair.h>

#include <CGAL/Simple_cartesian.h>

#include <Eigen/Geometry>

#include "least_perimeter.h"
#include "parallel.h"

#include <algorithm>
#include <array>
#include <limits>
#include <queue>
#include <tuple>
#include <unordered_map>

namespace pcl {
namespace cocone {

namespace {

Eigen::Vector3d
unitNormal(const std::vector<Eigen::Vector3d>& P, const Triangle& t)
{
  const Eigen::Vector3d n = (P[t[1]] - P[t[0]]).cross(P[t[2]] - P[t[0]]);
  const double len = n.norm();
  return len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

/** The edge incidences of \a triangles: \a known if given and grouped, else grouped
 * into \a storage. */
const EdgeIncidences&
incidencesOf(const std::vector<Triangle>& triangles,
             const EdgeIncidences* known,
             EdgeIncidences& storage)
{
  if (known && known->grouped())
    return *known;
  storage = EdgeIncidences(triangles);
  return storage;
}

/** At every edge with more than two triangles keep the best pair. */
std::size_t
resolveEdges(const std::vector<Eigen::Vector3d>& P,
             std::vector<Triangle>& triangles,
             EdgeIncidences& inc)
{
  std::vector<std::uint8_t> drop(triangles.size(), 0);
  bool any = false;
  for (std::size_t e = 0; e < inc.edges.size(); ++e) {
    if (inc.count(e) <= 2)
      continue;
    const std::size_t f = inc.first[e], l = inc.first[e + 1];
    std::size_t bi = f, bj = f + 1;
    double best = -1e300;
    for (std::size_t i = f; i < l; ++i)
      for (std::size_t j = i + 1; j < l; ++j) {
        const double agree = unitNormal(P, triangles[inc.triangle[i]])
                                 .dot(unitNormal(P, triangles[inc.triangle[j]]));
        // A pair that traverses the edge the same way cannot be kept as it is.
        const double s = agree - (inc.forward[i] == inc.forward[j] ? 10.0 : 0.0);
        if (s > best) {
          best = s;
          bi = i;
          bj = j;
        }
      }
    for (std::size_t i = f; i < l; ++i)
      if (i != bi && i != bj) {
        drop[inc.triangle[i]] = 1;
        any = true;
      }
  }
  return any ? removeTriangles(triangles, drop, &inc) : 0;
}

/** At every vertex with several fans keep the largest; with \a only, at the vertices
 * it marks (the others' fans are not looked at). The vertices of the dropped
 * triangles are marked in \a touched. */
std::size_t
resolveVertices(std::vector<Triangle>& triangles,
                EdgeIncidences& inc,
                std::size_t num_vertices,
                int threads,
                const std::vector<std::uint8_t>* only,
                std::vector<std::uint8_t>& touched)
{
  // With \a only: the stars of the marked vertices, by their ids in triangles.
  std::vector<int> subset;
  std::vector<Triangle> stars;
  if (only)
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const auto& v = triangles[t];
      if ((*only)[v[0]] || (*only)[v[1]] || (*only)[v[2]]) {
        subset.push_back(static_cast<int>(t));
        stars.push_back(v);
      }
    }
  const std::vector<Triangle>& list = only ? stars : triangles;
  const auto considered = [&](int v) { return !only || (*only)[v]; };
  std::vector<int> fans;
  const std::vector<int> fan = vertexFans(list, num_vertices, &fans, threads);
  touched.assign(num_vertices, 0);
  const auto several = [&](int v) { return fans[v] > 1 && considered(v); };
  bool any = false;
  for (std::size_t v = 0; v < num_vertices && !any; ++v)
    any = several(static_cast<int>(v));
  if (!any)
    return 0;
  // The sizes of the fans of the vertices with several.
  std::vector<int> size_first(num_vertices + 1, 0);
  for (std::size_t v = 0; v < num_vertices; ++v)
    size_first[v + 1] = size_first[v] + (several(static_cast<int>(v)) ? fans[v] : 0);
  std::vector<int> size(size_first.back(), 0);
  for (std::size_t c = 0; c < fan.size(); ++c) {
    const int v = list[c / 3][c % 3];
    if (size_first[v + 1] > size_first[v])
      ++size[size_first[v] + fan[c]];
  }
  std::vector<int> keep(num_vertices, 0);
  for (std::size_t v = 0; v < num_vertices; ++v)
    if (size_first[v + 1] > size_first[v]) {
      const auto b = size.begin() + size_first[v];
      keep[v] = static_cast<int>(std::max_element(b, b + fans[v]) - b);
    }
  std::vector<std::uint8_t> drop(triangles.size(), 0);
  for (std::size_t c = 0; c < fan.size(); ++c) {
    const int v = list[c / 3][c % 3];
    if (size_first[v + 1] > size_first[v] && fan[c] != keep[v]) {
      const std::size_t t = only ? subset[c / 3] : c / 3;
      drop[t] = 1;
      for (const int w : triangles[t])
        touched[w] = 1;
    }
  }
  return removeTriangles(triangles, drop, &inc);
}

/** Orient each component consistently and outward; returns triangles that could not
 * be oriented (dropped). \a inc follows. */
std::size_t
orient(const std::vector<Eigen::Vector3d>& P,
       std::vector<Triangle>& triangles,
       EdgeIncidences& inc,
       std::size_t& flipped,
       int threads)
{
  // inc's edges and triangles stay valid while triangles are turned over: whether
  // two neighbours run their edge the same way (and so disagree) is read from the
  // incidences once, and follows from the turns since.
  const std::size_t m = triangles.size();
  std::vector<std::uint8_t> turned_over(m, 0); // each turn toggles it
  const auto turn = [&](int t) {
    std::swap(triangles[t][1], triangles[t][2]);
    turned_over[t] ^= 1;
  };
  // Per triangle, in the order of its edges: the neighbour across each (-1 at a
  // border edge), and whether it ran the edge the same way at first.
  std::vector<std::array<int, 3>> across(m, {-1, -1, -1});
  std::vector<std::array<std::uint8_t, 3>> alike(m, {0, 0, 0});
  // Edge k of a triangle: the k-th of its edges in ascending order.
  const auto edge_rank = [&](int t, const std::array<int, 2>& edge) {
    const auto& v = triangles[t];
    int k = 0;
    for (int c = 0; c < 3; ++c) {
      const int a = v[c], b = v[(c + 1) % 3];
      k += std::array<int, 2>{std::min(a, b), std::max(a, b)} < edge;
    }
    return k;
  };
  const auto num_edges = static_cast<std::ptrdiff_t>(inc.edges.size());
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
  for (std::ptrdiff_t e = 0; e < num_edges; ++e) {
    if (inc.count(e) != 2)
      continue;
    for (std::size_t i = inc.first[e], j = i + 1; i < inc.first[e + 1]; ++i, --j) {
      const int t = inc.triangle[i], k = edge_rank(t, inc.edges[e]);
      across[t][k] = inc.triangle[j];
      alike[t][k] = inc.forward[i] == inc.forward[j];
    }
  }
  const auto disagree = [&](int t, int k) {
    return (alike[t][k] ^ turned_over[t] ^ turned_over[across[t][k]]) != 0;
  };

  // A component that can be oriented has one orientation given its lowest
  // triangle's: a union-find with parity (turned or not relative to the root, its
  // lowest triangle) finds it in parallel, and tells a component that cannot be
  // oriented by an edge whose parities disagree.
  const auto num_triangles = static_cast<std::ptrdiff_t>(m);
  std::vector<int> component(m, -1);
  std::vector<std::uint8_t> knotted(m, 0); // per root: cannot be oriented
  {
    detail::ConcurrentParitySets sets(m, threads);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t t = 0; t < num_triangles; ++t)
      for (int k = 0; k < 3; ++k)
        if (across[t][k] > t)
          sets.unite(static_cast<int>(t), across[t][k], alike[t][k]);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t t = 0; t < num_triangles; ++t) {
      const auto found = sets.find(static_cast<int>(t));
      component[t] = found.root;
      turned_over[t] = static_cast<std::uint8_t>(found.parity);
    }
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
    for (std::ptrdiff_t t = 0; t < num_triangles; ++t)
      for (int k = 0; k < 3; ++k)
        if (across[t][k] > t && disagree(static_cast<int>(t), k))
          __atomic_store_n(&knotted[component[t]], 1, __ATOMIC_RELAXED);
  }
  std::size_t turns = 0;
#pragma omp parallel for num_threads(threads) schedule(static, 8192) reduction(+ : turns)
  for (std::ptrdiff_t t = 0; t < num_triangles; ++t) {
    if (knotted[component[t]])
      turned_over[t] = 0;
    else if (turned_over[t]) {
      std::swap(triangles[t][1], triangles[t][2]);
      ++turns;
    }
  }
  flipped += turns;

  // A component that cannot be oriented grows from its lowest triangle, across the
  // edge whose two triangles, oriented alike, agree best in their normals first
  // (Prim's order). The disagreement then lands on the fold's own edges (a fold that
  // a walk left near a border), not on a seam wherever two fronts of a
  // breadth-first pass happen to meet.
  std::vector<Eigen::Vector3d> normal; // of the triangles grown in Prim's order
  std::vector<int> order(m, -1);
  std::vector<std::uint8_t> drop(m, 0);
  std::vector<int> members;
  // (agreement, -triangle, -parent): the best agreement first, ties by lowest ids.
  using Entry = std::tuple<double, int, int>;
  std::priority_queue<Entry> heap;
  int rank = 0;
  const auto offer = [&](int t) {
    for (int k = 0; k < 3; ++k) {
      const int t2 = across[t][k];
      if (t2 < 0 || component[t2] >= 0)
        continue;
      const double agree =
          normal[t].dot(disagree(t, k) ? Eigen::Vector3d(-normal[t2]) : normal[t2]);
      heap.emplace(agree, -t2, -t);
    }
  };
  const bool any_knotted =
      std::find(knotted.begin(), knotted.end(), 1) != knotted.end();
  if (any_knotted) {
    normal.resize(m);
    for (std::size_t t = 0; t < m; ++t)
      if (knotted[component[t]]) {
        component[t] = -1;
        normal[t] = unitNormal(P, triangles[t]);
      }
  }
  for (std::size_t s = 0; any_knotted && s < m; ++s) {
    if (!knotted[s]) // only roots are marked
      continue;
    members.assign(1, static_cast<int>(s));
    component[s] = static_cast<int>(s);
    order[s] = rank++;
    offer(static_cast<int>(s));
    while (!heap.empty()) {
      const int t2 = -std::get<1>(heap.top()), t = -std::get<2>(heap.top());
      heap.pop();
      if (component[t2] >= 0)
        continue;
      component[t2] = static_cast<int>(s);
      order[t2] = rank++;
      members.push_back(t2);
      int k = 0; // the side of t2 towards t
      while (across[t2][k] != t)
        ++k;
      if (disagree(t2, k)) {
        turn(t2);
        normal[t2] = -normal[t2];
        ++flipped;
      }
      offer(t2);
    }
    // A non-orientable cycle closes at an edge whose triangles still disagree: drop
    // the one reached later (through the worse edge).
    for (const int t : members)
      for (int k = 0; k < 3; ++k) {
        const int t2 = across[t][k];
        if (t2 >= 0 && t2 < t && disagree(t, k) && !drop[t] && !drop[t2])
          drop[order[t] > order[t2] ? t : t2] = 1;
      }
  }

  // Turn each component so that its signed volume about its centroid is positive.
  // The components are renumbered in the order of their roots, in place (a root is
  // its component's lowest triangle, so it is numbered before its members).
  std::size_t components = 0;
  for (std::size_t t = 0; t < m; ++t) {
    if (component[t] == static_cast<int>(t))
      order[t] = static_cast<int>(components++);
    component[t] = order[component[t]];
  }
  const std::vector<double> volume = signedVolumes(P, triangles, component, components);
#pragma omp parallel for num_threads(threads) schedule(static, 8192)
  for (std::ptrdiff_t t = 0; t < num_triangles; ++t)
    if (volume[component[t]] < 0.0)
      turn(static_cast<int>(t));
  // The same edges; the turned triangles run them the other way.
  const auto incidences = static_cast<std::ptrdiff_t>(inc.triangle.size());
#pragma omp parallel for num_threads(threads) schedule(static, 16384)
  for (std::ptrdiff_t i = 0; i < incidences; ++i)
    inc.forward[i] ^= turned_over[inc.triangle[i]];
  return removeTriangles(triangles, drop, &inc);
}

} // namespace

std::size_t
removeTriangles(std::vector<Triangle>& triangles,
                const std::vector<std::uint8_t>& drop,
                EdgeIncidences* inc)
{
  std::size_t j = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t)
    if (!drop[t])
      triangles[j++] = triangles[t];
  const std::size_t dropped = triangles.size() - j;
  triangles.resize(j);
  if (inc && dropped)
    inc->remove(drop);
  return dropped;
}

void
repairManifold(const std::vector<Eigen::Vector3d>& points,
               std::vector<Triangle>& triangles,
               RepairCounts& counts,
               int threads,
               EdgeIncidences* incidences,
               const std::vector<std::uint8_t>* whole_stars)
{
  // Grouped once: each step that drops triangles takes them out of the grouping.
  EdgeIncidences inc = incidences && incidences->grouped()
                           ? std::move(*incidences)
                           : EdgeIncidences(triangles, threads);
  for (;;) {
    if (const std::size_t d = resolveEdges(points, triangles, inc)) {
      counts.nonmanifold_edge += d;
      continue;
    }
    // Dropping triangles adds no triangle to an edge and changes only the stars of
    // their vertices: those are checked again until none has several fans.
    std::vector<std::uint8_t> touched, again;
    std::size_t dropped = 0;
    std::size_t d =
        resolveVertices(triangles, inc, points.size(), threads, whole_stars, touched);
    while (d > 0) {
      dropped += d;
      if (whole_stars)
        for (std::size_t v = 0; v < touched.size(); ++v)
          touched[v] &= (*whole_stars)[v];
      d = resolveVertices(triangles, inc, points.size(), threads, &touched, again);
      touched.swap(again);
    }
    counts.nonmanifold_vertex += dropped;
    d = orient(points, triangles, inc, counts.flipped, threads);
    if (d == 0) {
      if (incidences)
        *incidences = std::move(inc);
      return;
    }
    counts.orientation += d;
  }
}

std::size_t
fillHoles(const std::vector<Eigen::Vector3d>& points,
          std::vector<Triangle>& triangles,
          const std::function<bool(const Triangle&)>& allowed,
          std::size_t max_edges,
          EdgeIncidences* incidences)
{
  const std::size_t num_vertices = points.size();
  EdgeIncidences grouped;
  const EdgeIncidences& inc = incidencesOf(triangles, incidences, grouped);
  // Hole half-edges run against the border half-edges of the triangles.
  std::vector<int> hole_next(num_vertices, -1);
  std::vector<int> starts;
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (inc.count(e) == 1) {
      const bool fwd = inc.forward[inc.first[e]];
      const int a = fwd ? inc.edges[e][0] : inc.edges[e][1];
      const int b = fwd ? inc.edges[e][1] : inc.edges[e][0];
      hole_next[b] = a;
      starts.push_back(b);
    }
  // Edge ab of the mesh as it was before the filling: its id, or -1.
  const auto edge_id = [&](int a, int b) { return inc.find(a, b); };
  // Whether the mesh had triangle abc: one of the triangles at ab has c.
  const auto had = [&](int a, int b, int c) {
    const auto e = edge_id(a, b);
    if (e >= 0)
      for (std::size_t i = inc.first[e]; i < inc.first[e + 1]; ++i) {
        const Triangle& t = triangles[inc.triangle[i]];
        if (t[0] == c || t[1] == c || t[2] == c)
          return true;
      }
    return false;
  };
  const std::size_t before = triangles.size();
  std::sort(starts.begin(), starts.end());
  std::vector<std::uint8_t> done(num_vertices, 0);
  std::vector<int> loop;
  detail::LeastPerimeterScratch scratch;
  std::size_t added = 0;
  for (const int x : starts) {
    if (done[x])
      continue;
    loop.clear();
    for (int v = x; v >= 0 && !done[v]; v = hole_next[v]) {
      done[v] = 1;
      loop.push_back(v);
    }
    const std::size_t k = loop.size();
    if (k < 3 || k > max_edges || hole_next[loop.back()] != x)
      continue;
    // The triangulation of the hole's polygon by allowed triangles with the least
    // total perimeter; no new edge may already be in the mesh.
    const auto valid = [&](std::size_t i, std::size_t m, std::size_t j) {
      Triangle key{loop[i], loop[m], loop[j]};
      std::sort(key.begin(), key.end());
      if (!allowed(key) || had(loop[i], loop[m], loop[j]))
        return false;
      const auto diagonal = [&](std::size_t a, std::size_t b) {
        return b - a >= 2 && !(a == 0 && b == k - 1);
      };
      return !(diagonal(i, m) && edge_id(loop[i], loop[m]) >= 0) &&
             !(diagonal(m, j) && edge_id(loop[m], loop[j]) >= 0) &&
             !(diagonal(i, j) && edge_id(loop[i], loop[j]) >= 0);
    };
    const std::size_t size = triangles.size();
    if (detail::leastPerimeterTriangulation(points, loop, valid, triangles, scratch))
      added += triangles.size() - size;
  }
  if (incidences && &inc == &grouped)
    *incidences = std::move(grouped);
  if (added && incidences)
    incidences->add(triangles, before);
  return added;
}

namespace {

/** Drop the components of the mesh that \a drop_component(incidences, component,
 * count) marks (one flag per component, from the triangles' component ids). */
template <typename Mark>
std::size_t
dropComponents(std::vector<Triangle>& triangles,
               EdgeIncidences* incidences,
               const Mark& drop_component)
{
  std::size_t count = 0;
  EdgeIncidences grouped;
  const EdgeIncidences& inc = incidencesOf(triangles, incidences, grouped);
  const std::vector<int> component = triangleComponents(inc, triangles.size(), &count);
  const std::vector<std::uint8_t> marked = drop_component(inc, component, count);
  std::vector<std::uint8_t> drop(triangles.size(), 0);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    drop[t] = marked[component[t]];
  if (incidences && &inc == &grouped)
    *incidences = std::move(grouped);
  return removeTriangles(triangles, drop, incidences);
}

/** Per vertex its component (-1 in no triangle; one at most, as its fan is one) from
 * the triangles' \a component ids, and in \a vertices the vertices of each. */
std::vector<int>
vertexComponents(const std::vector<Triangle>& triangles,
                 const std::vector<int>& component,
                 std::size_t count,
                 std::size_t num_vertices,
                 std::vector<std::size_t>& vertices)
{
  std::vector<int> piece(num_vertices, -1);
  vertices.assign(count, 0);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const int v : triangles[t])
      if (piece[v] < 0) {
        piece[v] = component[t];
        ++vertices[component[t]];
      }
  return piece;
}

} // namespace

std::size_t
dropRibbons(std::vector<Triangle>& triangles,
            std::size_t num_vertices,
            EdgeIncidences* incidences)
{
  return dropComponents(triangles,
                        incidences,
                        [&](const EdgeIncidences& inc,
                            const std::vector<int>& component,
                            std::size_t count) {
                          const std::vector<std::uint8_t> on_border =
                              borderMask(inc, num_vertices);
                          std::vector<std::uint8_t> ribbon(count, 1);
                          for (std::size_t t = 0; t < triangles.size(); ++t)
                            for (const int v : triangles[t])
                              if (!on_border[v])
                                ribbon[component[t]] = 0;
                          return ribbon;
                        });
}

namespace {

/** The edges that are bridges of the dual graph of \a triangles (triangles joined
 * through the edges they share, incidences \a inc): each edge id whose two triangles
 * are joined through it alone. Tarjan's lowpoint search, iterative. */
std::vector<std::size_t>
dualBridges(const std::vector<Triangle>& triangles, const EdgeIncidences& inc)
{
  const std::size_t n = triangles.size();
  // Per triangle its neighbours across its shared edges, and those edges.
  std::vector<std::array<int, 3>> across(n, {-1, -1, -1});
  std::vector<std::array<std::ptrdiff_t, 3>> via(n, {-1, -1, -1});
  std::vector<std::uint8_t> degree(n, 0);
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (inc.count(e) == 2) {
      const int s = inc.triangle[inc.first[e]], t = inc.triangle[inc.first[e] + 1];
      across[s][degree[s]] = t;
      via[s][degree[s]++] = static_cast<std::ptrdiff_t>(e);
      across[t][degree[t]] = s;
      via[t][degree[t]++] = static_cast<std::ptrdiff_t>(e);
    }
  std::vector<int> order(n, -1), low(n, 0);
  std::vector<std::ptrdiff_t> entered_by(n, -1);
  std::vector<std::pair<int, int>> stack; // (triangle, next neighbour slot)
  std::vector<std::size_t> bridges;
  int clock = 0;
  for (std::size_t root = 0; root < n; ++root) {
    if (order[root] >= 0)
      continue;
    order[root] = low[root] = clock++;
    stack.emplace_back(static_cast<int>(root), 0);
    while (!stack.empty()) {
      auto& [t, slot] = stack.back();
      if (slot < degree[t]) {
        const int u = across[t][slot];
        const std::ptrdiff_t e = via[t][slot++];
        if (e == entered_by[t])
          continue;
        if (order[u] < 0) {
          order[u] = low[u] = clock++;
          entered_by[u] = e;
          stack.emplace_back(u, 0);
        }
        else
          low[t] = std::min(low[t], order[u]);
        continue;
      }
      const int done = t;
      stack.pop_back();
      if (stack.empty())
        break;
      const int parent = stack.back().first;
      low[parent] = std::min(low[parent], low[done]);
      if (low[done] > order[parent])
        bridges.push_back(static_cast<std::size_t>(entered_by[done]));
    }
  }
  return bridges;
}

} // namespace

std::size_t
dropBridges(const std::vector<Eigen::Vector3d>& points,
            const std::vector<double>& spacing,
            double max_spacings,
            std::vector<Triangle>& triangles,
            EdgeIncidences* incidences)
{
  if (spacing.empty() || triangles.empty())
    return 0;
  EdgeIncidences local;
  EdgeIncidences& inc = incidences ? *incidences : local;
  if (!inc.grouped())
    inc = EdgeIncidences(triangles);
  std::size_t dropped = 0;
  for (;;) {
    // A bridge's ends are both on borders (round an inner vertex the fan joins the
    // two triangles the other way): without a long edge between border vertices
    // there is none to look for, and the mesh is not searched.
    const std::vector<std::uint8_t> on_border = borderMask(inc, points.size());
    const auto long_edge = [&](std::size_t e) {
      const int a = inc.edges[e][0], b = inc.edges[e][1];
      const double reach = max_spacings * std::max(spacing[a], spacing[b]);
      return inc.count(e) == 2 && on_border[a] && on_border[b] &&
             (points[a] - points[b]).squaredNorm() > reach * reach;
    };
    bool any = false;
    for (std::size_t e = 0; e < inc.edges.size() && !any; ++e)
      any = long_edge(e);
    if (!any)
      return dropped;
    // The bridges whose triangles leave each of their corners one fan (one manifold
    // mesh, as the hole filling needs): a corner's fan, less some triangles, falls
    // into as many fans as it has triangles more than inner edges (those left with
    // both their triangles). Counted once per pass; the bridges dropped in a pass
    // share no corner, so that the counts hold for each.
    std::vector<int> fans(points.size(), 0);
    for (const auto& t : triangles)
      for (const int v : t)
        ++fans[v];
    for (std::size_t e = 0; e < inc.edges.size(); ++e)
      if (inc.count(e) == 2)
        --fans[inc.edges[e][0]], --fans[inc.edges[e][1]];
    std::vector<std::uint8_t> drop(triangles.size(), 0), taken(points.size(), 0);
    std::size_t found = 0;
    for (const std::size_t e : dualBridges(triangles, inc)) {
      if (!long_edge(e))
        continue;
      const std::array<int, 2> pair = {inc.triangle[inc.first[e]],
                                       inc.triangle[inc.first[e] + 1]};
      // Their corners, and per corner the triangles and inner edges they take.
      std::array<int, 4> corner{};
      std::array<int, 4> left{};
      std::size_t k = 0;
      const auto at = [&](int v) {
        const auto i =
            std::find(corner.begin(), corner.begin() + k, v) - corner.begin();
        if (static_cast<std::size_t>(i) == k) {
          corner[k] = v;
          left[k++] = fans[v];
        }
        return i;
      };
      for (const int t : pair)
        for (int c = 0; c < 3; ++c) {
          const int v = triangles[t][c], w = triangles[t][(c + 1) % 3];
          --left[at(v)];
          const std::ptrdiff_t edge = inc.find(v, w);
          // An inner edge of both triangles (the bridge) is counted once.
          if (inc.count(static_cast<std::size_t>(edge)) == 2 &&
              (static_cast<std::size_t>(edge) != e || t == pair[0]))
            ++left[at(v)], ++left[at(w)];
        }
      bool ok = true;
      for (std::size_t i = 0; i < k; ++i)
        ok = ok && left[i] <= 1 && !taken[corner[i]];
      if (!ok)
        continue;
      for (std::size_t i = 0; i < k; ++i)
        taken[corner[i]] = 1;
      drop[pair[0]] = drop[pair[1]] = 1;
      ++found;
    }
    if (found == 0)
      return dropped;
    dropped += removeTriangles(triangles, drop, &inc);
  }
}

std::size_t
dropSpecks(std::vector<Triangle>& triangles,
           std::size_t num_vertices,
           std::size_t min_vertices,
           EdgeIncidences* incidences)
{
  return dropComponents(
      triangles,
      incidences,
      [&](const EdgeIncidences&, const std::vector<int>& component, std::size_t count) {
        std::vector<std::size_t> vertices;
        vertexComponents(triangles, component, count, num_vertices, vertices);
        std::vector<std::uint8_t> speck(count, 0);
        for (std::size_t c = 0; c < count; ++c)
          speck[c] = vertices[c] < min_vertices;
        return speck;
      });
}

/** The most grid cells a triangle is listed in by dropLayers(): a triangle of the
 * mesh spans a few spacings, the cell being the largest spacing of the pieces
 * tested. */
constexpr std::uint64_t MAX_CELLS = 64;

std::size_t
dropLayers(const std::vector<Eigen::Vector3d>& points,
           const std::vector<double>& spacing,
           std::vector<Triangle>& triangles,
           EdgeIncidences* incidences)
{
  return dropComponents(
      triangles,
      incidences,
      [&](const EdgeIncidences&, const std::vector<int>& component, std::size_t count) {
        std::vector<std::uint8_t> layer(count, 0);
        if (count < 2)
          return layer;
        std::vector<std::size_t> vertices;
        const std::vector<int> piece =
            vertexComponents(triangles, component, count, points.size(), vertices);
        const std::size_t largest = *std::max_element(vertices.begin(), vertices.end());
        // The vertices of the smaller pieces, within a box and a reach (the grid's
        // cell) that their spacings give.
        Eigen::AlignedBox3d box;
        double cell = 0.0;
        for (std::size_t v = 0; v < points.size(); ++v)
          if (piece[v] >= 0 && vertices[piece[v]] < largest) {
            box.extend(points[v]);
            cell = std::max(cell, spacing[v]);
          }
        if (box.isEmpty() || !(cell > 0.0) || !std::isfinite(cell))
          return layer;
        box.min().array() -= cell;
        box.max().array() += cell;
        // The triangles that meet the box, in a hash grid of that cell (a key
        // packs the cell's three coordinates, 21 bits each, from the box's corner).
        // A triangle over more cells than MAX_CELLS (one across a wide patch) is
        // left out: it then keeps a piece rather than drop it.
        const auto coordinate = [&](double x, int axis) {
          return static_cast<std::uint64_t>(
              std::clamp((x - box.min()[axis]) / cell, 0.0, double((1 << 21) - 1)));
        };
        const auto key = [](std::uint64_t x, std::uint64_t y, std::uint64_t z) {
          return x | (y << 21) | (z << 42);
        };
        std::unordered_map<std::uint64_t, std::vector<int>> grid;
        for (std::size_t t = 0; t < triangles.size(); ++t) {
          Eigen::AlignedBox3d tbox;
          for (const int v : triangles[t])
            tbox.extend(points[v]);
          if (!tbox.intersects(box))
            continue;
          tbox = tbox.intersection(box);
          std::uint64_t cells = 1;
          for (int axis = 0; axis < 3; ++axis)
            cells *= coordinate(tbox.max()[axis], axis) -
                     coordinate(tbox.min()[axis], axis) + 1;
          if (cells > MAX_CELLS)
            continue;
          for (auto x = coordinate(tbox.min()[0], 0); x <= coordinate(tbox.max()[0], 0);
               ++x)
            for (auto y = coordinate(tbox.min()[1], 1);
                 y <= coordinate(tbox.max()[1], 1);
                 ++y)
              for (auto z = coordinate(tbox.min()[2], 2);
                   z <= coordinate(tbox.max()[2], 2);
                   ++z)
                grid[key(x, y, z)].push_back(static_cast<int>(t));
        }
        // A smaller piece is a layer if each of its vertices has a triangle of a
        // larger piece within its spacing (the cells round it hold them all).
        using Kernel = CGAL::Simple_cartesian<double>;
        const auto point = [&](int v) {
          return Kernel::Point_3(points[v][0], points[v][1], points[v][2]);
        };
        for (std::size_t c = 0; c < count; ++c)
          layer[c] = vertices[c] < largest;
        for (std::size_t v = 0; v < points.size(); ++v) {
          const int c = piece[v];
          if (c < 0 || !layer[c])
            continue;
          const double reach2 = spacing[v] * spacing[v];
          bool within = false;
          const auto around = [&](int axis, std::int64_t step) {
            return static_cast<std::int64_t>(coordinate(points[v][axis], axis)) + step;
          };
          for (std::int64_t dx = -1; dx <= 1 && !within; ++dx)
            for (std::int64_t dy = -1; dy <= 1 && !within; ++dy)
              for (std::int64_t dz = -1; dz <= 1 && !within; ++dz) {
                const std::int64_t x = around(0, dx), y = around(1, dy),
                                   z = around(2, dz);
                if (x < 0 || y < 0 || z < 0)
                  continue;
                const auto found = grid.find(key(static_cast<std::uint64_t>(x),
                                                 static_cast<std::uint64_t>(y),
                                                 static_cast<std::uint64_t>(z)));
                if (found == grid.end())
                  continue;
                for (const int t : found->second) {
                  const Triangle& tri = triangles[t];
                  if (vertices[component[t]] <= vertices[c])
                    continue;
                  if (CGAL::squared_distance(
                          point(static_cast<int>(v)),
                          Kernel::Triangle_3(
                              point(tri[0]), point(tri[1]), point(tri[2]))) <= reach2) {
                    within = true;
                    break;
                  }
                }
              }
          layer[c] = within;
        }
        return layer;
      });
}

} // namespace cocone
} // namespace pcl
