/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Border truth and its score, shared by cocone_scan_eval and cocone_benchmark.
 */

#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <vector>

namespace cocone_app {

/** \brief The true border points of a cloud. */
struct BorderTruth {
  std::vector<int> border; ///< indices into the compact cloud, ascending
  std::size_t loops = 0;
  double spacing = 0.0; ///< the sampling step the score's tolerance is measured in
};

/** \brief Border loops of a range grid with at most this many vertices (up to about
 * two missing pixels) do not count as holes. */
constexpr std::size_t MIN_GRID_LOOP = 8;

/** \brief Triangulate a range grid and take its borders.
 *
 * A range image's grid is the scanned surface's mesh: neighbouring valid pixels whose
 * 3D edges are short (below 4 median grid spacings) form triangles, and that mesh's
 * borders (outline and occlusion holes) are the truth; loops of at most
 * MIN_GRID_LOOP vertices are below the sampling resolution and do not count.
 *
 * \param[in] organized the range grid, invalid pixels not finite
 * \param[in] compact_of per pixel: its index in the cloud of the finite pixels, or -1
 * \return the border with spacing = the median grid spacing
 */
BorderTruth
gridBorderTruth(const pcl::PointCloud<pcl::PointXYZ>& organized,
                const std::vector<int>& compact_of);

/** \brief Precision and recall of reported border points. */
struct BorderScore {
  double precision = 0.0, recall = 0.0, f1 = 0.0;
};

/** \brief Score reported border points against the truth.
 *
 * A reported point is correct if a true border point lies within 2 truth.spacing; a
 * true border point is found if a reported one lies that close. With no reported
 * point the precision is 0; with no true border point the recall is 0.
 */
BorderScore
scoreBorder(const pcl::PointCloud<pcl::PointXYZ>& cloud,
            const std::vector<int>& reported,
            const BorderTruth& truth);

} // namespace cocone_app
