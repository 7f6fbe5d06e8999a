/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * CGAL's advancing front reconstruction for cocone_benchmark, in a translation unit of
 * its own: its header alone takes longer to compile than the rest of the benchmark.
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include <Eigen/Core>

#include <vector>

namespace cocone_app {

/** \brief CGAL::advancing_front_surface_reconstruction with its default parameters;
 * the triangles index \a points. */
std::vector<pcl::cocone::Triangle>
advancingFront(const std::vector<Eigen::Vector3d>& points);

} // namespace cocone_app
