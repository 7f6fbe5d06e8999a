/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include <algorithm>
#include <array>
#include <iterator>
#include <set>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/** A patch triangle as CGAL hands it over: indices into the loop. */
struct LoopTriangle {
  LoopTriangle(int a, int b, int c) : v{a, b, c} {}
  std::array<int, 3> v;
};

/** Loops of at most this many edges whose Delaunay patch is not plausible are
 * searched again over all triangles of their vertices (cubic in the edges). */
constexpr std::size_t CUBIC_SEARCH_EDGES = 40;

/** A patch from another mesh may hold at most this many triangles per loop edge:
 * a disk of a loop's k edges with i inner vertices has k + 2i - 2 triangles. */
constexpr std::size_t PATCH_TRIANGLES_PER_EDGE = 16;

bool
sameVertices(Triangle a, Triangle b)
{
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  return a == b;
}

std::array<int, 2>
edgeKey(int a, int b)
{
  return {std::min(a, b), std::max(a, b)};
}

/** Whether edge ab is at most \a reach times the larger local spacing of its ends
 * long: as short as the triangles of the sampling there. */
bool
withinReach(const std::vector<Eigen::Vector3d>& points,
            const std::vector<double>& spacing,
            double reach,
            int a,
            int b)
{
  const double longest = reach * std::max(spacing[a], spacing[b]);
  return (points[a] - points[b]).squaredNorm() <= longest * longest;
}

Kernel::Point_3
toCgal(const Eigen::Vector3d& p)
{
  return {p.x(), p.y(), p.z()};
}

} // namespace

HoleFilling
fillUndersampledHoles(const std::vector<Eigen::Vector3d>& points,
                      const std::vector<double>& spacing,
                      std::vector<Triangle>& triangles,
                      EdgeIncidences& incidences,
                      std::vector<std::vector<int>>& loops,
                      double reach,
                      std::size_t max_edges)
{
  HoleFilling out;
  const std::size_t before = triangles.size();
  std::vector<std::vector<int>> open;
  std::vector<Kernel::Point_3> polyline, third;
  std::vector<LoopTriangle> patch;
  for (auto& loop : loops) {
    const std::size_t k = loop.size();
    if (k < 3 || k > max_edges) {
      open.push_back(std::move(loop));
      continue;
    }
    // The hole runs against the loop, which has the mesh on its left: a triangle
    // of the hole's polygon with its corners in the hole's order faces as the mesh.
    std::vector<int> hole(loop.rbegin(), loop.rend());
    polyline.clear();
    third.clear();
    for (std::size_t i = 0; i < k; ++i) {
      const int a = hole[i], b = hole[(i + 1) % k];
      polyline.push_back(toCgal(points[a]));
      // The third corner of the mesh's triangle at the loop's edge ab.
      const auto e = incidences.find(a, b);
      const Triangle& t = triangles[incidences.triangle[incidences.first[e]]];
      const int c = t[0] != a && t[0] != b   ? t[0]
                    : t[1] != a && t[1] != b ? t[1]
                                             : t[2];
      third.push_back(toCgal(points[c]));
    }
    patch.clear();
    CGAL::Polygon_mesh_processing::triangulate_hole_polyline(
        polyline,
        third,
        std::back_inserter(patch),
        CGAL::parameters::use_delaunay_triangulation(true).do_not_use_cubic_algorithm(
            true));
    // Plausible: every new edge short and not in the mesh yet.
    const auto plausible = [&](int i, int j) {
      if (j < i)
        std::swap(i, j);
      if (j == i + 1 || (i == 0 && j == static_cast<int>(k) - 1))
        return true; // an edge of the loop
      const int a = hole[i], b = hole[j];
      return withinReach(points, spacing, reach, a, b) && incidences.find(a, b) < 0;
    };
    const auto plausible_patch = [&]() {
      bool ok = patch.size() == k - 2;
      for (const auto& t : patch)
        ok = ok && plausible(t.v[0], t.v[1]) && plausible(t.v[1], t.v[2]) &&
             plausible(t.v[0], t.v[2]);
      return ok;
    };
    bool closed = plausible_patch();
    if (!closed && k <= CUBIC_SEARCH_EDGES) {
      // The Delaunay faces of a loop round a corner or a crease may hold no short
      // patch; all triangles of the loop's vertices may (Liepa's cubic search).
      patch.clear();
      CGAL::Polygon_mesh_processing::triangulate_hole_polyline(
          polyline,
          third,
          std::back_inserter(patch),
          CGAL::parameters::use_delaunay_triangulation(false));
      closed = plausible_patch();
    }
    if (!closed) {
      open.push_back(std::move(loop));
      continue;
    }
    for (auto t : patch) {
      std::sort(t.v.begin(), t.v.end());
      triangles.push_back({hole[t.v[0]], hole[t.v[1]], hole[t.v[2]]});
    }
    ++out.holes;
    out.triangles += patch.size();
    out.sizes.push_back(k);
  }
  loops = std::move(open);
  if (triangles.size() > before)
    incidences.add(triangles, before);
  return out;
}

