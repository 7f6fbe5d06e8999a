/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/mesh_checks.h>

#include "edge_sort.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace pcl {
namespace cocone {

namespace {

/** Union-find with path halving. */
struct DisjointSets {
  std::vector<int> parent;

  explicit DisjointSets(std::size_t n = 0) { reset(n); }

  /** n singletons again, reusing the storage. */
  void
  reset(std::size_t n)
  {
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), 0);
  }

  int
  find(int x)
  {
    while (parent[x] != x)
      x = parent[x] = parent[parent[x]];
    return x;
  }

  void
  unite(int a, int b)
  {
    a = find(a);
    b = find(b);
    if (a != b)
      parent[std::max(a, b)] = std::min(a, b);
  }
};

} // namespace

EdgeIncidences::EdgeIncidences(const std::vector<Triangle>& oriented, int threads)
{
  const std::vector<std::uint64_t> word =
      detail::groupEdgeIncidences(oriented, edges, first, threads);
  triangle.resize(word.size());
  forward.resize(word.size());
  const auto size = static_cast<std::ptrdiff_t>(word.size());
#pragma omp parallel for num_threads(threads) schedule(static, 16384)
  for (std::ptrdiff_t i = 0; i < size; ++i) {
    const int t = detail::incidenceTriangle(word[i]),
              k = detail::incidenceCorner(word[i]);
    triangle[i] = t;
    forward[i] = oriented[t][k] < oriented[t][(k + 1) % 3];
  }
}

void
EdgeIncidences::add(const std::vector<Triangle>& oriented, std::size_t from)
{
  // The new triangles grouped on their own, then one merge of the two groupings
  // by edge; at an edge the new triangles come last, as their ids are the highest.
  EdgeIncidences added(std::vector<Triangle>(oriented.begin() + from, oriented.end()));
  for (int& t : added.triangle)
    t += static_cast<int>(from);
  EdgeIncidences merged;
  merged.edges.reserve(edges.size() + added.edges.size());
  merged.first.reserve(edges.size() + added.edges.size() + 1);
  merged.triangle.reserve(triangle.size() + added.triangle.size());
  merged.forward.reserve(triangle.size() + added.triangle.size());
  const auto take = [&merged](const EdgeIncidences& from_list, std::size_t e) {
    const auto begin = from_list.first[e], end = from_list.first[e + 1];
    merged.triangle.insert(merged.triangle.end(),
                           from_list.triangle.begin() + begin,
                           from_list.triangle.begin() + end);
    merged.forward.insert(merged.forward.end(),
                          from_list.forward.begin() + begin,
                          from_list.forward.begin() + end);
  };
  for (std::size_t e = 0, a = 0; e < edges.size() || a < added.edges.size();) {
    const bool old =
        a == added.edges.size() || (e < edges.size() && edges[e] <= added.edges[a]);
    const std::array<int, 2> edge = old ? edges[e] : added.edges[a];
    merged.edges.push_back(edge);
    merged.first.push_back(merged.triangle.size());
    if (old)
      take(*this, e++);
    if (a < added.edges.size() && added.edges[a] == edge)
      take(added, a++);
  }
  merged.first.push_back(merged.triangle.size());
  *this = std::move(merged);
}

std::vector<int>
vertexFans(const std::vector<Triangle>& oriented,
           std::size_t num_vertices,
           std::vector<int>* fans_per_vertex,
           int threads)
{
  // Corners (t, k) sorted by vertex; two corners of a vertex share a fan when their
  // triangles share an edge at the vertex.
  const std::size_t m = oriented.size();
  std::vector<int> corner_first(num_vertices + 1, 0), corners(3 * m);
  for (const auto& t : oriented)
    for (const int v : t)
      ++corner_first[v + 1];
  for (std::size_t v = 0; v < num_vertices; ++v)
    corner_first[v + 1] += corner_first[v];
  std::vector<int> fill(corner_first.begin(), corner_first.end() - 1);
  for (std::size_t t = 0; t < m; ++t)
    for (int k = 0; k < 3; ++k)
      corners[fill[oriented[t][k]]++] = static_cast<int>(3 * t + k);

  std::vector<int> fan(3 * m, -1);
  if (fans_per_vertex)
    fans_per_vertex->assign(num_vertices, 0);
#pragma omp parallel num_threads(threads)
  {
    std::vector<std::pair<int, int>> others; // (other vertex, local corner)
    DisjointSets sets;
    std::vector<int> id;
#pragma omp for schedule(dynamic, 4096)
    for (std::ptrdiff_t v = 0; v < static_cast<std::ptrdiff_t>(num_vertices); ++v) {
      const int first = corner_first[v], size = corner_first[v + 1] - first;
      if (size == 0)
        continue;
      sets.reset(size);
      others.clear();
      for (int i = 0; i < size; ++i) {
        const int c = corners[first + i], t = c / 3, k = c % 3;
        others.emplace_back(oriented[t][(k + 1) % 3], i);
        others.emplace_back(oriented[t][(k + 2) % 3], i);
      }
      std::sort(others.begin(), others.end());
      for (std::size_t j = 1; j < others.size(); ++j)
        if (others[j].first == others[j - 1].first)
          sets.unite(others[j].second, others[j - 1].second);
      id.assign(size, -1);
      int fans = 0;
      for (int i = 0; i < size; ++i) {
        const int r = sets.find(i);
        if (id[r] < 0)
          id[r] = fans++;
        fan[corners[first + i]] = id[r];
      }
      if (fans_per_vertex)
        (*fans_per_vertex)[v] = fans;
    }
  }
  return fan;
}

