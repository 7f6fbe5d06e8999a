/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/walk.h>

#include <CGAL/Exact_rational.h>
#include <CGAL/Interval_nt.h>

#include <Eigen/Geometry>

#include "edge_sort.h"
#include "parallel.h"

#include <algorithm>
#include <array>
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

/** The present triangle of vertices \a a, \a b, \a c (any order), or -1. */
int
presentTriangle(const TriangleComplex& complex,
                const std::vector<std::uint8_t>& present,
                int a,
                int b,
                int c)
{
  Triangle v{a, b, c};
  std::sort(v.begin(), v.end());
  for (std::size_t i = complex.vertexBegin(v[0]); i < complex.vertexEnd(v[0]); ++i) {
    const int t = complex.vertexTriangle(i);
    if (complex.triangle(t) == v)
      return present[t] ? t : -1;
  }
  return -1;
}

/** |pq|^2 - |rs|^2 in the number type NT. */
template <typename NT>
NT
squaredLengthDifference(const Eigen::Vector3d& p,
                        const Eigen::Vector3d& q,
                        const Eigen::Vector3d& r,
                        const Eigen::Vector3d& s)
{
  NT d(0);
  for (int k = 0; k < 3; ++k) {
    const NT u = NT(p[k]) - NT(q[k]), w = NT(r[k]) - NT(s[k]);
    d = d + u * u - w * w;
  }
  return d;
}

/** The sign of |pq|^2 - |rs|^2, exactly: intervals, then rationals if they do not
 * tell. */
int
compareSquaredLengths(const Eigen::Vector3d& p,
                      const Eigen::Vector3d& q,
                      const Eigen::Vector3d& r,
                      const Eigen::Vector3d& s)
{
  {
    CGAL::Protect_FPU_rounding<true> protect;
    const auto d = squaredLengthDifference<CGAL::Interval_nt_advanced>(p, q, r, s);
    if (d.inf() > 0.0)
      return 1;
    if (d.sup() < 0.0)
      return -1;
  }
  return CGAL::sign(squaredLengthDifference<CGAL::Exact_rational>(p, q, r, s));
}

/** The most tetrahedra of a cluster resolveFlatTetrahedra() decides (clusters of
 * random samples have one to three). */
constexpr std::size_t MAXIMUM_CLUSTER = 16;

/** Flat tetrahedra: where four nearly cocircular points make a tetrahedron all four
 * of whose faces are present, the surface through them is one of two pairs
 * of its faces, and the walk keeps the pair on the side its orientation faces: the
 * orientation of each walk's seed, i.e. the caller's order of the points, would
 * decide (mirroring a cloud changed 3 to 4 % of the triangles of one piece on random
 * samples). Decided here instead, once and without orientation.
 *
 * More nearly cospherical points make a cluster of such tetrahedra, joined by shared
 * faces. The faces of one tetrahedron only (the hull) close around the cluster; the
 * surface enters through the hull edges that hold a present triangle outside the
 * cluster (the loop). A cluster qualifies when the loop cuts the hull into two
 * pieces, each of which spans the loop: the two triangulations of the flat polygon,
 * one on either side (for one tetrahedron, whose sides may lie on the sampled
 * surface's border: the one pair of opposite edges that hold nothing outside are
 * its diagonals, the other four edges the loop). The piece kept is the one whose
 * longest inner edge is shorter, lengths compared exactly (for one tetrahedron: the
 * pair about the shorter diagonal; on a tie, the piece without an inner edge at the
 * lexicographically smallest point): a rule of the points alone, which a tile and the
 * whole cloud, a cloud and its mirror image apply alike. The other piece and the faces
 * between two tetrahedra are taken out of \a present.
 *
 * \return the number of clusters resolved */
std::size_t
resolveFlatTetrahedra(const TriangleComplex& complex,
                      std::vector<std::uint8_t>& present,
                      int threads)
{
  const auto num_edges = static_cast<std::ptrdiff_t>(complex.numEdges());
  const auto presentAt = [&](int e) {
    int count = 0;
    for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i)
      count += present[complex.edgeTriangle(i)];
    return count;
  };
  // Every tetrahedron all of whose faces are present, found from the edges of
  // three or more present triangles, as its four faces.
  std::vector<std::array<int, 4>> found;
