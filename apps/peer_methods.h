/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The PCL methods this library is compared with, set up as they are used in
 * practice; shared by cocone_benchmark and cocone_scan_eval.
 */

#pragma once

#include <pcl/search/kdtree.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <vector>

namespace cocone_app {

using Tree = pcl::search::KdTree<pcl::PointXYZ>;

/** \brief Normals from the 20 nearest points (pcl::NormalEstimation). */
pcl::PointCloud<pcl::Normal>::Ptr
estimateNormals(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                const Tree::Ptr& tree);

/** \brief The points pcl::BoundaryEstimation flags (20 neighbours, angle pi/2). */
std::vector<int>
boundaryEstimation(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                   const pcl::PointCloud<pcl::Normal>::ConstPtr& normals,
                   const Tree::Ptr& tree);

/** \brief pcl::GreedyProjectionTriangulation (mu 2.5, 100 neighbours) over the
 * cloud's indices. */
std::vector<pcl::cocone::Triangle>
greedyProjection(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                 const pcl::PointCloud<pcl::Normal>::ConstPtr& normals,
                 double search_radius);

} // namespace cocone_app
