/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Dense>

#include "disjoint_sets.h"
#include "least_perimeter.h"
#include "local_mesh.h"
#include "loop_plane.h"
#include "points.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <set>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

/** Whether each vertex of \a piece has one fan: its triangles there connected
 * through the edges at it (a part of a manifold mesh can pinch at a vertex).
 * vertexFans() would do, but over arrays the size of the cloud for every piece. */
bool
singleFans(const std::vector<Triangle>& piece)
{
  std::vector<std::pair<int, int>> corners; // (vertex, triangle)
  for (std::size_t t = 0; t < piece.size(); ++t)
    for (const int v : piece[t])
      corners.emplace_back(v, static_cast<int>(t));
  std::sort(corners.begin(), corners.end());
  detail::DisjointSets fans;
  for (std::size_t i = 0, j = 0; i < corners.size(); i = j) {
    while (j < corners.size() && corners[j].first == corners[i].first)
      ++j;
    // Two triangles at v are in one fan if they share another vertex.
    fans.reset(j - i);
    for (std::size_t a = i; a < j; ++a)
      for (std::size_t b = a + 1; b < j; ++b) {
        const Triangle &s = piece[corners[a].second], &t = piece[corners[b].second];
        for (const int u : s)
          if (u != corners[i].first && std::find(t.begin(), t.end(), u) != t.end())
            fans.unite(static_cast<int>(a - i), static_cast<int>(b - i));
      }
    for (std::size_t a = i; a < j; ++a)
      if (fans.find(static_cast<int>(a - i)) != fans.find(0))
        return false;
  }
  return true;
}

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/** A patch triangle as CGAL hands it over: indices into the loop. */
struct LoopTriangle {
  LoopTriangle(int a, int b, int c) : v{a, b, c} {}
  std::array<int, 3> v;
};

/** Loops of at most this many edges whose Delaunay patch is not plausible are
 * searched again over all triangles of their vertices (cubic in the edges). */
constexpr std::size_t CUBIC_SEARCH_EDGES = 40;

/** Loops of at most this many edges are tried with HoleWeight::LEAST_PERIMETER (the
 * search is cubic in the edges; the longest slit measured had 52). */
constexpr std::size_t LEAST_PERIMETER_EDGES = 128;

/** The largest angle between the normals of two triangles at an edge of a least
 * perimeter patch, patch or mesh: beyond it the patch folds back over itself or the
 * mesh. cos 150 degrees: round the rim of a plate thinner than the spacing the
 * surface turns a half turn within a triangle or two (120 degrees left 4 of the 8
 * slits of a 10,000-point plate open, at 121). */
constexpr double FOLD_COSINE = -0.866;
/** The cosine beyond which a dihedral-angle patch lies back on the mesh beside the
 * loop (folded flat, within a degree): it closes a sheet's outline with the sheet's
 * other side, a closed piece of no volume (measured: the top and bottom of a box
 * sampled densely along its edges and sparsely on its faces came out as two such
 * pieces). Below a flat fold the dihedral patches are not refused: at 170 degrees the
 * noisy closed meshes keep 1 to 2 loops more each where noise crumples a patch. */
constexpr double DOUBLING_COSINE = -0.99985;

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

using detail::withinReach;

/** Whether a vertex of \a loop is on a true border (classifyBorderLoops()). */
bool
onTrueBorder(const std::vector<int>& loop, const std::vector<std::uint8_t>& true_border)
{
  return !true_border.empty() &&
         std::any_of(loop.begin(), loop.end(), [&](int v) { return true_border[v]; });
}

Kernel::Point_3
toCgal(const Eigen::Vector3d& p)
{
  return {p.x(), p.y(), p.z()};
}

/** Whether \a patch closes \a loop as a disk glued along it: each loop edge in one
 * patch triangle, run against the loop; every other edge in two, once each way, and
 * not in the mesh; no triangle with a corner twice; V - E + F = 1. Checked for every
 * patch, whichever way it was made: a patch maker misled by a degenerate loop (its
 * vertices collinear, a sample on it) leaves the loop open, never the mesh
 * non-manifold. */
bool
closesLoop(const std::vector<int>& loop,
           const std::vector<Triangle>& patch,
           const EdgeIncidences& incidences)
{
  std::vector<std::array<int, 2>> half;
  std::vector<int> corners;
  for (const auto& t : patch) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      return false;
    for (int c = 0; c < 3; ++c) {
      half.push_back({t[c], t[(c + 1) % 3]});
      corners.push_back(t[c]);
    }
  }
  std::sort(half.begin(), half.end());
  if (std::adjacent_find(half.begin(), half.end()) != half.end())
    return false;
  const auto has = [&](int a, int b) {
    return std::binary_search(half.begin(), half.end(), std::array<int, 2>{a, b});
  };
  const std::size_t k = loop.size();
  for (std::size_t i = 0; i < k; ++i)
    if (!has(loop[(i + 1) % k], loop[i]) || has(loop[i], loop[(i + 1) % k]))
      return false;
  std::size_t single = 0, paired = 0;
  for (const auto& [a, b] : half) {
    if (!has(b, a))
      ++single;
    else if (incidences.find(a, b) >= 0)
      return false;
    else
      ++paired;
  }
  if (single != k) // the loop's edges and no other
    return false;
  std::sort(corners.begin(), corners.end());
  const auto vertices = std::unique(corners.begin(), corners.end()) - corners.begin();
  const auto edges = static_cast<std::ptrdiff_t>(k + paired / 2);
  return vertices - edges + static_cast<std::ptrdiff_t>(patch.size()) == 1;
}

/** Close each loop that may be closed (3 to \a max_edges edges, not on a true
 * border) with the triangles \a patch_of(loop, patch) appends to patch, facing as the
 * mesh (false, or a patch that is no disk on the loop: the loop stays open). The
 * loops left open stay in \a loops; the incidences take in the triangles added. */