#pragma omp parallel num_threads(threads)
  {
    std::vector<std::array<int, 4>> mine;
#pragma omp for schedule(dynamic, 4096) nowait
    for (std::ptrdiff_t e = 0; e < num_edges; ++e) {
      if (complex.edgeEnd(e) - complex.edgeBegin(e) < 3 ||
          presentAt(static_cast<int>(e)) < 3)
        continue;
      const auto& edge = complex.edge(static_cast<int>(e));
      const int a = edge[0], b = edge[1];
      for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i) {
        const int t1 = complex.edgeTriangle(i);
        if (!present[t1])
          continue;
        const auto& v1 = complex.triangle(t1);
        const int c1 = v1[0] + v1[1] + v1[2] - a - b;
        for (std::size_t j = i + 1; j < complex.edgeEnd(e); ++j) {
          const int t2 = complex.edgeTriangle(j);
          if (!present[t2])
            continue;
          const auto& v2 = complex.triangle(t2);
          const int c2 = v2[0] + v2[1] + v2[2] - a - b;
          const int t3 = presentTriangle(complex, present, a, c1, c2);
          const int t4 = t3 < 0 ? -1 : presentTriangle(complex, present, b, c1, c2);
          if (t4 < 0)
            continue;
          std::array<int, 4> faces{t1, t2, t3, t4};
          std::sort(faces.begin(), faces.end());
          mine.push_back(faces);
        }
      }
    }
