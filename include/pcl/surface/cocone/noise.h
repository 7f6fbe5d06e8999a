/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/voronoi_cell.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief How noisy the sample is, and which points lie off the sampled surface.
 *
 * Read off the nearest Delaunay neighbours of the first triangulation
 * (VoronoiCells::nearest), so that a clean cloud pays a pass over them and nothing
 * more. All arrays are indexed by vertex id.
 */
struct NoiseAnalysis {
  /** Per vertex: the noise level, the RMS distance of p and its neighbours (see
   * analyzeNoise()) to their least-squares degree-2 jet over their RMS spread along
   * it, scaled to read about the Gaussian noise's sigma in units of the sample
   * spacing (measured on random samples: sigma 0.3, 0.5 and 1 read 0.30, 0.49 and
   * 0.87); clean samples of the test surfaces read below 0.05. */
  std::vector<float> level;
  /** The noise level of the cloud: the median of level over the points (those
   * counted, see analyzeNoise()). */
  double cloud_level = 0.0;
  /** Per vertex: an outlier (see analyzeNoise()). */
  std::vector<std::uint8_t> outlier;
  /** Number of outliers. */
  std::size_t outliers = 0;
};

/** \brief The noise level of every point and of the cloud, and the outliers.
 *
 * The neighbours of p are its nearest Delaunay neighbours within three local
 * spacings (the mean distance to the 6 nearest): the Delaunay neighbours of a surface
 * sample include long edges across the inside or the outside.
 *
 * An outlier is a point off the surface its neighbours sample: its distance to the
 * degree-2 jet fitted to its neighbours without p exceeds a quarter of their mean
 * spacing and 6 standard deviations of the neighbours about that jet. A flying
 * pixel a spacing or more off a clean surface and a point far from everything both
 * are; a point of a thin part, a crease or a coarse tube is not, since its
 * neighbours sit as far off their own fits; nor a point beside its neighbours rather
 * than above them (at a border, where the neighbours' fit extrapolated misses it),
 * unless it is isolated (its spacing three times theirs); nor, in a cloud whose level
 * is at most 0.1, a point with samples of a sheet of its own round it (three off the
 * jet on its side, on a plane with it: a second sheet closer than the spacing, whose
 * samples may have only the other sheet's among their nearest). Outliers next to each
 * other hide one another, so the search runs again among the neighbours that are not
 * outliers, up to three rounds. Assumes a surface sample with noise far below the
 * spacing of a dense region's neighbours in the normal direction at the outliers.
 * \param[in] points the Delaunay vertices
 * \param[in] nearest their nearest Delaunay neighbours (VoronoiCells::nearest)
 * \param[in] threads threads to compute with (the result does not depend on them)
 * \param[in] counted per vertex: counts in the cloud's level (e.g. a tile's core,
 *            not its halo); empty: every vertex
 * \param[in] not_noise the level is known not to be noise (the smoothing would not
 *            take it out): the samples of a sheet of their own are kept whatever
 *            the level
 * \param[in] mean_spacing per vertex its mean distance to its nearest neighbours
 *            (meanSpacing()), where the caller has it; empty: computed here
 */
NoiseAnalysis
analyzeNoise(const std::vector<Eigen::Vector3d>& points,
             const std::vector<std::array<int, VoronoiCells::NEAREST>>& nearest,
             int threads = 1,
             const std::vector<std::uint8_t>& counted = {},
             bool not_noise = false,
             const std::vector<double>& mean_spacing = {});

/** \brief The noise level of the cloud (NoiseAnalysis::cloud_level) read again on
 * other positions of the same points, with the same neighbours, on one point in 4:
 * after smoothing, whether it took the noise out. Noise goes, while a surface too
 * coarse or too creased for the jets of a few neighbours reads as high as before.
 * \param[in] points positions of the Delaunay vertices
 * \param[in] nearest their nearest Delaunay neighbours (VoronoiCells::nearest)
 * \param[in] outlier per vertex: an outlier, left out (empty: none)
 * \param[in] threads threads to compute with (the result does not depend on them)
 * \param[in] counted per vertex: counts (see analyzeNoise()); empty: every vertex
 */
double
cloudNoiseLevel(const std::vector<Eigen::Vector3d>& points,
                const std::vector<std::array<int, VoronoiCells::NEAREST>>& nearest,
                const std::vector<std::uint8_t>& outlier,
                int threads = 1,
                const std::vector<std::uint8_t>& counted = {});

