/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/voronoi_cell.h>

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief Parameters of the flatness test (Dey & Giesen, Definition 2). */
struct FlatnessParameters {
  /** Ratio rho: a flat cell has rho * width <= height. */
  double ratio = 1.5;
  /** Normal angle theta (radians): largest angle between the pole lines of p and
   * of every q that has p as a co-cone neighbour. */
  double normal_angle = 0.5235987755982988; // pi / 6
};

/** \brief Per-vertex outcome of stage 3. */
struct BoundaryLabels {
  /** rho * w(V_p) <= h(V_p). */
  std::vector<std::uint8_t> ratio_ok;
  /** The ratio and the normal condition hold (ISFLAT). */
  std::vector<std::uint8_t> flat;
  /** The interior set R after growth; the boundary set is its complement. */
  std::vector<std::uint8_t> interior;
};

/** \brief ISFLAT for every vertex and BOUNDARY's growth of R to a fixed point.
 *
 * A vertex p joins R through a q already in R that has p as a co-cone neighbour,
 * when p satisfies the ratio condition and the pole lines of p and q make an angle
 * of at most theta. The fixed point does not depend on the order of the growth.
 */
BoundaryLabels
detectBoundary(const VoronoiCells& cells, const FlatnessParameters& parameters);

} // namespace cocone
} // namespace pcl
