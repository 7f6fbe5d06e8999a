/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * cocone_scan_eval: score border detection on range scans against the scans' own
 * truth. A range image's grid is the scanned surface's mesh: neighbouring valid
 * pixels whose 3D edges are short form triangles, and that mesh's borders (outline
 * and occlusion holes) are the truth. Each scan is then treated as an unorganized
 * cloud and given to
 *  - this library at its default, without the hole filling, without it and the
 *    noise handling, with a hole width of 1.5 (range views), and with the paper's
 *    test (no spacing and no half-disk test) at rho = 1.5 and at rho = 2.5;
 *  - pcl::BoundaryEstimation (normals from 20 neighbours, 20 neighbours, pi/2);
 *  - pcl::GreedyProjectionTriangulation (the borders of its mesh).
 *
 *   cocone_scan_eval SCAN.ply [SCAN.ply ...]
 *
 * A reported border point is correct if a true border point lies within 2 median
 * grid spacings; a true border point is found if a reported one lies that close.
 * Holes of the grid with at most 8 border vertices (a pixel or two missing) are below
 * the sampling resolution and do not count.
 */

#include <pcl/common/point_tests.h>
#include <pcl/io/ply_io.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone_boundary.h>
#include <pcl/point_types.h>

#include "border_truth.h"
#include "peer_methods.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

using cocone_app::BorderScore;
using cocone_app::BorderTruth;

double
since(std::chrono::steady_clock::time_point t)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void
report(const char* method,
       const BorderScore& s,
       std::size_t loops,
       std::size_t points,
       double sec)
{
  std::printf("  %-28s border F1 %.2f (precision %.2f recall %.2f)  loops %5zu  "
              "points %6zu  %.2f s\n",
              method,
              s.f1,
              s.precision,
              s.recall,
              loops,
              points,
              sec);
}

void
runCocone(const Cloud::Ptr& cloud,
          const BorderTruth& truth,
          const char* name,
          double ratio,
          double spacing_factor,
          double gap_angle,
          bool fill = true,
          bool denoise = true,
          double hole_width = pcl::cocone::Parameters().hole_width)
{
  const auto t = std::chrono::steady_clock::now();
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  cocone.setRatio(ratio);
  cocone.setSpacingFactor(spacing_factor);
  cocone.setGapAngle(gap_angle);
  cocone.setFillUndersampledHoles(fill);
  cocone.setNoiseHandling(denoise);
  cocone.setMaxHoleWidth(hole_width);
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  const double sec = since(t);
  std::vector<pcl::Vertices> loops;
  cocone.getBoundaryLoops(loops);
  std::vector<pcl::cocone::Triangle> triangles;
  for (const auto& p : mesh.polygons)
    triangles.push_back({int(p.vertices[0]), int(p.vertices[1]), int(p.vertices[2])});
  const std::vector<int> border = pcl::cocone::borderVertices(triangles);
  pcl::PointIndices undersampled;
  cocone.getBoundaryPointIndices(undersampled);
  char label[64];
  std::snprintf(
      label, sizeof(label), "%s (rho %.2f) borders", name, cocone.getUsedRatio());
  report(label,
         cocone_app::scoreBorder(*cloud, border, truth),
         loops.size(),
         border.size(),
         sec);
  std::snprintf(label, sizeof(label), "%s undersampled", name);
  report(label,
         cocone_app::scoreBorder(*cloud, undersampled.indices, truth),
         0,
         undersampled.indices.size(),
         sec);
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCAN.ply [SCAN.ply ...]\n", argv[0]);
    return 1;
  }
  for (int a = 1; a < argc; ++a) {
    Cloud organized;
    if (pcl::io::loadPLYFile(argv[a], organized) < 0 || !organized.isOrganized()) {
      std::fprintf(stderr, "%s: not a range grid\n", argv[a]);
      continue;
    }
    Cloud::Ptr cloud(new Cloud);
    std::vector<int> compact_of(organized.size(), -1);
    for (std::size_t i = 0; i < organized.size(); ++i)
      if (pcl::isFinite(organized[i])) {
        compact_of[i] = static_cast<int>(cloud->size());
        cloud->push_back(organized[i]);
      }
    const BorderTruth truth = cocone_app::gridBorderTruth(organized, compact_of);
    std::printf(
        "%s: %zu points, truth: %zu border points on %zu loops (spacing %.5f)\n",
        argv[a],
        cloud->size(),
        truth.border.size(),
        truth.loops,
        truth.spacing);

    const pcl::cocone::Parameters defaults;
    runCocone(cloud, truth, "cocone default", 0.0, 3.0, defaults.gap_angle);
    // What the hole filling and the smoothing each change on a scan.
    runCocone(cloud, truth, "no fill", 0.0, 3.0, defaults.gap_angle, false);
    runCocone(
        cloud, truth, "no fill/denoise", 0.0, 3.0, defaults.gap_angle, false, false);
    // A single range view's dropouts are where the sensor got no return: the setting
    // for them keeps every empty hole wider than 1.5 rim triangles open.
    runCocone(
        cloud, truth, "hole width 1.5", 0.0, 3.0, defaults.gap_angle, true, true, 1.5);
    runCocone(cloud, truth, "cocone paper", 1.5, 0.0, 0.0);
    runCocone(cloud, truth, "cocone paper", 2.5, 0.0, 0.0);

    // pcl::BoundaryEstimation with estimated normals.
    auto t = std::chrono::steady_clock::now();
    cocone_app::Tree::Ptr tree(new cocone_app::Tree);
    const auto normals = cocone_app::estimateNormals(cloud, tree);
    const std::vector<int> flagged =
        cocone_app::boundaryEstimation(cloud, normals, tree);
    report("BoundaryEstimation points",
           cocone_app::scoreBorder(*cloud, flagged, truth),
           0,
           flagged.size(),
           since(t));

    // Greedy projection: the borders of its mesh.
    t = std::chrono::steady_clock::now();
    const auto triangles =
        cocone_app::greedyProjection(cloud, normals, 6.0 * truth.spacing);
    const std::vector<int> border = pcl::cocone::borderVertices(triangles);
    report("GP3 (k=20 normals) borders",
           cocone_app::scoreBorder(*cloud, border, truth),
           pcl::cocone::boundaryLoops(triangles, cloud->size()).size(),
           border.size(),
           since(t));
  }
  return 0;
}