#pragma omp critical
    found.insert(found.end(), mine.begin(), mine.end());
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  if (found.empty())
    return 0;

  // Clusters: tetrahedra joined by shared faces.
  const int tets = static_cast<int>(found.size());
  std::vector<std::pair<int, int>> face_tet; // (face, tetrahedron)
  face_tet.reserve(4 * found.size());
  for (int k = 0; k < tets; ++k)
    for (const int t : found[k])
      face_tet.emplace_back(t, k);
  std::sort(face_tet.begin(), face_tet.end());
  std::vector<int> root(tets);
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&](int k) {
    while (root[k] != k)
      k = root[k] = root[root[k]];
    return k;
  };
  for (std::size_t i = 1; i < face_tet.size(); ++i)
    if (face_tet[i].first == face_tet[i - 1].first) {
      const int a = find(face_tet[i].second), b = find(face_tet[i - 1].second);
      root[std::max(a, b)] = std::min(a, b);
    }
  std::vector<std::pair<int, int>> members; // (cluster, tetrahedron)
  members.reserve(found.size());
  for (int k = 0; k < tets; ++k)
    members.emplace_back(find(k), k);
  std::sort(members.begin(), members.end());

  const auto& P = complex.points();
  const auto length_less = [&](int e, int f) {
    const auto &a = complex.edge(e), &b = complex.edge(f);
    return compareSquaredLengths(P[a[0]], P[a[1]], P[b[0]], P[b[1]]) < 0;
  };
  const auto lex_less = [&](int u, int w) {
    return std::lexicographical_compare(
        P[u].data(), P[u].data() + 3, P[w].data(), P[w].data() + 3);
  };
  std::vector<int> removed, faces, hull, edges, piece;
  std::size_t resolved = 0;
  for (std::size_t begin = 0, end; begin < members.size(); begin = end) {
    for (end = begin;
         end < members.size() && members[end].first == members[begin].first;
         ++end) {
    }
    if (end - begin > MAXIMUM_CLUSTER)
      continue; // many cospherical points: left to the walk
    faces.clear();
    for (std::size_t i = begin; i < end; ++i)
      for (const int t : found[members[i].second])
        faces.push_back(t);
    std::sort(faces.begin(), faces.end());
    // The hull: the faces of one tetrahedron; a face of three is no Delaunay cluster.
    hull.clear();
    bool ok = true;
    for (std::size_t i = 0, j; i < faces.size(); i = j) {
      for (j = i; j < faces.size() && faces[j] == faces[i]; ++j) {
      }
      ok = ok && j - i <= 2;
      if (j - i == 1)
        hull.push_back(faces[i]);
    }
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    const auto in_cluster = [&](int t) {
      return std::binary_search(faces.begin(), faces.end(), t);
    };
    // Per hull edge: the loop if a present triangle outside the cluster holds it;
    // otherwise it joins its two hull faces into one piece.
    const int h = static_cast<int>(hull.size());
    piece.assign(h, -1);
    edges.clear();
    for (const int t : hull)
      for (const int e : complex.triangleEdges(t))
        edges.push_back(e);
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::vector<std::array<int, 2>> at(edges.size(), {-1, -1}); // hull faces
    std::vector<std::uint8_t> loop(edges.size(), 0);
    for (std::size_t i = 0; ok && i < edges.size(); ++i) {
      const int e = edges[i];
      int hull_faces = 0;
      for (std::size_t k = complex.edgeBegin(e); k < complex.edgeEnd(e); ++k) {
        const int t = complex.edgeTriangle(k);
        if (!present[t])
          continue;
        if (!in_cluster(t))
          loop[i] = 1;
        else if (std::binary_search(hull.begin(), hull.end(), t)) {
          if (hull_faces < 2)
            at[i][hull_faces] = static_cast<int>(
                std::lower_bound(hull.begin(), hull.end(), t) - hull.begin());
          ++hull_faces;
        }
      }
      ok = hull_faces == 2;
    }
    if (!ok || std::find(loop.begin(), loop.end(), 1) == loop.end())
      continue;
    if (end - begin == 1) {
      // One tetrahedron: its sides may lie on the sampled surface's border and hold
      // nothing outside. Its diagonals are the one pair of opposite edges that hold
      // nothing outside; the other four edges are the loop.
      int pairs = 0;
      std::array<std::size_t, 2> diagonals{};
      for (std::size_t i = 0; i < edges.size(); ++i)
        for (std::size_t j = i + 1; j < edges.size(); ++j) {
          const auto &x = complex.edge(edges[i]), &y = complex.edge(edges[j]);
          if (!loop[i] && !loop[j] && x[0] != y[0] && x[0] != y[1] && x[1] != y[0] &&
              x[1] != y[1]) {
            diagonals = {i, j};
            ++pairs;
          }
        }
      if (pairs != 1)
        continue;
      std::fill(loop.begin(), loop.end(), 1);
      loop[diagonals[0]] = loop[diagonals[1]] = 0;
    }
    // The pieces: hull faces joined across the edges off the loop.
    int pieces = 0;
    for (int f = 0; f < h; ++f) {
      if (piece[f] >= 0)
        continue;
      piece[f] = pieces;
      for (bool grown = true; grown;) {
        grown = false;
        for (std::size_t i = 0; i < edges.size(); ++i)
          if (!loop[i] && (piece[at[i][0]] == pieces) != (piece[at[i][1]] == pieces)) {
            piece[at[i][0]] = piece[at[i][1]] = pieces;
            grown = true;
          }
      }
      ++pieces;
    }
    // Two pieces, each spanning the loop.
    ok = pieces == 2;
    for (std::size_t i = 0; ok && i < edges.size(); ++i)
      ok = !loop[i] || piece[at[i][0]] != piece[at[i][1]];
    if (!ok)
      continue;
    // Per piece its longest inner edge, and whether one is at the lexicographically
    // smallest vertex of the cluster.
    int smallest = complex.triangle(hull[0])[0];
    for (const int t : hull)
      for (const int v : complex.triangle(t))
        if (lex_less(v, smallest))
          smallest = v;
    std::array<int, 2> longest{-1, -1};
    std::array<bool, 2> at_smallest{false, false};
    for (std::size_t i = 0; i < edges.size(); ++i) {
      if (loop[i])
        continue;
      const int k = piece[at[i][0]];
      if (longest[k] < 0 || length_less(longest[k], edges[i]))
        longest[k] = edges[i];
      const auto& ends = complex.edge(edges[i]);
      at_smallest[k] = at_smallest[k] || ends[0] == smallest || ends[1] == smallest;
    }
    if (longest[0] < 0 || longest[1] < 0)
      continue;
    int drop = length_less(longest[1], longest[0])   ? 0
               : length_less(longest[0], longest[1]) ? 1
                                                     : (at_smallest[1] ? 1 : 0);
    for (int f = 0; f < h; ++f)
      if (piece[f] == drop)
        removed.push_back(hull[f]);
    for (const int t : faces)
      if (!std::binary_search(hull.begin(), hull.end(), t))
        removed.push_back(t);
    ++resolved;
  }
  for (const int t : removed)
    present[t] = 0;
  return resolved;
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
     const std::vector<std::uint8_t>& pruned,
     const std::vector<std::uint8_t>& boundary,
     int threads)
{
  const int m = static_cast<int>(complex.numTriangles());
  WalkResult out;
  std::vector<std::uint8_t> present = pruned;
  out.flat_clusters = resolveFlatTetrahedra(complex, present, threads);

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
