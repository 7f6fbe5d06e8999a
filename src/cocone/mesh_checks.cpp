/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/mesh_checks.h>

#include <Eigen/Geometry>

#include "disjoint_sets.h"
#include "edge_sort.h"

#include <algorithm>
#include <cstdint>

namespace pcl {
namespace cocone {

using detail::DisjointSets;

EdgeIncidences::EdgeIncidences(const std::vector<Triangle>& oriented, int threads)
{
  const detail::LargeVector<std::uint64_t> word =
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

std::ptrdiff_t
EdgeIncidences::find(int a, int b) const
{
  const std::array<int, 2> key{std::min(a, b), std::max(a, b)};
  const auto it = std::lower_bound(edges.begin(), edges.end(), key);
  return it != edges.end() && *it == key ? it - edges.begin() : -1;
}

void
EdgeIncidences::remove(const std::vector<std::uint8_t>& dropped)
{
  std::vector<int> renumbered(dropped.size(), -1);
  int kept = 0;
  for (std::size_t t = 0; t < dropped.size(); ++t)
    if (!dropped[t])
      renumbered[t] = kept++;
  std::size_t e2 = 0, i2 = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const std::size_t begin = first[e], end = first[e + 1];
    first[e2] = i2;
    for (std::size_t i = begin; i < end; ++i)
      if (renumbered[triangle[i]] >= 0) {
        triangle[i2] = renumbered[triangle[i]];
        forward[i2++] = forward[i];
      }
    if (i2 > first[e2])
      edges[e2++] = edges[e];
  }
  edges.resize(e2);
  first.resize(e2 + 1);
  first[e2] = i2;
  triangle.resize(i2);
  forward.resize(i2);
}

void
EdgeIncidences::add(const std::vector<Triangle>& oriented, std::size_t from)
{
  // The new triangles grouped on their own, then merged in place from the back: the
  // old lists between two new edges move as one block. At an edge the new triangles
  // come last, as their ids are the highest.
  EdgeIncidences added(std::vector<Triangle>(oriented.begin() + from, oriented.end()));
  for (int& t : added.triangle)
    t += static_cast<int>(from);
  const std::size_t old_edges = edges.size(), old_incidences = triangle.size();
  // Per new edge: the old edges before it, and whether it is one of them.
  std::vector<std::size_t> before(added.edges.size());
  std::vector<std::uint8_t> twin(added.edges.size());
  std::size_t fresh = 0;
  for (std::size_t a = 0; a < added.edges.size(); ++a) {
    const auto it = std::lower_bound(edges.begin(), edges.end(), added.edges[a]);
    before[a] = static_cast<std::size_t>(it - edges.begin());
    twin[a] = it != edges.end() && *it == added.edges[a];
    fresh += !twin[a];
  }
  edges.resize(old_edges + fresh);
  first.resize(old_edges + fresh + 1);
  triangle.resize(old_incidences + added.triangle.size());
  forward.resize(triangle.size());
  // Old edges [0, e) and their incidences [0, i) are still in their old places; the
  // merged ones from w and iw on are in their new places.
  std::size_t e = old_edges, i = old_incidences, w = edges.size(), iw = triangle.size();
  // Move the old incidences [from, i) up to end at iw.
  const auto lift = [&](std::size_t from) {
    std::move_backward(
        triangle.begin() + from, triangle.begin() + i, triangle.begin() + iw);
    std::move_backward(
        forward.begin() + from, forward.begin() + i, forward.begin() + iw);
    iw -= i - from;
    i = from;
  };
  first.back() = triangle.size();
  for (std::size_t a = added.edges.size(); a-- > 0;) {
    // The old edges after this one, up to end at w. (first[e] may be a merged
    // edge's already.)
    const std::size_t to = before[a] + twin[a], shift = iw - i;
    lift(to == e ? i : first[to]);
    for (std::size_t k = e; k-- > to;) {
      --w;
      edges[w] = edges[k];
      first[w] = first[k] + shift;
    }
    e = to;
    // The new incidences of the edge, after its old ones if it had any.
    const std::size_t begin = added.first[a], end = added.first[a + 1];
    iw -= end - begin;
    std::copy(added.triangle.begin() + begin,
              added.triangle.begin() + end,
              triangle.begin() + iw);
    std::copy(added.forward.begin() + begin,
              added.forward.begin() + end,
              forward.begin() + iw);
    if (twin[a])
      lift(first[--e]);
    --w;
    edges[w] = added.edges[a];
    first[w] = iw;
  }
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
  std::vector<int> corners(3 * m);
  const detail::LargeVector<std::uint32_t> corner_first = detail::groupCorners(
      oriented,
      num_vertices,
      threads,
      [](const Triangle& t, int k) { return t[k]; },
      [&](std::size_t t, int k, std::uint32_t place) {
        corners[place] = static_cast<int>(3 * t + k);
      });

  std::vector<int> fan(3 * m, -1);
  constexpr int SMALL_STAR = 12;
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
      // Most stars are one fan: walked from the first triangle both ways, from one
      // triangle to an unseen one that shares an edge at v, it takes them all.
      const auto other = [&](int i, int side) {
        return others[2 * static_cast<std::size_t>(i) + side].first;
      };
      std::uint32_t seen = 1;
      int count = 1;
      for (int side = 0; side < 2 && size <= SMALL_STAR; ++side)
        for (int w = other(0, side);;) {
          int next = 0;
          while (next < size &&
                 ((seen >> next & 1u) || (other(next, 0) != w && other(next, 1) != w)))
            ++next;
          if (next == size)
            break;
          seen |= 1u << next;
          ++count;
          w = other(next, 0) == w ? other(next, 1) : other(next, 0);
        }
      if (count == size) {
        for (int i = 0; i < size; ++i)
          fan[corners[first + i]] = 0;
        if (fans_per_vertex)
          (*fans_per_vertex)[v] = 1;
        continue;
      }
      if (size <= SMALL_STAR) {
        // A few triangles: compare every two, cheaper than sorting.
        for (int i = 1; i < size; ++i)
          for (int j = 0; j < i; ++j) {
            const auto* a = &others[2 * static_cast<std::size_t>(i)];
            const auto* b = &others[2 * static_cast<std::size_t>(j)];
            if (a[0].first == b[0].first || a[0].first == b[1].first ||
                a[1].first == b[0].first || a[1].first == b[1].first)
              sets.unite(i, j);
          }
      }
      else {
        std::sort(others.begin(), others.end());
        for (std::size_t j = 1; j < others.size(); ++j)
          if (others[j].first == others[j - 1].first)
            sets.unite(others[j].second, others[j - 1].second);
      }
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

std::vector<double>
signedVolumes(const std::vector<Eigen::Vector3d>& points,
              const std::vector<Triangle>& triangles,
              const std::vector<int>& component,
              std::size_t count)
{
  // About the centroid rather than the origin: far from the origin the sum would
  // cancel large terms. Both sums in the order of the triangles (deterministic).
  std::vector<Eigen::Vector3d> centre(count, Eigen::Vector3d::Zero());
  std::vector<std::size_t> size(count, 0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& v = triangles[t];
    centre[component[t]] += points[v[0]] + points[v[1]] + points[v[2]];
    ++size[component[t]];
  }
  for (std::size_t c = 0; c < count; ++c)
    if (size[c] > 0)
      centre[c] /= 3.0 * static_cast<double>(size[c]);
  std::vector<double> volume(count, 0.0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& v = triangles[t];
    const Eigen::Vector3d& o = centre[component[t]];
    volume[component[t]] +=
        (points[v[0]] - o).dot((points[v[1]] - o).cross(points[v[2]] - o));
  }
  return volume;
}

MeshTopology
analyzeMesh(const std::vector<Triangle>& oriented, std::size_t num_vertices)
{
  return analyzeMesh(oriented, num_vertices, EdgeIncidences(oriented));
}

MeshTopology
analyzeMesh(const std::vector<Triangle>& oriented,
            std::size_t num_vertices,
            const EdgeIncidences& inc)
{
  MeshTopology topo;
  topo.triangles = oriented.size();
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

std::vector<std::uint8_t>
borderMask(const EdgeIncidences& inc, std::size_t num_vertices)
{
  std::vector<std::uint8_t> border(num_vertices, 0);
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (inc.count(e) == 1)
      border[inc.edges[e][0]] = border[inc.edges[e][1]] = 1;
  return border;
}

std::vector<std::uint8_t>
usedVertices(const std::vector<Triangle>& triangles, std::size_t num_vertices)
{
  std::vector<std::uint8_t> used(num_vertices, 0);
  for (const auto& t : triangles)
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  return used;
}

} // namespace cocone
} // namespace pcl