template <typename PatchOf>
HoleFilling
closeLoops(std::vector<Triangle>& triangles,
           EdgeIncidences& incidences,
           std::vector<std::vector<int>>& loops,
           std::size_t max_edges,
           const std::vector<std::uint8_t>& true_border,
           PatchOf patch_of)
{
  HoleFilling out;
  const std::size_t before = triangles.size();
  std::vector<std::vector<int>> open;
  std::vector<Triangle> patch;
  for (auto& loop : loops) {
    patch.clear();
    if (loop.size() < 3 || loop.size() > max_edges || onTrueBorder(loop, true_border) ||
        !patch_of(loop, patch) || !closesLoop(loop, patch, incidences)) {
      open.push_back(std::move(loop));
      continue;
    }
    triangles.insert(triangles.end(), patch.begin(), patch.end());
    ++out.holes;
    out.triangles += patch.size();
    out.rims.push_back(std::move(loop));
  }
  loops = std::move(open);
  if (triangles.size() > before)
    incidences.add(triangles, before);
  return out;
}

} // namespace

HoleFilling
fillUndersampledHoles(const std::vector<Eigen::Vector3d>& points,
                      const std::vector<double>& spacing,
                      std::vector<Triangle>& triangles,
                      EdgeIncidences& incidences,
                      std::vector<std::vector<int>>& loops,
                      double reach,
                      std::size_t max_edges,
                      const std::vector<std::uint8_t>& true_border,
                      HoleWeight weight,
                      double rim_reach)
{
  std::vector<int> hole;
  double rim_longest2 = 0.0; // rim_reach in the hole's rim diameters, squared
  // Plausible: an edge of the hole, or a new edge within the reach and not in the
  // mesh yet (i, j positions in the hole).
  const auto plausible = [&](std::size_t i, std::size_t j) {
    if (j < i)
      std::swap(i, j);
    if (j == i + 1 || (i == 0 && j + 1 == hole.size()))
      return true;
    return (withinReach(points, spacing, reach, hole[i], hole[j]) ||
            (points[hole[i]] - points[hole[j]]).squaredNorm() <= rim_longest2) &&
           incidences.find(hole[i], hole[j]) < 0;
  };
  // The mesh's triangle at the loop's edge ab.
  const auto beside = [&](int a, int b) -> const Triangle& {
    return triangles[incidences.triangle[incidences.first[incidences.find(a, b)]]];
  };
  // rim_longest2 for the hole: the rim diameter of the mesh's triangles at its edges.
  std::vector<double> rim_radii;
  const auto set_rim_longest = [&]() {
    rim_longest2 = 0.0;
    if (!(rim_reach > 0.0))
      return;
    rim_radii.clear();
    for (std::size_t i = 0; i < hole.size(); ++i) {
      const Triangle& t = beside(hole[i], hole[(i + 1) % hole.size()]);
      rim_radii.push_back(
          detail::circumradius(points[t[0]], points[t[1]], points[t[2]]));
    }
    const double longest = rim_reach * detail::rimDiameter(rim_radii);
    if (std::isfinite(longest))
      rim_longest2 = longest * longest;
  };

  // A fold: at an edge of the patch the two triangles, the patch's or the mesh's
  // beside the loop, face more than fold_cosine apart (or one is degenerate).
  std::vector<std::pair<std::array<int, 2>, Eigen::Vector3d>> normal_at;
  const auto normal = [&](const Triangle& t) {
    return (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]);
  };
  const auto folds = [&](const std::vector<Triangle>& patch,
                         std::size_t first,
                         double fold_cosine) {
    normal_at.clear();
    for (std::size_t i = 0; i < hole.size(); ++i) {
      const int a = hole[i], b = hole[(i + 1) % hole.size()];
      normal_at.push_back({edgeKey(a, b), normal(beside(a, b))});
    }
    for (std::size_t t = first; t < patch.size(); ++t)
      for (int c = 0; c < 3; ++c)
        normal_at.push_back(
            {edgeKey(patch[t][c], patch[t][(c + 1) % 3]), normal(patch[t])});
    std::sort(normal_at.begin(), normal_at.end(), [](const auto& x, const auto& y) {
      return x.first < y.first;
    });
    for (std::size_t i = 0; i < normal_at.size(); ++i) {
      const Eigen::Vector3d& n = normal_at[i].second;
      if (!(n.squaredNorm() > 0.0) ||
          (i + 1 < normal_at.size() && normal_at[i + 1].first == normal_at[i].first &&
           !(n.dot(normal_at[i + 1].second) >
             fold_cosine * n.norm() * normal_at[i + 1].second.norm())))
        return true;
    }
    return false;
  };

  std::vector<Kernel::Point_3> polyline, third;
  std::vector<LoopTriangle> found;
  const auto dihedral_patch = [&](std::vector<Triangle>& patch) {
    const std::size_t k = hole.size();
    polyline.clear();
    third.clear();
    for (std::size_t i = 0; i < k; ++i) {
      const int a = hole[i], b = hole[(i + 1) % k];
      polyline.push_back(toCgal(points[a]));
      third.push_back(toCgal(points[thirdCorner(beside(a, b), a, b)]));
    }
    const std::size_t first = patch.size();
    // The patch CGAL found, if plausible and unfolded, appended to patch.
    const auto take = [&]() {
      bool ok = found.size() == k - 2;
      for (const auto& t : found)
        ok = ok && plausible(t.v[0], t.v[1]) && plausible(t.v[1], t.v[2]) &&
             plausible(t.v[0], t.v[2]);
      if (!ok)
        return false;
      for (auto t : found) {
        std::sort(t.v.begin(), t.v.end());
        patch.push_back({hole[t.v[0]], hole[t.v[1]], hole[t.v[2]]});
      }
      if (!folds(patch, first, DOUBLING_COSINE))
        return true;
      patch.resize(first);
      return false;
    };
    // The Delaunay faces of the loop's vertices first; where they hold no short
    // patch (a loop round a corner or a crease), all triangles of its vertices
    // (Liepa's cubic search) for loops of up to CUBIC_SEARCH_EDGES.
    for (const bool delaunay : {true, false}) {
      if (!delaunay && k > CUBIC_SEARCH_EDGES)
        break;
      found.clear();
      CGAL::Polygon_mesh_processing::triangulate_hole_polyline(
          polyline,
          third,
          std::back_inserter(found),
          CGAL::parameters::use_delaunay_triangulation(delaunay)
              .do_not_use_cubic_algorithm(delaunay));
      if (take())
        return true;
    }
    return false;
  };

  std::vector<std::uint8_t> edge_ok;
  detail::LeastPerimeterScratch scratch;
  const auto least_perimeter_patch = [&](std::vector<Triangle>& patch) {
    const std::size_t k = hole.size();
    if (k > LEAST_PERIMETER_EDGES)
      return false;
    edge_ok.assign(k * k, 0);
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = i + 1; j < k; ++j)
        edge_ok[i * k + j] = plausible(i, j);
    const auto valid = [&](std::size_t i, std::size_t m, std::size_t j) {
      return edge_ok[i * k + m] && edge_ok[m * k + j] && edge_ok[i * k + j];
    };
    const std::size_t first = patch.size();
    if (!detail::leastPerimeterTriangulation(points, hole, valid, patch, scratch))
      return false;
    if (!folds(patch, first, FOLD_COSINE))
      return true;
    patch.resize(first);
    return false;
  };

  const auto patch_of = [&](const std::vector<int>& loop,
                            std::vector<Triangle>& patch) {
    // The hole runs against the loop, which has the mesh on its left: a triangle of
    // the hole's polygon with its corners in the hole's order faces as the mesh.
    hole.assign(loop.rbegin(), loop.rend());
    set_rim_longest();
    return weight == HoleWeight::LEAST_PERIMETER ? least_perimeter_patch(patch)
                                                 : dihedral_patch(patch);
  };
  return closeLoops(triangles, incidences, loops, max_edges, true_border, patch_of);
}

