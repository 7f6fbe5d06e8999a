/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * libFuzzer target: the whole pipeline on small point sets built to be degenerate.
 * The first byte picks a construction; the rest are coordinates on a coarse grid, so
 * co-spherical, coplanar, collinear and repeated points are the rule, not the
 * exception. Every result must be an error or a valid oriented manifold whose
 * indices refer to the input.
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  if (size < 2)
    return 0;
  const std::uint8_t mode = data[0];
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 1; i + 2 < size && points.size() < 400; i += 3) {
    Eigen::Vector3d p(static_cast<std::int8_t>(data[i]) / 8.0,
                      static_cast<std::int8_t>(data[i + 1]) / 8.0,
                      static_cast<std::int8_t>(data[i + 2]) / 8.0);
    switch (mode % 8) {
    case 1:
      p.z() = 0.0; // coplanar
      break;
    case 2:
      p.y() = p.z() = p.x(); // collinear
      break;
    case 3:
      if (p.norm() > 0.0)
        p.normalize(); // co-spherical
      break;
    case 4:
      p *= std::ldexp(1.0, mode / 8 - 16); // tiny to huge scales
      break;
    case 5:
      if ((data[i] & 7) == 0)
        p.x() = std::numeric_limits<double>::quiet_NaN();
      break;
    default:
      break;
    }
    points.push_back(p);
    if (mode % 8 == 6)
      points.push_back(p); // every point twice
  }
  pcl::cocone::Parameters parameters;
  if (mode & 0x80) {
    parameters.ratio = 1.5;
    parameters.spacing_factor = 0.0;
  }
  parameters.boundary_detection = (mode & 0x40) == 0;
  const auto r =
      pcl::cocone::run(points, parameters, pcl::cocone::Stages::RECONSTRUCTION);
  if (!r.error.empty())
    return 0;
  const auto topology = pcl::cocone::analyzeMesh(r.triangles, r.vertices);
  if (!topology.manifold())
    std::abort();
  for (const auto& t : r.polygons)
    for (const int v : t)
      if (v < 0 || v >= static_cast<int>(points.size()) ||
          !std::isfinite(points[v].x()))
        std::abort();
  for (const int i : r.boundary_indices)
    if (i < 0 || i >= static_cast<int>(points.size()))
      std::abort();
  return 0;
}