/** \brief The median pole height h+ of the sample's vertices in local spacings
 * (VoronoiCells::height_plus over the mean distance to the nearest neighbours),
 * outliers and the convex hull's vertices left out.
 *
 * Noise shortens the Voronoi cells across the surface: a point's neighbours above
 * and below it in the noise band bound its cell near it, so the pole is near (the
 * polar balls are small, as Robust Cocone observes). A clean sample's poles lie at
 * the local feature size, many spacings out. Measured on the vertex sets of closed
 * meshes: clean 5 to 18 spacings (a coarse knotted tube 1.9, a CAD part 3.9); with
 * Gaussian noise of 0.2, 0.3, 0.5 and 1 spacing 1.8 to 5.4, 1.7 to 4.1, 1.5 to 2.8
 * and 1.4 to 1.8. Smoothing that takes noise out lengthens them 1.8 to 5.4 times;
 * on a clean sample it lengthens them 1.0 to 1.4 times (1.9 on one).
 * \param[in] cells the sample's first pass (VoronoiCells::height_plus)
 * \param[in] mean_spacing per vertex its mean distance to its nearest neighbours
 *            (meanSpacing())
 * \param[in] outlier per vertex: an outlier, left out (empty: none)
 * \param[in] counted per vertex: counts (see analyzeNoise()); empty: every vertex
 * \return the median; 0 if no vertex has a finite one
 */
double
medianPoleHeight(const VoronoiCells& cells,
                 const std::vector<double>& mean_spacing,
                 const std::vector<std::uint8_t>& outlier = {},
                 const std::vector<std::uint8_t>& counted = {});

/** \brief The kurtosis E|d|^4 / (E|d|^2)^2 of the displacements d of the points
 * from \a before to \a after (smoothPoints()), outliers left out.
 *
 * Smoothing moves a noisy point by its noise, along the normal: Gaussian noise
 * reads 3 (measured 2.8 to 3.1 on the test surfaces with noise of 0.3 to 1 spacing,
 * heavier tails more: 8 to 70 on real scans). Where the points are no noisy sample
 * of one smooth sheet, smoothing moves them all by about as much, the same way, and
 * the kurtosis is low: two sheets closer than the spacing pulled onto one (a
 * bimodal spread, about 1), a tube with a few samples round it pulled towards its
 * axis, a crease rounded (measured 1.05 to 2.46 on thin plates, tubes and cubes).
 * Assumes the noise is not lighter-tailed than Gaussian: uniform noise reads 1.8.
 * \return the kurtosis; 0 if no point moved
 */
double
displacementKurtosis(const std::vector<Eigen::Vector3d>& before,
                     const std::vector<Eigen::Vector3d>& after,
                     const std::vector<std::uint8_t>& outlier);

/** \brief The points projected onto local fits (scale space): each point moves onto
 * the quadratic height field (a degree-2 jet, as CGAL's jet_smooth_point_set) fitted
 * by least squares to it and its neighbours, \a iterations times, the neighbourhoods
 * found once. The neighbours are the K nearest among p's nearest Delaunay neighbours
 * and their 10 nearest (a two-ring, K = 24 as CGAL's default neighbourhood); outliers
 * neither move nor count as anyone's neighbour.
 *
 * Written here rather than called from CGAL: jet_smooth_point_set takes 41 s on a
 * million points (its k-d tree search 11 s, its Monge fit by SVD most of the rest),
 * five times the Delaunay triangulation; this pass reads the neighbours the
 * triangulation already found and solves a 6 x 6 system per point.
 * \param[in] points the Delaunay vertices
 * \param[in] nearest their nearest Delaunay neighbours (VoronoiCells::nearest)
 * \param[in] outlier per vertex: an outlier (empty: none)
 * \param[in] iterations projections (1 or more)
 * \param[in] threads threads to compute with (the result does not depend on them)
 */
std::vector<Eigen::Vector3d>
smoothPoints(const std::vector<Eigen::Vector3d>& points,
             const std::vector<std::array<int, VoronoiCells::NEAREST>>& nearest,
             const std::vector<std::uint8_t>& outlier,
             int iterations,
             int threads = 1);

} // namespace cocone
} // namespace pcl
