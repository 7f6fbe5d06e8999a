/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include "peer_methods.h"

#include <pcl/common/io.h>
#include <pcl/features/boundary.h>
#include <pcl/features/normal_3d.h>
#include <pcl/surface/gp3.h>

#include <cmath>

namespace cocone_app {

pcl::PointCloud<pcl::Normal>::Ptr
estimateNormals(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                const Tree::Ptr& tree)
{
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setInputCloud(cloud);
  ne.setSearchMethod(tree);
  ne.setKSearch(20);
  ne.compute(*normals);
  return normals;
}

std::vector<int>
boundaryEstimation(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                   const pcl::PointCloud<pcl::Normal>::ConstPtr& normals,
                   const Tree::Ptr& tree)
{
  pcl::BoundaryEstimation<pcl::PointXYZ, pcl::Normal, pcl::Boundary> be;
  be.setInputCloud(cloud);
  be.setInputNormals(normals);
  be.setSearchMethod(tree);
  be.setKSearch(20);
  be.setAngleThreshold(static_cast<float>(M_PI / 2.0));
  pcl::PointCloud<pcl::Boundary> flags;
  be.compute(flags);
  std::vector<int> flagged;
  for (std::size_t i = 0; i < flags.size(); ++i)
    if (flags[i].boundary_point)
      flagged.push_back(static_cast<int>(i));
  return flagged;
}

std::vector<pcl::cocone::Triangle>
greedyProjection(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
                 const pcl::PointCloud<pcl::Normal>::ConstPtr& normals,
                 double search_radius)
{
  pcl::PointCloud<pcl::PointNormal>::Ptr with_normals(
      new pcl::PointCloud<pcl::PointNormal>);
  pcl::concatenateFields(*cloud, *normals, *with_normals);
  pcl::search::KdTree<pcl::PointNormal>::Ptr tree(
      new pcl::search::KdTree<pcl::PointNormal>);
  pcl::GreedyProjectionTriangulation<pcl::PointNormal> gp3;
  gp3.setSearchRadius(search_radius);
  gp3.setMu(2.5);
  gp3.setMaximumNearestNeighbors(100);
  gp3.setInputCloud(with_normals);
  gp3.setSearchMethod(tree);
  pcl::PolygonMesh mesh;
  gp3.reconstruct(mesh);
  std::vector<pcl::cocone::Triangle> triangles;
  triangles.reserve(mesh.polygons.size());
  for (const auto& p : mesh.polygons)
    triangles.push_back({int(p.vertices[0]), int(p.vertices[1]), int(p.vertices[2])});
  return triangles;
}

} // namespace cocone_app
