/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/triangulation.h>
#include <pcl/surface/cocone/voronoi_cell.h>

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief Parameters of the flatness test (Dey & Giesen, Definition 2). */
struct FlatnessParameters {
  /** Ratio rho: a flat cell has rho * width <= height. 0: chosen from the cloud,
   * rho = clamp(1 / (2 Q95(w / h)), 0.5, 4) (see automaticRatio()). */
  double ratio = 1.5;
  /** Normal angle theta (radians): largest angle between the pole lines of p and
   * of every q that has p as a co-cone neighbour. */
  double normal_angle = 0.5235987755982988; // pi / 6
  /** Spacing factor a: a flat cell also has width <= a * s_p, s_p the local sample
   * spacing (see localSpacing()); 0 turns this test off (the paper's test). */
  double spacing_factor = 0.0;
};

/** \brief Local sample spacing s_p: the mean distance of p to its 6 nearest Delaunay
 * neighbours (VoronoiCells::nearest) but those more than 10 times as far as their
 * median (edges across a hole or along the convex hull), maximised over p and those
 * neighbours.
 *
 * The width of an interior Voronoi cell is about the spacing whatever the scale or
 * the noise (w / s <= 1.3 measured), while at a border the cell reaches out several
 * spacings (w / s >= 3): unlike w / h, the ratio w / s does not depend on how the
 * border compares with the local feature size.
 * \param[in] threads threads to compute with (the spacings do not depend on them)
 */
std::vector<double>
localSpacing(const std::vector<Eigen::Vector3d>& points,
             const VoronoiCells& cells,
             int threads = 1);

/** \brief The local spacing (see localSpacing()) from the mean distances of the
 * vertices to their neighbours (meanSpacing()), where a stage before has them.
 * \param[in] cells the Voronoi pass (its nearest neighbour lists)
 * \param[in] mean per vertex its mean distance (meanSpacing())
 * \param[in] threads threads to compute with (the spacings do not depend on them)
 */
std::vector<double>
localSpacing(const VoronoiCells& cells,
             const std::vector<double>& mean,
             int threads = 1);

/** \brief Per vertex the mean distance of p to its 6 nearest Delaunay neighbours but
 * those more than 10 times as far as their median: what localSpacing() maximises,
 * and what the noise analysis reads its neighbourhoods by (see analyzeNoise()).
 * \param[in] points the Delaunay vertices
 * \param[in] cells the Voronoi pass (its nearest neighbour lists)
 * \param[in] threads threads to compute with (the distances do not depend on them)
 */
std::vector<double>
meanSpacing(const std::vector<Eigen::Vector3d>& points,
            const VoronoiCells& cells,
            int threads = 1);

/** \brief Outcome of the half-disk test (see halfDiskTest()). */
struct HalfDisk {
  /** Per vertex: the largest angle between consecutive nearby neighbours seen along
   * the pole line; 2 pi when fewer than two neighbours are near. Exact where it
   * exceeds the gap angle used (and at the median's sample); elsewhere the gap seen
   * through the one-ring alone, an upper bound that is at most that angle. */
  std::vector<double> gap;
  /** The gap angle used: the one asked for, times (median gap / 50 degrees)^2 if
   * that is more than 1. */
  double angle = 0.0;
  /** Per vertex: a rim vertex (gap above the gap angle, and two rim neighbours). */
  std::vector<std::uint8_t> rim;
};

/** \brief The half-disk test: a point on a border has its surface neighbours on one
 * side only.
 *
 * The neighbours of p are the vertices within \a reach * s_p of it (s_p:
 * localSpacing()) joined to it by one or two short Delaunay edges (of the nearest
 * ones, VoronoiCells::nearest, those within reach); seen along p's pole line, i.e.
 * projected on the plane normal to it, they leave an angular gap around p. Inside a
 * surface the gaps are small, at a border the gap is a half plane or more. The test
 * sees borders that the Voronoi tests pass: where the scanner grazes a surface a
 * border point's cell is bounded by the sparse samples beyond it, or by the far
 * side of a slit a few spacings wide, and is as narrow as an interior cell.
 *
 * A vertex is a rim vertex when its gap exceeds the gap angle and at least two of
 * its Delaunay neighbours within reach have such gaps as well: a border is a curve,
 * an isolated gap (an irregular spot of an even sample) is not. The gaps inside a
 * surface grow with the irregularity of the sample: their median is about 50
 * degrees on range grids and even samples and 75 on area-uniform random samples,
 * where 80 degrees would flag a third of the points. The gap angle used is
 * \a gap_angle times (median gap / 50 degrees)^2 when that is larger; the median is
 * that of all the vertices below 131,072, of a sample of 65,536 to 131,071 spread
 * evenly along the ids (a space-filling curve) above; of the vertices counted.
 *
 * \param[in] points the triangulation's points
 * \param[in] cells stage 2 output (the poles, the nearest neighbours)
 * \param[in] spacing per vertex s_p (localSpacing())
 * \param[in] reach neighbours count within reach * s_p
 * \param[in] gap_angle the largest gap (radians) of a point that is not a rim point
 * \param[in] threads number of threads (the result does not depend on it)
 * \param[in] counted per vertex: counts in the median (e.g. a tile's core, not its
 *            halo); empty: every vertex
 */
HalfDisk
halfDiskTest(const std::vector<Eigen::Vector3d>& points,
             const VoronoiCells& cells,
             const std::vector<double>& spacing,
             double reach,
             double gap_angle,
             int threads = 1,
             const std::vector<std::uint8_t>& counted = {});

/** \brief The automatic ratio rho = clamp(1 / (2 Q95(w / h)), 0.5, 4).
 *
 * Theory ties rho to the sampling density (rho = 1 / (1.3 epsilon)) and w / h of
 * interior cells is of the order of epsilon: the 95th percentile of w / h over the
 * cloud measures epsilon with room for the few border points.
 *
 * \param[in] cells stage 2 output
 * \param[in] counted per vertex: counts in the percentile (e.g. a tile's core, not
 *            its halo); empty: every vertex */
double
automaticRatio(const VoronoiCells& cells,
               const std::vector<std::uint8_t>& counted = {});

/** \brief Per-vertex outcome of stage 3. */
struct BoundaryLabels {
  /** The ratio rho used (the automatic one if FlatnessParameters::ratio was 0). */
  double ratio = 0.0;
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
 *
 * \param[in] cells stage 2 output
 * \param[in] parameters rho, theta and the spacing factor
 * \param[in] spacing per vertex s_p (localSpacing()); needed if the spacing factor
 *            is not 0
 * \param[in] threads threads to test with (the labels do not depend on them)
 */
BoundaryLabels
detectBoundary(const VoronoiCells& cells,
               const FlatnessParameters& parameters,
               const std::vector<double>& spacing = {},
               int threads = 1);

} // namespace cocone
} // namespace pcl