std::vector<int>
triangleComponents(const std::vector<Triangle>& oriented, std::size_t* count)
{
  return triangleComponents(EdgeIncidences(oriented), oriented.size(), count);
}

std::vector<int>
triangleComponents(const EdgeIncidences& inc,
                   std::size_t num_triangles,
                   std::size_t* count)
{
  DisjointSets sets(num_triangles);
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    for (std::size_t i = inc.first[e] + 1; i < inc.first[e + 1]; ++i)
      sets.unite(inc.triangle[i], inc.triangle[inc.first[e]]);
  std::vector<int> id(num_triangles, -1), out(num_triangles);
  int n = 0;
  for (std::size_t t = 0; t < num_triangles; ++t) {
    const int r = sets.find(static_cast<int>(t));
    if (id[r] < 0)
      id[r] = n++;
    out[t] = id[r];
  }
  if (count)
    *count = static_cast<std::size_t>(n);
  return out;
}

MeshTopology
analyzeMesh(const std::vector<Triangle>& oriented, std::size_t num_vertices)
{
  MeshTopology topo;
  topo.triangles = oriented.size();
  const EdgeIncidences inc(oriented);
  topo.edges = inc.edges.size();
  std::size_t components = 0;
  const std::vector<int> comp = triangleComponents(inc, oriented.size(), &components);
  topo.components = components;
  std::vector<std::uint8_t> open(components, 0);
  for (std::size_t e = 0; e < inc.edges.size(); ++e) {
    const std::size_t n = inc.count(e);
    if (n == 1) {
      ++topo.boundary_edges;
      open[comp[inc.triangle[inc.first[e]]]] = 1;
    }
    else if (n > 2)
      ++topo.nonmanifold_edges;
    else if (inc.forward[inc.first[e]] == inc.forward[inc.first[e] + 1])
      ++topo.orientation_conflicts;
  }
  for (const auto o : open)
    topo.closed_components += !o;
  std::vector<int> fans;
  vertexFans(oriented, num_vertices, &fans);
  for (const int f : fans) {
    topo.vertices += f > 0;
    topo.nonmanifold_vertices += f > 1;
  }
  topo.euler = static_cast<long>(topo.vertices) - static_cast<long>(topo.edges) +
               static_cast<long>(topo.triangles);
  return topo;
}

std::vector<std::vector<int>>
boundaryLoops(const std::vector<Triangle>& oriented, std::size_t num_vertices)
{
  return boundaryLoops(EdgeIncidences(oriented), num_vertices);
}

std::vector<std::vector<int>>
boundaryLoops(const EdgeIncidences& inc, std::size_t num_vertices)
{
  // The border half-edges a -> b as the triangles traverse them.
  std::vector<int> next(num_vertices, -1);
  std::vector<int> starts;
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (inc.count(e) == 1) {
      const std::size_t i = inc.first[e];
      const int a = inc.forward[i] ? inc.edges[e][0] : inc.edges[e][1];
      const int b = inc.forward[i] ? inc.edges[e][1] : inc.edges[e][0];
      next[a] = b;
      starts.push_back(a);
    }
  std::sort(starts.begin(), starts.end());
  std::vector<std::vector<int>> loops;
  for (const int s : starts) {
    if (next[s] < 0)
      continue; // already on a loop
    std::vector<int> loop;
    int v = s;
    while (v >= 0 && next[v] >= 0) {
      loop.push_back(v);
      const int w = next[v];
      next[v] = -1;
      v = w;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

std::vector<int>
borderVertices(const std::vector<Triangle>& triangles)
{
  const EdgeIncidences inc(triangles);
  std::vector<int> border;
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (inc.count(e) == 1)
      border.insert(border.end(), inc.edges[e].begin(), inc.edges[e].end());
  std::sort(border.begin(), border.end());
  border.erase(std::unique(border.begin(), border.end()), border.end());
  return border;
}

} // namespace cocone
} // namespace pcl
