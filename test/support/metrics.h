/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>

#include <Eigen/Core>

#include <support/surfaces.h>

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace cocone_test {

/** \brief Fixed-radius queries on a point set through a uniform hash grid. */
class NearQuery {
public:
  NearQuery(const std::vector<Eigen::Vector3d>& points, double cell);

  /** Distance to the nearest point if it is within \a radius, else infinity. */
  double
  nearest(const Eigen::Vector3d& q, double radius) const;

  /** Indices of the points within \a radius of \a q. */
  std::vector<int>
  within(const Eigen::Vector3d& q, double radius) const;

private:
  std::int64_t
  key(long x, long y, long z) const;

  /** Call f(index, distance) for the points in the grid cells within radius. */
  template <typename Visit>
  void
  visit(const Eigen::Vector3d& q, double radius, const Visit& f) const;

  const std::vector<Eigen::Vector3d>& points_;
  double cell_;
  std::unordered_map<std::int64_t, std::vector<int>> grid_;
};

/** \brief Quality of a reported boundary against the true boundary curve.
 *
 * Distances are in local sample spacings (the mean nearest-neighbour distance of the
 * samples within four global spacings), so that unevenly sampled surfaces are judged
 * by their own density. */
struct BoundaryScore {
  /** Share of the true boundary curve with a reported point within 2.5 spacings. */
  double recall = 0.0;
  /** Share of reported points within 3 spacings of the true boundary. */
  double precision = 0.0;
  /** Reported points / all points. */
  double reported_share = 0.0;
  std::size_t reported = 0;

  std::string
  str() const;
};

/** \brief Score reported boundary indices (into s.points) against s. */
BoundaryScore
scoreBoundary(const Sample& s, const std::vector<int>& reported);

/** \brief Quality of a reconstructed mesh against its sample's ground truth. */
struct MeshScore {
  pcl::cocone::MeshTopology topology;
  std::size_t loops = 0;
  /** Share of the sample's points used by a triangle. */
  double used_share = 0.0;
  /** Largest distance of a triangle's centroid or edge midpoint from the true
   * surface, in sample spacings. */
  double max_distance = 0.0;
  /** Signed volume of the mesh (positive: facing outward). */
  double volume = 0.0;

  std::string
  str() const;
};

/** \brief Score the mesh of a pipeline result computed on s.points. */
MeshScore
scoreMesh(const Sample& s, const pcl::cocone::Result& r);

} // namespace cocone_test