namespace {

using DirectedEdge = std::array<int, 2>;

/** Euler characteristic V - E + F of the triangles \a ids of \a triangles. */
template <typename Ids>
long
eulerCharacteristic(const std::vector<Triangle>& triangles, const Ids& ids)
{
  std::vector<int> vertices;
  std::vector<std::array<int, 2>> edges;
  for (const int t : ids)
    for (int c = 0; c < 3; ++c) {
      vertices.push_back(triangles[t][c]);
      edges.push_back(edgeKey(triangles[t][c], triangles[t][(c + 1) % 3]));
    }
  std::sort(vertices.begin(), vertices.end());
  std::sort(edges.begin(), edges.end());
  const long v = std::unique(vertices.begin(), vertices.end()) - vertices.begin();
  const long e = std::unique(edges.begin(), edges.end()) - edges.begin();
  return v - e + static_cast<long>(ids.size());
}

/** Euler characteristic of all of \a triangles. */
long
eulerCharacteristic(const std::vector<Triangle>& triangles)
{
  std::vector<int> all(triangles.size());
  std::iota(all.begin(), all.end(), 0);
  return eulerCharacteristic(triangles, all);
}

/** The cycles of directed edges that leave each vertex once, each as its vertices
 * in order; \a closed false if one ends open (it is cut short there, its last
 * vertex not joined to its first): at a vertex no edge leaves, or at an edge walked
 * already that is not the cycle's first (two edges enter a vertex there). */
std::vector<std::vector<int>>
directedCycles(std::vector<DirectedEdge> edges, bool* closed = nullptr)
{
  std::sort(edges.begin(), edges.end());
  std::vector<std::vector<int>> cycles;
  std::vector<std::uint8_t> walked(edges.size(), 0);
  for (std::size_t i = 0; i < edges.size(); ++i) {
    if (walked[i])
      continue;
    cycles.emplace_back();
    for (std::size_t j = i; !walked[j];) {
      walked[j] = 1;
      cycles.back().push_back(edges[j][0]);
      const auto next =
          std::lower_bound(edges.begin(),
                           edges.end(),
                           DirectedEdge{edges[j][1], std::numeric_limits<int>::min()});
      const auto at = static_cast<std::size_t>(next - edges.begin());
      if (next == edges.end() || (*next)[0] != edges[j][1] || (walked[at] && at != i)) {
        if (closed)
          *closed = false;
        break;
      }
      j = at;
    }
  }
  return cycles;
}

} // namespace

