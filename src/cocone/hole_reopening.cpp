/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/hole_reopening.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl {
namespace cocone {

std::vector<std::uint8_t>
trianglesRoundLoop(const std::vector<Triangle>& triangles,
                   const std::vector<int>& loop,
                   int rings,
                   std::size_t num_vertices,
                   std::vector<std::uint8_t>* corners)
{
  std::vector<std::uint8_t> reached(num_vertices, 0), within(triangles.size(), 0);
  for (const int v : loop)
    reached[v] = 1;
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<std::uint8_t> next = reached;
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const Triangle& tri = triangles[t];
      if (reached[tri[0]] || reached[tri[1]] || reached[tri[2]]) {
        within[t] = 1;
        next[tri[0]] = next[tri[1]] = next[tri[2]] = 1;
      }
    }
    reached = std::move(next);
  }
  // A vertex the removal would pinch (its star left in two fans or more) loses the
  // rest of its star too: the wider hole must leave an oriented manifold to be
  // closed again (on FinalBaseMesh with noise 0.3, a third of the attempts pinched
  // one and were undone). Only a corner of a triangle taken out can be pinched, and
  // all of what is left of its star has it as a corner: the fans are counted on
  // those triangles alone (the whole mesh's, per attempt, cost as much as a pass).
  for (bool pinched = true; pinched;) {
    pinched = false;
    const std::vector<std::uint8_t> touched = reached;
    const auto near = [&](const Triangle& tri) {
      return touched[tri[0]] || touched[tri[1]] || touched[tri[2]];
    };
    std::vector<Triangle> left;
    for (std::size_t t = 0; t < triangles.size(); ++t)
      if (!within[t] && near(triangles[t]))
        left.push_back(triangles[t]);
    std::vector<int> fans;
    vertexFans(left, num_vertices, &fans);
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const Triangle& tri = triangles[t];
      if (within[t] || !near(tri))
        continue;
      if (std::any_of(tri.begin(), tri.end(), [&](int v) {
            return touched[v] && fans[v] > 1;
          })) {
        within[t] = 1;
        reached[tri[0]] = reached[tri[1]] = reached[tri[2]] = 1;
        pinched = true;
      }
    }
  }
  // After the last ring: the loop and every corner of the triangles within.
  if (corners != nullptr)
    *corners = std::move(reached);
  return within;
}

bool
insertLeftOut(const std::vector<Eigen::Vector3d>& points,
              const std::vector<double>& spacing,
              const std::vector<Triangle>& before,
              std::vector<Triangle>& after,
              const std::vector<std::uint8_t>& region,
              double reach)
{
  // Exact distances are not needed (a length compared with a tolerance, the nearest
  // of a few triangles), so the plain double kernel.
  using Kernel = CGAL::Simple_cartesian<double>;
  const auto point = [&](int v) {
    return Kernel::Point_3(points[v].x(), points[v].y(), points[v].z());
  };
  const std::vector<std::uint8_t> used_before = usedVertices(before, points.size()),
                                  used_after = usedVertices(after, points.size());
  // The triangles round the change, found once: a split adds its two new ones.
  const auto round_change = [&](const Triangle& tri) {
    return region[tri[0]] || region[tri[1]] || region[tri[2]];
  };
  // Each with a ball round it (its centroid, the farthest corner): a triangle whose
  // ball is farther off than the nearest triangle so far is not measured.
  struct Round {
    std::size_t t;
    Eigen::Vector3d centre;
    double radius;
  };
  const auto ball = [&](std::size_t t) {
    const Triangle& tri = after[t];
    Round r{t, (points[tri[0]] + points[tri[1]] + points[tri[2]]) / 3.0, 0.0};
    for (const int v : tri)
      r.radius = std::max(r.radius, (points[v] - r.centre).norm());
    return r;
  };
  std::vector<Round> round;
  for (std::size_t t = 0; t < after.size(); ++t)
    if (round_change(after[t]))
      round.push_back(ball(t));
  bool all = true;
  for (std::size_t v = 0; v < points.size(); ++v) {
    if (!used_before[v] || used_after[v])
      continue;
    const Kernel::Point_3 p = point(static_cast<int>(v));
    double nearest2 = std::numeric_limits<double>::infinity();
    std::size_t nearest = round.size();
    for (std::size_t i = 0; i < round.size(); ++i) {
      const Triangle& tri = after[round[i].t];
      if (!round_change(tri))
        continue;
      // The ball is no farther than the triangle (a margin for the rounding).
      const double below = (points[v] - round[i].centre).norm() - round[i].radius;
      if (below > 0.0 && below * below > nearest2 * (1.0 + 1e-9))
        continue;
      const double d2 = CGAL::squared_distance(
          p, Kernel::Triangle_3(point(tri[0]), point(tri[1]), point(tri[2])));
      if (d2 < nearest2) {
        nearest2 = d2;
        nearest = i;
      }
    }
    if (nearest == round.size() || std::sqrt(nearest2) > reach * spacing[v]) {
      all = false;
      continue;
    }
    const std::size_t split = round[nearest].t;
    const Triangle t = after[split];
    const int x = static_cast<int>(v);
    after[split] = {t[0], t[1], x};
    after.push_back({t[1], t[2], x});
    after.push_back({t[2], t[0], x});
    round[nearest] = ball(split);
    round.push_back(ball(after.size() - 2));
    round.push_back(ball(after.size() - 1));
  }
  return all;
}

} // namespace cocone
} // namespace pcl