HoleFilling
fillHolesFromMesh(const std::vector<Eigen::Vector3d>& points,
                  const std::vector<double>& spacing,
                  const std::vector<Triangle>& other,
                  std::vector<Triangle>& triangles,
                  EdgeIncidences& incidences,
                  std::vector<std::vector<int>>& loops,
                  double reach,
                  std::size_t max_edges)
{
  HoleFilling out;
  const std::size_t num_vertices = points.size();
  if (other.empty())
    return out;
  // As short as the Delaunay patches' edges: where the original Co-cone covers a
  // true border's hole, it does so with long triangles.
  const auto short_edge = [&](int a, int b) {
    return withinReach(points, spacing, reach, a, b);
  };
  const EdgeIncidences theirs(other);
  const std::size_t before = triangles.size();
  std::vector<std::uint8_t> used(num_vertices, 0), taken(other.size(), 0);
  for (const auto& t : triangles)
    for (const int v : t)
      used[v] = 1;
  // Edges of the patches added here (the incidences are brought up to date once, at
  // the end).
  std::set<std::array<int, 2>> added;
  const auto in_mesh = [&](int a, int b) {
    return incidences.find(a, b) >= 0 || added.count(edgeKey(a, b)) > 0;
  };
  std::vector<int> on_loop(num_vertices, -1), in_patch(other.size(), -1);
  int attempt = -1; // stamps in_patch
  std::vector<std::vector<int>> open;
  std::vector<int> patch, stack;
  std::vector<std::array<int, 2>> loop_edges, patch_edges;
  std::vector<int> patch_vertices;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    auto& loop = loops[l];
    const std::size_t k = loop.size();
    if (k < 3 || k > max_edges) {
      open.push_back(std::move(loop));
      continue;
    }
    const int id = static_cast<int>(l); // stamps on_loop
    loop_edges.clear();
    for (std::size_t i = 0; i < k; ++i) {
      on_loop[loop[i]] = id;
      loop_edges.push_back(edgeKey(loop[i], loop[(i + 1) % k]));
    }
    std::sort(loop_edges.begin(), loop_edges.end());
    const auto is_loop_edge = [&](int a, int b) {
      return std::binary_search(loop_edges.begin(), loop_edges.end(), edgeKey(a, b));
    };
    // Seeds: at each loop edge the triangle of the other mesh that traverses it
    // against the mesh's triangle (or, the other mesh turned over, with it); grown
    // across the other mesh's inner edges. An edge of the mesh, a border of the other
    // mesh or a triangle taken already ends the attempt.
    const auto grow = [&](int flip) {
      patch.clear();
      stack.clear();
      for (std::size_t i = 0; i < k; ++i) {
        const int a = loop[i], b = loop[(i + 1) % k];
        const auto e = theirs.find(a, b), mine = incidences.find(a, b);
        if (e < 0 || mine < 0)
          return false;
        const std::size_t at = incidences.first[mine];
        const Triangle& own = triangles[incidences.triangle[at]];
        int seed = -1;
        for (std::size_t j = theirs.first[e]; j < theirs.first[e + 1]; ++j)
          if ((theirs.forward[j] == incidences.forward[at]) == (flip == 1) &&
              !sameVertices(other[theirs.triangle[j]], own))
            seed = theirs.triangle[j];
        if (seed < 0 || taken[seed])
          return false;
        if (in_patch[seed] != attempt) {
          in_patch[seed] = attempt;
          stack.push_back(seed);
        }
      }
      while (!stack.empty()) {
        const int t = stack.back();
        stack.pop_back();
        patch.push_back(t);
        if (patch.size() > PATCH_TRIANGLES_PER_EDGE * k)
          return false;
        for (int c = 0; c < 3; ++c) {
          const int u = other[t][c], v = other[t][(c + 1) % 3];
          if (is_loop_edge(u, v))
            continue;
          const auto e = theirs.find(u, v);
          if (in_mesh(u, v) || theirs.count(e) != 2 || !short_edge(u, v))
            return false;
          for (std::size_t j = theirs.first[e]; j < theirs.first[e + 1]; ++j) {
            const int next = theirs.triangle[j];
            if (next == t || in_patch[next] == attempt)
              continue;
            if (taken[next])
              return false;
            in_patch[next] = attempt;
            stack.push_back(next);
          }
        }
      }
      return true;
    };
    int flip = 0;
    ++attempt;
    bool ok = grow(flip);
    if (!ok) {
      flip = 1;
      ++attempt;
      ok = grow(flip);
    }
    // A disk bounded by the loop whose inner vertices are free: Euler characteristic
    // 1, every loop edge in it once.
    if (ok) {
      patch_edges.clear();
      patch_vertices.clear();
      for (const int t : patch)
        for (int c = 0; c < 3; ++c) {
          const int u = other[t][c];
          patch_vertices.push_back(u);
          patch_edges.push_back(edgeKey(u, other[t][(c + 1) % 3]));
          ok = ok && (on_loop[u] == id || !used[u]);
        }
      std::sort(patch_vertices.begin(), patch_vertices.end());
      patch_vertices.erase(std::unique(patch_vertices.begin(), patch_vertices.end()),
                           patch_vertices.end());
      std::sort(patch_edges.begin(), patch_edges.end());
      std::size_t border = 0;
      for (std::size_t i = 0; i < patch_edges.size();) {
        std::size_t j = i;
        while (j < patch_edges.size() && patch_edges[j] == patch_edges[i])
          ++j;
        border += j - i == 1;
        ok = ok && (j - i == 1) == is_loop_edge(patch_edges[i][0], patch_edges[i][1]);
        i = j;
      }
      patch_edges.erase(std::unique(patch_edges.begin(), patch_edges.end()),
                        patch_edges.end());
      ok = ok && border == k &&
           static_cast<long>(patch_vertices.size()) -
                   static_cast<long>(patch_edges.size()) +
                   static_cast<long>(patch.size()) ==
               1;
    }
    if (!ok) {
      open.push_back(std::move(loop));
      continue;
    }
    std::sort(patch.begin(), patch.end());
    for (const int t : patch) {
      taken[t] = 1;
      Triangle added_triangle = other[t];
      if (flip == 1)
        std::swap(added_triangle[1], added_triangle[2]);
      triangles.push_back(added_triangle);
      for (int c = 0; c < 3; ++c) {
        used[added_triangle[c]] = 1;
        added.insert(edgeKey(added_triangle[c], added_triangle[(c + 1) % 3]));
      }
    }
    ++out.holes;
    out.triangles += patch.size();
    out.sizes.push_back(k);
  }
  loops = std::move(open);

  // The closed components of the other mesh over free vertices, as they are.
  std::vector<int> component(other.size(), -1);
  for (std::size_t s = 0; s < other.size(); ++s) {
    if (component[s] >= 0 || taken[s])
      continue;
    patch.assign(1, static_cast<int>(s));
    component[s] = static_cast<int>(s);
    bool closed = true;
    for (std::size_t i = 0; i < patch.size(); ++i) {
      const Triangle& t = other[patch[i]];
      for (int c = 0; c < 3; ++c) {
        closed = closed && !used[t[c]] && short_edge(t[c], t[(c + 1) % 3]);
        const auto e = theirs.find(t[c], t[(c + 1) % 3]);
        closed = closed && theirs.count(e) == 2;
        for (std::size_t j = theirs.first[e]; j < theirs.first[e + 1]; ++j) {
          const int next = theirs.triangle[j];
          if (component[next] < 0) {
            component[next] = static_cast<int>(s);
            patch.push_back(next);
          }
        }
      }
    }
    if (!closed)
      continue;
    std::sort(patch.begin(), patch.end());
    for (const int t : patch)
      triangles.push_back(other[t]);
    out.triangles += patch.size();
  }
  if (triangles.size() > before)
    incidences.add(triangles, before);
  return out;
}

} // namespace cocone
} // namespace pcl
