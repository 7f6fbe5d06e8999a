/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * libFuzzer target: the tool's file readers on arbitrary bytes. The first byte picks
 * the format; the rest is the file. Reading may fail, but must fail cleanly.
 */

#include <pcl/console/print.h>

#include "../apps/cloud_io.h"
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  if (size < 1)
    return 0;
  static const char* extensions[] = {"pcd", "ply", "obj", "xyz", "off"};
  const std::string path =
      "/tmp/cocone_fuzz_" + std::to_string(::getpid()) + "." + extensions[data[0] % 5];
  {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(data + 1),
            static_cast<std::streamsize>(size - 1));
  }
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  pcl::PCLPointCloud2 cloud;
  std::string error;
  if (cocone_app::readCloud(path, cloud, error)) {
    std::vector<Eigen::Vector3d> xyz;
    cocone_app::extractXYZ(cloud, xyz, error);
  }
  std::remove(path.c_str());
  return 0;
}