HoleFilling
fillHolesFromMesh(const std::vector<Eigen::Vector3d>& points,
                  const std::vector<double>& spacing,
                  const std::vector<Triangle>& other,
                  std::vector<Triangle>& triangles,
                  EdgeIncidences& incidences,
                  std::vector<std::vector<int>>& loops,
                  double reach,
                  std::size_t max_edges,
                  std::size_t band_per_edge,
                  const std::vector<std::uint8_t>& true_border,
                  bool join_loops)
{
  HoleFilling out;
  const std::size_t num_vertices = points.size();
  if (other.empty())
    return out;
  // As short as the Delaunay patches' edges: where another mesh covers a true
  // border's hole, it does so with long triangles.
  const auto short_edge = [&](int a, int b) {
    return withinReach(points, spacing, reach, a, b);
  };
  const EdgeIncidences theirs(other);
  const std::size_t before = triangles.size();
  detail::LocalMesh mesh(triangles, num_vertices);
  std::vector<std::uint8_t> taken(other.size(), 0);
  std::vector<int> in_patch(other.size(), -1), in_band(before, -1);
  int patch_stamp = -1, band_stamp = -1;
  std::vector<int> band, patch, stack, blamed;
  std::vector<DirectedEdge> rim, band_border, cut;
  std::vector<Triangle> piece, context;
  std::vector<std::array<int, 2>> rim_keys, patch_edges;
  std::vector<int> rim_vertices, band_uses, taken_vertices;
  std::vector<std::vector<int>> absorbed; // the loops a patch closes
  // Blame: the mesh's triangles outside the band at edge ab, or at vertex v.
  const auto blame_edge = [&](int a, int b) {
    for (const int t : {mesh.traversing(a, b), mesh.traversing(b, a)})
      if (t >= 0 && in_band[t] != band_stamp)
        blamed.push_back(t);
  };
  const auto blame_vertex = [&](int v) {
    mesh.forStar(v, [&](int t) {
      if (in_band[t] != band_stamp)
        blamed.push_back(t);
    });
  };
  bool changed = false;
  for (const auto& loop : loops) {
    const std::size_t k = loop.size();
    if (k < 3 || k > max_edges || onTrueBorder(loop, true_border))
      continue;
    // Still a border of the mesh (an earlier patch may have taken it in)?
    if ((mesh.traversing(loop[0], loop[1]) >= 0) ==
        (mesh.traversing(loop[1], loop[0]) >= 0))
      continue;
    // The band: the mesh's triangles the other mesh's patch replaces, empty at first
    // (the patch closes the loop itself). Where the two meshes disagree next to the
    // hole (an edge the other mesh does not have, a triangle of it crossing an edge
    // of the mesh, a vertex the mesh still uses), the mesh's triangles there join the
    // band, up to max_band triangles.
    ++band_stamp;
    band.clear();
    const std::size_t max_band = band_per_edge * k;
    bool closed = false;
    while (!closed) {
      blamed.clear();
      rim.clear();
      band_border.clear();
      absorbed.assign(1, loop);
      if (band.empty()) {
        for (std::size_t i = 0; i < k; ++i) {
          const int a = loop[i], b = loop[(i + 1) % k];
          rim.push_back(mesh.traversing(a, b) >= 0 ? DirectedEdge{a, b}
                                                   : DirectedEdge{b, a});
        }
      }
      else {
        for (const int t : band)
          for (int c = 0; c < 3; ++c) {
            const int a = mesh.triangles()[t][c], b = mesh.triangles()[t][(c + 1) % 3];
            const int across = mesh.traversing(b, a);
            if (across < 0)
              band_border.push_back({a, b});
            else if (in_band[across] != band_stamp)
              rim.push_back({b, a});
          }
        // The band's borders must be whole loops of the mesh: where the mesh's
        // border goes on outside the band, the triangles along that loop join it.
        // Walked only from an edge whose next border edge is outside the band: a
        // loop the band holds whole is not walked at all.
        const auto next_border = [&](int at, int& triangle) {
          int next = -1;
          mesh.forStar(at, [&](int t) {
            for (int c = 0; c < 3; ++c)
              if (mesh.triangles()[t][c] == at &&
                  mesh.traversing(mesh.triangles()[t][(c + 1) % 3], at) < 0) {
                next = mesh.triangles()[t][(c + 1) % 3];
                triangle = t;
              }
          });
          return next;
        };
        for (const auto& e : band_border) {
          int triangle = -1;
          int at = next_border(e[1], triangle);
          if (at < 0 || in_band[triangle] == band_stamp)
            continue;
          blamed.push_back(triangle);
          for (std::size_t steps = 0; at != e[0] && steps < max_edges; ++steps) {
            at = next_border(at, triangle);
            if (at < 0)
              break;
            if (in_band[triangle] != band_stamp)
              blamed.push_back(triangle);
          }
        }
        // Each loop taken into the band is a cycle of its border edges.
        absorbed = directedCycles(band_border);
      }
      // The rim: cycles that leave each vertex once (else the rim pinches there).
      std::sort(rim.begin(), rim.end());
      for (std::size_t i = 1; i < rim.size(); ++i)
        if (rim[i][0] == rim[i - 1][0])
          blame_vertex(rim[i][0]);
      rim_keys.clear();
      rim_vertices.clear();
      for (const auto& e : rim) {
        rim_keys.push_back(edgeKey(e[0], e[1]));
        rim_vertices.push_back(e[0]);
      }
      std::sort(rim_keys.begin(), rim_keys.end());
      std::sort(rim_vertices.begin(), rim_vertices.end());
      const auto on_rim = [&](int a, int b) {
        return std::binary_search(rim_keys.begin(), rim_keys.end(), edgeKey(a, b));
      };
      // A vertex is free for the patch if no triangle outside the band uses it.
      band_uses.clear();
      for (const int t : band)
        for (const int v : mesh.triangles()[t])
          band_uses.push_back(v);
      std::sort(band_uses.begin(), band_uses.end());
      const auto free_vertex = [&](int v) {
        const auto range = std::equal_range(band_uses.begin(), band_uses.end(), v);
        return mesh.uses(v) == range.second - range.first;
      };
      // The other mesh's orientation against the mesh's: the triangles both have,
      // next to the rim, vote.
      int same = 0, reversed = 0;
      for (const auto& e : rim) {
        const int t = mesh.traversing(e[0], e[1]);
        const auto j0 = theirs.find(e[0], e[1]);
        if (j0 < 0)
          continue;
        for (std::size_t j = theirs.first[j0]; j < theirs.first[j0 + 1]; ++j)
          if (sameVertices(other[theirs.triangle[j]], mesh.triangles()[t]))
            ++(theirs.forward[j] == (e[0] < e[1]) ? same : reversed);
      }
      // A triangle of the other mesh the patch may hold: its edges within the reach.
      const auto fits = [&](int t) {
        for (int c = 0; c < 3; ++c) {
          const int u = other[t][c], v = other[t][(c + 1) % 3];
          if (!on_rim(u, v) && !short_edge(u, v))
            return false;
        }
        return true;
      };
      // Seeds: at each rim edge the other mesh's triangle on the side away from the
      // mesh; grown across the other mesh's inner edges. Where the other mesh has a
      // hole too (a border, a triangle with an edge beyond the reach) the patch stops
      // at a cut edge, which the Delaunay patches must then close (a rim edge without
      // a seed is one, with the mesh's triangle there as the context the patches
      // face by); a triangle taken already ends the attempt.
      const auto grow = [&](int flip) {
        ++patch_stamp;
        taken_vertices.clear();
        patch.clear();
        stack.clear();
        cut.clear();
        context.clear();
        for (const auto& e : rim) {
          const auto j0 = theirs.find(e[0], e[1]);
          int seed = -1;
          if (j0 >= 0)
            for (std::size_t j = theirs.first[j0]; j < theirs.first[j0 + 1]; ++j)
              if ((theirs.forward[j] == (e[0] < e[1])) == (flip == 1))
                seed = theirs.triangle[j];
          if (seed < 0) {
            blame_edge(e[0], e[1]);
            continue;
          }
          if (taken[seed])
            return false;
          if (!fits(seed)) {
            // As the other mesh faces, the mesh's triangle at ab runs against a
            // seed there: it runs ab if the patch is not turned over.
            Triangle t = mesh.triangles()[mesh.traversing(e[0], e[1])];
            if (flip == 1)
              std::swap(t[1], t[2]);
            cut.push_back(flip == 1 ? DirectedEdge{e[1], e[0]} : e);
            context.push_back(t);
            continue;
          }
          if (in_patch[seed] != patch_stamp) {
            in_patch[seed] = patch_stamp;
            stack.push_back(seed);
          }
        }
        // A rim of edges both meshes have first: grown from a rim with gaps, the
        // patch would leak through them.
        if (!blamed.empty())
          return true;
        while (!stack.empty()) {
          const int t = stack.back();
          stack.pop_back();
          patch.push_back(t);
          if (patch.size() > PATCH_TRIANGLES_PER_EDGE * rim.size())
            return false;
          for (int c = 0; c < 3; ++c) {
            const int u = other[t][c], v = other[t][(c + 1) % 3];
            if (!std::binary_search(rim_vertices.begin(), rim_vertices.end(), u) &&
                !free_vertex(u))
              taken_vertices.push_back(u);
            if (on_rim(u, v))
              continue;
            const auto e = theirs.find(u, v);
            if (theirs.count(e) > 2)
              return false;
            // The patch does not cross the mesh: where it would, the mesh's triangles
            // there are to join the band.
            const std::size_t blamed_before = blamed.size();
            blame_edge(u, v);
            if (blamed.size() > blamed_before)
              continue;
            if (theirs.count(e) == 1) {
              cut.push_back({u, v});
              continue;
            }
            for (std::size_t j = theirs.first[e]; j < theirs.first[e + 1]; ++j) {
              const int next = theirs.triangle[j];
              if (next == t || in_patch[next] == patch_stamp)
                continue;
              if (taken[next])
                return false;
              if (!fits(next)) {
                cut.push_back({u, v});
                continue;
              }
              in_patch[next] = patch_stamp;
              stack.push_back(next);
            }
          }
        }
        return true;
      };
      // Where the meshes disagree the band widens, and the patch is sought again;
      // never over a true border.
      const auto widen = [&]() {
        if (band.size() >= max_band)
          return false;
        std::sort(blamed.begin(), blamed.end());
        blamed.erase(std::unique(blamed.begin(), blamed.end()), blamed.end());
        if (!true_border.empty())
          for (const int t : blamed)
            for (const int v : mesh.triangles()[t])
              if (true_border[v])
                return false;
        for (const int t : blamed) {
          in_band[t] = band_stamp;
          band.push_back(t);
        }
        return true;
      };
      if (!blamed.empty()) {
        if (!widen())
          break;
        continue;
      }
      int flip = reversed > same ? 1 : 0;
      bool ok = grow(flip);
      if (!ok && same == reversed && blamed.empty()) {
        flip = 1 - flip;
        ok = grow(flip);
      }
      // A vertex the patch would share with the mesh outside the band: where no
      // edge says where they overlap, the mesh's triangles at it join the band.
      if (ok && blamed.empty())
        for (const int u : taken_vertices)
          blame_vertex(u);
      if (ok && !blamed.empty()) {
        if (!widen())
          break;
        continue;
      }
      if (!ok)
        break;
      // The patch's own holes, as the other mesh faces, closed by Delaunay patches
      // of their loops (each vertex starts one cut edge at most: simple loops); the
      // new edges not the mesh's.
      std::sort(patch.begin(), patch.end());
      piece.clear();
      for (const int t : patch)
        piece.push_back(other[t]);
      if (!cut.empty()) {
        std::sort(cut.begin(), cut.end());
        for (std::size_t i = 1; i < cut.size() && ok; ++i)
          ok = cut[i][0] != cut[i - 1][0];
        if (!ok)
          break;
        std::vector<std::vector<int>> cut_loops = directedCycles(cut, &ok);
        if (!ok)
          break;
        const std::size_t own = piece.size();
        piece.insert(piece.end(), context.begin(), context.end());
        EdgeIncidences piece_incidences(piece);
        fillUndersampledHoles(
            points, spacing, piece, piece_incidences, cut_loops, reach, max_edges, {});
        piece.erase(piece.begin() + own, piece.begin() + own + context.size());
        ok = cut_loops.empty();
        for (std::size_t t = own; t < piece.size() && ok; ++t)
          for (int c = 0; c < 3 && ok; ++c) {
            const std::size_t blamed_before = blamed.size();
            blame_edge(piece[t][c], piece[t][(c + 1) % 3]);
            ok = blamed.size() == blamed_before;
          }
        if (!ok)
          break;
      }
      // A patch bounded by the rim that stands for the band with its holes capped:
      // the same Euler characteristic, so the genus stays.
      patch_edges.clear();
      for (const Triangle& t : piece)
        for (int c = 0; c < 3; ++c)
          patch_edges.push_back(edgeKey(t[c], t[(c + 1) % 3]));
      std::sort(patch_edges.begin(), patch_edges.end());
      std::size_t border = 0;
      for (std::size_t i = 0; i < patch_edges.size() && ok;) {
        std::size_t j = i;
        while (j < patch_edges.size() && patch_edges[j] == patch_edges[i])
          ++j;
        border += j - i == 1;
        ok = (j - i == 1) == on_rim(patch_edges[i][0], patch_edges[i][1]);
        i = j;
      }
      // A patch may instead join r disks of the band and holes (r rim cycles) into
      // a sphere with r holes: a tunnel whose wall the walk left out, its rims open.
      const long replaced = eulerCharacteristic(mesh.triangles(), band) +
                            static_cast<long>(absorbed.size());
      const long patch_euler = eulerCharacteristic(piece);
      bool joins = false;
      if (ok && join_loops && patch_euler != replaced) {
        const long cycles = static_cast<long>(directedCycles(rim).size());
        std::size_t pieces = 0;
        if (cycles > 1 && replaced == cycles && patch_euler == 2 - cycles)
          triangleComponents(piece, &pieces);
        joins = pieces == 1;
      }
      ok = ok && border == rim.size() &&
           (join_loops ? joins || (patch_euler == replaced && absorbed.size() > 1)
                       : patch_euler == replaced);
      if (!ok)
        break;
      for (const int t : band)
        mesh.kill(t);
      for (const int t : patch)
        taken[t] = 1;
      for (Triangle added_triangle : piece) {
        if (flip == 1)
          std::swap(added_triangle[1], added_triangle[2]);
        mesh.add(added_triangle);
      }
      in_band.resize(mesh.triangles().size(), -1);
      out.holes += absorbed.size();
      out.triangles += piece.size();
      out.rims.insert(out.rims.end(), absorbed.begin(), absorbed.end());
      changed = true;
      closed = true;
    }
  }
  if (changed) {
    mesh.commit(before, incidences);
    loops = boundaryLoops(incidences, num_vertices);
  }
  if (join_loops)
    return out;
  const std::vector<std::uint8_t> used = usedVertices(triangles, num_vertices);
  const std::size_t after_patches = triangles.size();

  // The components of the other mesh over free vertices: a part the flatness test
  // turned down whole (a tube a few samples round), which the mesh does not reach.
  // Taken when closed, or when the Delaunay patches close each of its holes and it
  // is a surface rather than a strip (its border edges at most a quarter of its
  // triangles): an open patch along a true border keeps a loop no short patch
  // closes.
  std::vector<int> component(other.size(), -1);
  for (std::size_t s = 0; s < other.size(); ++s) {
    if (component[s] >= 0 || taken[s])
      continue;
    patch.assign(1, static_cast<int>(s));
    component[s] = static_cast<int>(s);
    bool surface = true;
    std::size_t border = 0;
    for (std::size_t i = 0; i < patch.size(); ++i) {
      const Triangle& t = other[patch[i]];
      for (int c = 0; c < 3; ++c) {
        surface = surface && !used[t[c]] && short_edge(t[c], t[(c + 1) % 3]);
        const auto e = theirs.find(t[c], t[(c + 1) % 3]);
        surface = surface && theirs.count(e) <= 2;
        border += theirs.count(e) == 1;
        for (std::size_t j = theirs.first[e]; j < theirs.first[e + 1]; ++j) {
          const int next = theirs.triangle[j];
          if (component[next] < 0) {
            component[next] = static_cast<int>(s);
            patch.push_back(next);
          }
        }
      }
    }
    if (!surface || 4 * border > patch.size())
      continue;
    std::sort(patch.begin(), patch.end());
    piece.clear();
    for (const int t : patch)
      piece.push_back(other[t]);
    if (!singleFans(piece))
      continue; // pinched at a vertex: no surface of its own

    if (border > 0) {
      EdgeIncidences piece_incidences(piece);
      std::vector<std::vector<int>> piece_loops =
          boundaryLoops(piece_incidences, num_vertices);
      const HoleFilling closed = fillUndersampledHoles(
          points, spacing, piece, piece_incidences, piece_loops, reach, max_edges, {});
      if (!piece_loops.empty())
        continue; // a hole no short patch closes: a border
      out.holes += closed.holes;
      out.triangles += closed.triangles;
      out.rims.insert(out.rims.end(), closed.rims.begin(), closed.rims.end());
    }
    triangles.insert(triangles.end(), piece.begin(), piece.end());
    out.triangles += patch.size();
  }
  if (triangles.size() > after_patches)
    incidences.add(triangles, after_patches);
  return out;
}

