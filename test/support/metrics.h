/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <support/surfaces.h>

#include <Eigen/Core>

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

private:
  std::int64_t
  key(long x, long y, long z) const;

  const std::vector<Eigen::Vector3d>& points_;
  double cell_;
  std::unordered_map<std::int64_t, std::vector<int>> grid_;
};

/** \brief Quality of a reported boundary against the true boundary curve. */
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

} // namespace cocone_test
