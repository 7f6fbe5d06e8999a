/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include "screenshot.h"

#include <pcl/common/common.h>
#include <pcl/common/io.h>
#include <pcl/visualization/pcl_visualizer.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

namespace cocone_app {

bool
renderScreenshot(const pcl::PolygonMesh& mesh,
                 const pcl::PCLPointCloud2& cloud,
                 const pcl::Indices& boundary,
                 const std::string& png,
                 std::string& error)
{
  // The visualizer needs its interactor for saveScreenshot.
  pcl::visualization::PCLVisualizer viewer("pcl_cocone_reconstruction", true);
  viewer.setSize(1024, 768);
  viewer.setBackgroundColor(1.0, 1.0, 1.0);
  viewer.addPolygonMesh(mesh, "mesh");
  pcl::PointCloud<pcl::PointXYZ> xyz, points;
  pcl::fromPCLPointCloud2(cloud, xyz);
  pcl::copyPointCloud(xyz, boundary, points);
  if (!points.empty()) {
    const auto ptr = points.makeShared();
    pcl::visualization::PointCloudColorHandlerCustom<pcl::PointXYZ> red(ptr, 200, 0, 0);
    viewer.addPointCloud<pcl::PointXYZ>(ptr, red, "boundary");
    viewer.setPointCloudRenderingProperties(
        pcl::visualization::PCL_VISUALIZER_POINT_SIZE, 4, "boundary");
  }
  // An oblique view from above, the whole cloud in the frame.
  Eigen::Vector4f lo, hi;
  pcl::getMinMax3D(xyz, lo, hi);
  const Eigen::Vector3f centre = 0.5f * (lo + hi).head<3>();
  const float size = (hi - lo).head<3>().norm();
  const Eigen::Vector3f eye =
      centre + 2.0f * size * Eigen::Vector3f(0.5f, -0.8f, 0.9f).normalized();
  viewer.setCameraPosition(
      eye.x(), eye.y(), eye.z(), centre.x(), centre.y(), centre.z(), 0.0, 0.0, 1.0);
  viewer.spinOnce(1, true);
  viewer.saveScreenshot(png);
  std::ifstream f(png, std::ios::binary);
  if (!f.good() || f.peek() == std::ifstream::traits_type::eof()) {
    error = "cannot write screenshot '" + png + "'";
    return false;
  }
  return true;
}

void
reexecUnderXvfb(int argc, char** argv)
{
  std::vector<char*> args;
  std::string screen = "-screen 0 1280x1024x24";
  args.push_back(const_cast<char*>("xvfb-run"));
  args.push_back(const_cast<char*>("-a"));
  args.push_back(const_cast<char*>("-s"));
  args.push_back(screen.data());
  // The running binary itself, whatever path it was started by.
  char self[4096];
  const ssize_t len = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (len > 0) {
    self[len] = '\0';
    args.push_back(self);
  }
  else
    args.push_back(argv[0]);
  for (int i = 1; i < argc; ++i)
    args.push_back(argv[i]);
  args.push_back(nullptr);
  ::setenv("COCONE_UNDER_XVFB", "1", 1);
  ::execvp("xvfb-run", args.data());
  std::fprintf(stderr,
               "Error: -screenshot needs a display or xvfb-run (package xvfb)\n");
  std::exit(1);
}

} // namespace cocone_app