namespace {

/** A sample of the hole's sheet lies within this share of the spacing of the plane
 * the samples taken within a spacing of it span (less the noise): without noise a
 * surface leaves its tangent plane by about a tenth of a spacing over one. Two
 * sheets closer than the window of fillHolesWithInnerSamples() (two bodies
 * touching, half a spacing apart) stand over each other: a sample of the other
 * sheet is off that plane by their distance. */
constexpr double SHEET_OFFSET = 0.25;

/** A noisy sample of the sheet is off its neighbours' plane by up to this many
 * sigmas of the noise. */
constexpr double NOISE_SPREAD = 3.0;

/** Of the \a candidates (free samples over the hole, their heights off the loop's
 * quadratic given by \a residual), those on the loop's own sheet: taken from the
 * loop inwards, the nearest to what is taken first (in the plane), each unless it
 * is off the plane of the samples taken within \a spacing of it (in the plane) by
 * more than SHEET_OFFSET of \a spacing and \a spread (the noise's). A candidate turned
 * down stays free for another hole. The quadratic alone does not tell the sheets:
 * over a round loop its height in the middle is free (any multiple of the circle's
 * equation may be added), and it fitted one touching sphere's hole between the two
 * caps, half a spacing apart. */
template <typename Residual>
std::vector<int>
ownSheet(const detail::LoopPlane& hole,
         const std::vector<int>& loop,
         const std::vector<int>& candidates,
         const std::vector<Eigen::Vector3d>& points,
         const Residual& residual,
         double spread,
         double spacing)
{
  const std::size_t m = candidates.size();
  if (m == 0 || !(spacing > 0.0))
    return {};
  // The loop's vertices and the candidates (from m on), in the plane, over a grid
  // of cell \a spacing: the samples a candidate is checked against lie in the 3 x
  // 3 cells round it, and a sample taken brings nearer those in the 5 x 5 round it.
  std::vector<Eigen::Vector2d> x;
  std::vector<double> height;
  for (const int q : candidates) {
    x.push_back(hole.flat(points[q]));
    height.push_back(residual(q));
  }
  for (const int v : loop) {
    x.push_back(hole.flat(points[v]));
    height.push_back(residual(v));
  }
  using Cell = std::pair<long, long>;
  const auto cell_of = [&](const Eigen::Vector2d& p) {
    return Cell(static_cast<long>(std::floor(p.x() / spacing)),
                static_cast<long>(std::floor(p.y() / spacing)));
  };
  std::map<Cell, std::vector<int>> candidates_in, taken_in;
  for (std::size_t i = 0; i < m; ++i)
    candidates_in[cell_of(x[i])].push_back(static_cast<int>(i));
  const auto around = [&](const std::map<Cell, std::vector<int>>& grid,
                          const Eigen::Vector2d& p,
                          long rings,
                          const auto& f) {
    const Cell c = cell_of(p);
    for (long dx = -rings; dx <= rings; ++dx)
      for (long dy = -rings; dy <= rings; ++dy) {
        const auto found = grid.find(Cell(c.first + dx, c.second + dy));
        if (found != grid.end())
          for (const int i : found->second)
            f(i);
      }
  };
  // Nearest first: a heap of (squared distance to the nearest sample taken,
  // candidate), stale entries skipped.
  std::vector<double> nearest(m, std::numeric_limits<double>::infinity());
  std::vector<std::uint8_t> done(m, 0);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  const auto take = [&](int t) {
    taken_in[cell_of(x[t])].push_back(t);
    around(candidates_in, x[t], 2, [&](int i) {
      const double d = (x[i] - x[t]).squaredNorm();
      if (!done[i] && d < nearest[i]) {
        nearest[i] = d;
        queue.emplace(d, i);
      }
    });
  };
  for (std::size_t v = m; v < x.size(); ++v)
    take(static_cast<int>(v));
  std::vector<int> own;
  for (std::size_t left = m; left > 0; --left) {
    while (!queue.empty() && (done[queue.top().second] ||
                              queue.top().first != nearest[queue.top().second]))
      queue.pop();
    // None within two cells of what is taken: the first left (a gap in the hole).
    int next = 0;
    if (queue.empty())
      while (done[next])
        ++next;
    else
      next = queue.top().second;
    done[next] = 1;
    // The height the samples taken within a spacing give at the candidate: their
    // plane where they span one (least squares), else their mean.
    Eigen::Matrix3d moments = Eigen::Matrix3d::Zero();
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    around(taken_in, x[next], 1, [&](int t) {
      const Eigen::Vector2d d = x[t] - x[next];
      if (d.squaredNorm() < spacing * spacing) {
        const Eigen::Vector3d a(1.0, d.x(), d.y());
        moments += a * a.transpose();
        weighted += a * height[t];
      }
    });
    const double count = moments(0, 0);
    bool over = false;
    if (count > 0.0) {
      double expected = weighted(0) / count;
      const Eigen::Vector2d mean = moments.block<2, 1>(1, 0) / count;
      const Eigen::Matrix2d spread_in_plane =
          moments.block<2, 2>(1, 1) / count - mean * mean.transpose();
      if (count >= 3.0 && Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(
                              spread_in_plane, Eigen::EigenvaluesOnly)
                                  .eigenvalues()(0) > 0.04 * spacing * spacing)
        expected = moments.ldlt().solve(weighted)(0);
      over =
          std::abs(height[next] - expected) > std::max(SHEET_OFFSET * spacing, spread);
    }
    if (over)
      continue;
    own.push_back(candidates[next]);
    take(next);
  }
  return own;
}

} // namespace

