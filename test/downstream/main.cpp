/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The README's example, built against the installed package.
 */

#include <pcl/surface/cocone_boundary.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>

int
main()
{
  // A hemisphere on a golden-angle spiral: one open border.
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (i + 0.5) / n, r = std::sqrt(1.0 - z * z);
    const double a = i * 2.399963229728653;
    cloud->push_back(
        pcl::PointXYZ(float(r * std::cos(a)), float(r * std::sin(a)), float(z)));
  }

  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  pcl::PointIndices boundary;
  cocone.getBoundaryPointIndices(boundary);
  std::vector<pcl::Vertices> loops;
  cocone.getBoundaryLoops(loops);
  pcl::PointCloud<pcl::Normal> normals;
  cocone.getPointNormals(normals);

  std::printf("%zu triangles, %zu undersampled points, %zu border loops\n",
              mesh.polygons.size(),
              boundary.indices.size(),
              loops.size());
  return mesh.polygons.size() > std::size_t(n) && loops.size() == 1 ? 0 : 1;
}
