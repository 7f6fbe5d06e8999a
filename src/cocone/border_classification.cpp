/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/border_classification.h>

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "cocone_neighbours.h"
#include "disjoint_sets.h"
#include "loop_plane.h"
#include "points.h"

#include <algorithm>
#include <cmath>

namespace pcl {
namespace cocone {

namespace {

/** The diameter of the widest disk centred in \a hole's polygon that holds none of
 * its vertices nor of \a inner (plane coordinates): the largest Delaunay circle
 * whose centre is inside the polygon. */
double
widestEmptyDisk(const detail::LoopPlane& hole,
                const std::vector<Eigen::Vector2d>& inner)
{
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<Kernel::Point_2> sites;
  for (const auto* set : {&hole.polygon, &inner})
    for (const auto& p : *set)
      sites.emplace_back(p.x(), p.y());
  const CGAL::Delaunay_triangulation_2<Kernel> dt(sites.begin(), sites.end());
  double widest = 0.0;
  for (const auto face : dt.finite_face_handles()) {
    const Kernel::Point_2 c = CGAL::circumcenter(
        face->vertex(0)->point(), face->vertex(1)->point(), face->vertex(2)->point());
    if (hole.inside({c.x(), c.y()}))
      widest = std::max(widest, CGAL::squared_distance(c, face->vertex(0)->point()));
  }
  return 2.0 * std::sqrt(widest);
}

/** A loop that this share of its piece's other vertices lie over (within its
 * radius, near its plane, inside it: LoopPlane::contains()) runs round the whole
 * piece: the piece's outline, not a hole in it, which has the surface going on all
 * round. Capped, it would lay a second sheet over the piece, a closed pillow of no
 * volume: measured on PCL's 397-point bunny (one view), whose ear, cut off from
 * the head, came out so, and on the merged Stanford scans, whose flakes off the
 * surface (8 to 41 vertices) did. */
constexpr double OUTLINE_SHARE = 0.9;

/** The pieces (connected components) of the mesh: per vertex its piece, -1 for
 * a vertex no triangle uses; per piece its bounding box and its vertices, piece
 * after piece in one array (those of piece k from first[k] to first[k + 1]). */
struct Pieces {
  std::vector<int> of, first, vertices;
  std::vector<Eigen::Vector3d> low, high;
};

Pieces
meshPieces(const std::vector<Eigen::Vector3d>& points,
           const std::vector<Triangle>& triangles)
{
  // Joined through vertices rather than edges (triangleComponents()): the repaired
  // mesh has one fan per vertex, so the pieces are the same, without the edges.
  detail::DisjointSets sets(points.size());
  std::vector<std::uint8_t> used(points.size(), 0);
  for (const auto& t : triangles) {
    sets.unite(t[0], t[1]);
    sets.unite(t[0], t[2]);
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  Pieces out;
  out.of.assign(points.size(), -1);
  std::vector<int> piece_of_root(points.size(), -1);
  std::vector<int> count;
  for (std::size_t v = 0; v < points.size(); ++v) {
    if (!used[v])
      continue;
    int& piece = piece_of_root[sets.find(static_cast<int>(v))];
    if (piece < 0) {
      piece = static_cast<int>(count.size());
      count.push_back(0);
      out.low.push_back(points[v]);
      out.high.push_back(points[v]);
    }
    out.of[v] = piece;
    ++count[piece];
    out.low[piece] = out.low[piece].cwiseMin(points[v]);
    out.high[piece] = out.high[piece].cwiseMax(points[v]);
  }
  out.first.assign(count.size() + 1, 0);
  for (std::size_t k = 0; k < count.size(); ++k)
    out.first[k + 1] = out.first[k] + count[k];
  out.vertices.resize(out.first.back());
  std::vector<int> next(out.first.begin(), out.first.end() - 1);
  for (std::size_t v = 0; v < points.size(); ++v)
    if (out.of[v] >= 0)
      out.vertices[next[out.of[v]]++] = static_cast<int>(v);
  return out;
}

/** Whether \a loop (projected as \a hole) is the outline of its piece: a strip or
 * flake a few samples across, with no more vertices inside it than on the loop
 * (which the width alone reads as narrow as a hole), whose other vertices lie over
 * the loop (OUTLINE_SHARE of them). A wider piece can lie inside a loop of its own
 * that must close: the slit round the rim of a plate thinner than the spacing,
 * both of whose sheets lie over it (without the bound the generated sweep's clean
 * thin plates kept 40 loops beyond the truth rather than 19). A closed surface's
 * hole is none: the rest of the surface leaves the hole's plane. */
bool
isOutline(const std::vector<Eigen::Vector3d>& points,
          const std::vector<int>& loop,
          const detail::LoopPlane& hole,
          const Pieces& pieces)
{
  const int piece = pieces.of[loop.front()];
  if (piece < 0)
    return false;
  // A piece that lies over its loop lies within the loop's radius of its centre,
  // its bounding box within twice the loop's diameter: the large pieces with small
  // holes are passed over without a look at their vertices.
  const Eigen::Vector3d reach = pieces.high[piece] - pieces.low[piece];
  if (reach.norm() > 4.0 * hole.radius)
    return false;
  const auto begin = pieces.vertices.begin() + pieces.first[piece],
             end = pieces.vertices.begin() + pieces.first[piece + 1];
  const std::size_t others = static_cast<std::size_t>(end - begin) - loop.size();
  if (others > loop.size())
    return false;
  std::size_t outside = 0;
  for (auto v = begin; v != end; ++v)
    if (!hole.contains(points[*v]) &&
        std::find(loop.begin(), loop.end(), *v) == loop.end() &&
        ++outside > (1.0 - OUTLINE_SHARE) * static_cast<double>(others))
      return false;
  return others > 0;
}

} // namespace

std::vector<std::uint8_t>
classifyBorderLoops(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Triangle>& triangles,
                    const std::vector<std::vector<int>>& loops,
                    const std::vector<CoconeTriangle>& cocone_triangles,
                    double max_width,
                    std::size_t max_edges)
{
  std::vector<std::uint8_t> border(loops.size(), 1);
  // The repaired mesh has one fan per vertex: a vertex is on at most one loop.
  std::vector<int> loop_of(points.size(), -1);
  bool any = false;
  for (std::size_t l = 0; l < loops.size(); ++l)
    if (loops[l].size() >= 3 && loops[l].size() <= max_edges) {
      any = true;
      for (const int v : loops[l])
        loop_of[v] = static_cast<int>(l);
    }
  if (max_width <= 0.0)
    return std::vector<std::uint8_t>(loops.size(), 0);
  if (!any)
    return border;

  // The triangles at each loop's rim, by their circumradii.
  std::vector<std::vector<double>> rim_radii(loops.size());
  for (const auto& t : triangles) {
    int last = -1;
    for (const int v : t) {
      const int l = loop_of[v];
      if (l >= 0 && l != last) { // counted once per loop
        rim_radii[l].push_back(
            detail::circumradius(points[t[0]], points[t[1]], points[t[2]]));
        last = l;
      }
    }
  }
  const Pieces pieces = meshPieces(points, triangles);
  // The co-cone triangles' corners at each point, to find the points in each hole.
  const detail::CoconeNeighbours around = detail::coconeNeighbours(
      cocone_triangles, points.size(), [](int) { return true; });
  std::vector<int> seen(points.size(), -1), queue;
  std::vector<Eigen::Vector2d> inner;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const auto& loop = loops[l];
    auto& radii = rim_radii[l];
    if (loop.size() < 3 || loop.size() > max_edges || radii.empty())
      continue;
    const detail::LoopPlane hole = detail::projectLoop(points, loop);
    if (isOutline(points, loop, hole, pieces))
      continue; // a true border

    // The points in the hole: reached from the loop through co-cone triangles,
    // each projecting into it.
    const int stamp = static_cast<int>(l);
    inner.clear();
    queue.assign(loop.begin(), loop.end());
    for (const int v : loop)
      seen[v] = stamp;
    for (std::size_t q = 0; q < queue.size(); ++q)
      for (std::size_t a = around.first[queue[q]]; a < around.first[queue[q] + 1];
           ++a) {
        const int v = around.neighbour[a];
        if (seen[v] != stamp && hole.contains(points[v])) {
          seen[v] = stamp;
          queue.push_back(v);
          inner.push_back(hole.flat(points[v]));
        }
      }
    double area = 0.0, length = 0.0;
    for (std::size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
      const Eigen::Vector2d &a = hole.polygon[j], &b = hole.polygon[i];
      area += a.x() * b.y() - b.x() * a.y();
      length += (points[loop[i]] - points[loop[j]]).norm();
    }
    // 4 A / P (A = |area| / 2); with points in the hole, the widest opening they
    // leave.
    double width = 2.0 * std::abs(area) / length;
    if (!inner.empty())
      width = std::min(width, widestEmptyDisk(hole, inner));
    border[l] = width > max_width * detail::rimDiameter(radii);
  }
  return border;
}

} // namespace cocone
} // namespace pcl
