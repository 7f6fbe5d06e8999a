/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** A border loop projected onto its best-fit plane: what the classification of the
 * loops and the patches through the samples inside them read of a hole. */
struct LoopPlane {
  Eigen::Vector3d centre, normal, u, w;
  /** The loop's vertices in the plane's coordinates (u, w), in the loop's order. */
  std::vector<Eigen::Vector2d> polygon;
  /** The farthest loop vertex from the centre. */
  double radius = 0.0;

  /** \a p in the plane's coordinates. */
  Eigen::Vector2d
  flat(const Eigen::Vector3d& p) const
  {
    const Eigen::Vector3d q = p - centre;
    return {q.dot(u), q.dot(w)};
  }

  /** Whether \a x (plane coordinates) is inside the polygon (crossings of a ray
   * along +u). */
  bool
  inside(const Eigen::Vector2d& x) const
  {
    bool in = false;
    for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
      const Eigen::Vector2d &a = polygon[i], &b = polygon[j];
      if ((a.y() > x.y()) != (b.y() > x.y()) &&
          x.x() < a.x() + (b.x() - a.x()) * (x.y() - a.y()) / (b.y() - a.y()))
        in = !in;
    }
    return in;
  }

  /** Whether \a p lies over the hole: within the loop's radius of its centre, within
   * half of it of the plane, and inside the polygon. */
  bool
  contains(const Eigen::Vector3d& p) const
  {
    const Eigen::Vector3d q = p - centre;
    return q.norm() <= radius && std::abs(q.dot(normal)) <= 0.5 * radius &&
           inside(flat(p));
  }
};

/** The best-fit plane of \a loop (vertex ids into \a points) and its projection. */
inline LoopPlane
projectLoop(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& loop)
{
  LoopPlane p;
  p.centre.setZero();
  for (const int v : loop)
    p.centre += points[v];
  p.centre /= static_cast<double>(loop.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const int v : loop) {
    const Eigen::Vector3d q = points[v] - p.centre;
    scatter += q * q.transpose();
    p.radius = std::max(p.radius, q.norm());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  p.normal = eigen.eigenvectors().col(0);
  p.w = eigen.eigenvectors().col(1);
  p.u = eigen.eigenvectors().col(2);
  for (const int v : loop)
    p.polygon.push_back(p.flat(points[v]));
  return p;
}

} // namespace detail
} // namespace cocone
} // namespace pcl