HoleFilling
fillHolesWithInnerSamples(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<double>& spacing,
                          const std::vector<CoconeTriangle>& cocone_triangles,
                          std::vector<Triangle>& triangles,
                          EdgeIncidences& incidences,
                          std::vector<std::vector<int>>& loops,
                          double reach,
                          std::size_t max_edges,
                          const std::vector<std::uint8_t>& true_border,
                          double noise)
{
  using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
  using Fb = CGAL::Triangulation_face_base_with_info_2<
      bool,
      Kernel,
      CGAL::Constrained_triangulation_face_base_2<Kernel>>; // outside the loop
  using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
  using Cdt = CGAL::
      Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
  if (loops.empty())
    return HoleFilling();
  const std::size_t n = points.size();
  std::vector<std::uint8_t> used = usedVertices(triangles, n);
  // Neighbours through the co-cone triangles (compressed rows), made when a loop
  // needs them.
  std::vector<std::size_t> first;
  std::vector<int> neighbour;
  const auto group_neighbours = [&]() {
    first.assign(n + 1, 0);
    for (const auto& t : cocone_triangles)
      for (const int v : t.v)
        first[v + 1] += 2;
    for (std::size_t v = 0; v < n; ++v)
      first[v + 1] += first[v];
    neighbour.resize(first[n]);
    std::vector<std::size_t> at(first.begin(), first.end() - 1);
    for (const auto& t : cocone_triangles)
      for (int i = 0; i < 3; ++i)
        for (int j = 1; j < 3; ++j)
          neighbour[at[t.v[i]]++] = t.v[(i + j) % 3];
  };
  std::vector<int> seen(n, -1), inner, stack;
  std::vector<Cdt::Face_handle> stack_faces;
  int stamp = 0;
  const auto patch_of = [&](const std::vector<int>& loop,
                            std::vector<Triangle>& patch) {
    const std::size_t k = loop.size();
    const detail::LoopPlane hole = detail::projectLoop(points, loop);
    const auto point2 = [](const Eigen::Vector2d& x) {
      return Kernel::Point_2(x.x(), x.y());
    };
    // The loop must project to a simple polygon (a hole, not a fold round a tip).
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = i + 2; j < k; ++j)
        if ((i != 0 || j != k - 1) &&
            CGAL::do_intersect(Kernel::Segment_2(point2(hole.polygon[i]),
                                                 point2(hole.polygon[(i + 1) % k])),
                               Kernel::Segment_2(point2(hole.polygon[j]),
                                                 point2(hole.polygon[(j + 1) % k]))))
          return false;
    // A quadratic height over the plane, fitted to the loop.
    const auto monomials = [&](const Eigen::Vector3d& p) {
      const Eigen::Vector2d x = hole.flat(p) / hole.radius;
      Eigen::Matrix<double, 6, 1> m;
      m << 1.0, x.x(), x.y(), x.x() * x.x(), x.x() * x.y(), x.y() * x.y();
      return m;
    };
    Eigen::MatrixXd design(k, 6);
    Eigen::VectorXd height(k);
    double rim_spacing = 0.0;
    for (std::size_t i = 0; i < k; ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      design.row(r) = monomials(points[loop[i]]).transpose();
      height(r) = (points[loop[i]] - hole.centre).dot(hole.normal);
      rim_spacing += spacing[loop[i]] / static_cast<double>(k);
    }
    const Eigen::VectorXd fit = design.colPivHouseholderQr().solve(height);
    const auto residual = [&](int v) {
      return (points[v] - hole.centre).dot(hole.normal) - monomials(points[v]).dot(fit);
    };
    // The free samples over the hole within half a spacing of that height, reached
    // from the loop through the co-cone triangles.
    if (first.empty())
      group_neighbours();
    ++stamp;
    inner.clear();
    stack.assign(loop.begin(), loop.end());
    for (const int v : loop)
      seen[v] = stamp;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (std::size_t i = first[v]; i < first[v + 1]; ++i) {
        const int q = neighbour[i];
        if (used[q] || seen[q] == stamp)
          continue;
        seen[q] = stamp;
        if (!hole.contains(points[q]) || std::abs(residual(q)) > 0.5 * rim_spacing)
          continue;
        inner.push_back(q);
        stack.push_back(q);
      }
    }
    inner = ownSheet(hole,
                     loop,
                     inner,
                     points,
                     residual,
                     NOISE_SPREAD * noise * rim_spacing,
                     rim_spacing);
    if (inner.empty())
      return false;
    // The constrained Delaunay triangulation of the loop and the samples inside, in
    // the plane; its triangles inside the loop make the patch.
    Cdt cdt;
    std::vector<Cdt::Vertex_handle> rim;
    for (std::size_t i = 0; i < k; ++i) {
      rim.push_back(cdt.insert(point2(hole.polygon[i])));
      rim.back()->info() = loop[i];
    }
    for (std::size_t i = 0; i < k; ++i)
      cdt.insert_constraint(rim[i], rim[(i + 1) % k]);
    for (const int q : inner)
      cdt.insert(point2(hole.flat(points[q])))->info() = q;
    // Distinct in the plane (no two projected onto one point), every new edge short.
    if (cdt.number_of_vertices() != k + inner.size())
      return false;
    // Outside the loop: the faces reached from the infinite one without crossing it
    // (exact; a centroid test is not where rim vertices are collinear).
    for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
      f->info() = false;
    stack_faces.assign(1, cdt.infinite_face());
    cdt.infinite_face()->info() = true;
    while (!stack_faces.empty()) {
      const Cdt::Face_handle f = stack_faces.back();
      stack_faces.pop_back();
      for (int e = 0; e < 3; ++e)
        if (!f->is_constrained(e) && !f->neighbor(e)->info()) {
          f->neighbor(e)->info() = true;
          stack_faces.push_back(f->neighbor(e));
        }
    }
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
      if (f->info())
        continue;
      const Triangle t{
          f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
      for (int e = 0; e < 3; ++e)
        if (!f->is_constrained((e + 2) % 3) && // the edge opposite corner e + 2
            !withinReach(points, spacing, reach, t[e], t[(e + 1) % 3]))
          return false;
      patch.push_back(t);
    }
    // Counter-clockwise in the plane; the patch runs against the loop, which has the
    // mesh on its left: turned over if it runs along it.
    bool along = false;
    for (const auto& t : patch)
      for (int e = 0; e < 3; ++e)
        along = along || (t[e] == loop[0] && t[(e + 1) % 3] == loop[1]);
    if (along)
      for (Triangle& t : patch)
        std::swap(t[1], t[2]);
    for (const int q : inner)
      used[q] = 1;
    return !patch.empty();
  };
  return closeLoops(triangles, incidences, loops, max_edges, true_border, patch_of);
}

} // namespace cocone
} // namespace pcl
