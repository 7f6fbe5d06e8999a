/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * A user's own point type: PCL_NO_PRECOMPILE pulls in the template code.
 */

#define PCL_NO_PRECOMPILE
#include <pcl/surface/cocone_boundary.h>
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <gtest/gtest.h>

#include <cmath>

struct EIGEN_ALIGN16 ScanPoint {
  PCL_ADD_POINT4D;
  float reflectance;
  std::uint32_t ring;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

POINT_CLOUD_REGISTER_POINT_STRUCT(
    ScanPoint,
    (float, x, x)(float, y, y)(float, z, z)(float,
                                            reflectance,
                                            reflectance)(std::uint32_t, ring, ring))

TEST(CustomPointType, ReconstructsAndKeepsItsFields)
{
  pcl::PointCloud<ScanPoint>::Ptr cloud(new pcl::PointCloud<ScanPoint>);
  const int n = 3000;
  for (int i = 0; i < n; ++i) { // a hemisphere on a golden-angle spiral
    const double z = 1.0 - (i + 0.5) / n, r = std::sqrt(1.0 - z * z);
    ScanPoint p;
    p.x = float(r * std::cos(i * 2.399963229728653));
    p.y = float(r * std::sin(i * 2.399963229728653));
    p.z = float(z);
    p.reflectance = 0.25f * float(i % 5);
    p.ring = std::uint32_t(i / 100);
    cloud->push_back(p);
  }
  pcl::CoConeBoundary<ScanPoint> cocone;
  cocone.setInputCloud(cloud);
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  EXPECT_GT(mesh.polygons.size(), std::size_t(n));
  std::vector<pcl::Vertices> loops;
  cocone.getBoundaryLoops(loops);
  EXPECT_EQ(loops.size(), 1u);
  pcl::PointCloud<ScanPoint> back;
  pcl::fromPCLPointCloud2(mesh.cloud, back);
  ASSERT_EQ(back.size(), cloud->size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].reflectance, (*cloud)[i].reflectance);
    EXPECT_EQ(back[i].ring, (*cloud)[i].ring);
  }
}
