/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The default (automatic) mode on holed, slit, noisy, uneven and anisotropic samples.
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>

#include <gtest/gtest.h>

#include <support/cases.h>
#include <support/metrics.h>
#include <support/surfaces.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using cocone_test::options;
using cocone_test::Sample;
using cocone_test::SampleOptions;

namespace {

struct Outcome {
  pcl::cocone::Result result;
  cocone_test::MeshScore mesh;
  cocone_test::BoundaryScore boundary;
};

Outcome
reconstruct(const Sample& s, const char* tag)
{
  Outcome o;
  o.result = pcl::cocone::run(
      s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  EXPECT_TRUE(o.result.error.empty()) << o.result.error;
  o.mesh = cocone_test::scoreMesh(s, o.result);
  o.boundary = cocone_test::scoreBoundary(s, o.result.boundary_indices);
  std::printf("[ measured ] %-18s %-14s rho %.2f: %s; boundary %s\n",
              s.name.c_str(),
              tag,
              o.result.ratio,
              o.mesh.str().c_str(),
              o.boundary.str().c_str());
  EXPECT_TRUE(o.mesh.topology.manifold()) << s.name << " " << tag;
  return o;
}

/** Exact topology and a good border. */
void
expectExact(const Sample& s, const Outcome& o, double max_distance = 1.0)
{
  EXPECT_EQ(o.mesh.loops, std::size_t(s.boundary_loops)) << s.name;
  EXPECT_EQ(o.mesh.topology.euler, s.euler) << s.name;
  EXPECT_EQ(o.mesh.topology.components, std::size_t(s.components)) << s.name;
  EXPECT_LT(o.mesh.max_distance, max_distance) << s.name;
  EXPECT_GE(o.boundary.recall, 0.95) << s.name;
  EXPECT_GE(o.boundary.precision, 0.90) << s.name;
}

} // namespace

TEST(AutomaticMode, HoledSpheres)
{
  for (const double degrees : {30.0, 15.0}) {
    const double angle = degrees * M_PI / 180.0;
    const auto clean = cocone_test::sphereWithHoles(options(10000), 3, angle);
    expectExact(clean, reconstruct(clean, "clean"));
    const auto uneven =
        cocone_test::sphereWithHoles(options(10000, 0.0, 4.0), 3, angle);
    expectExact(uneven, reconstruct(uneven, "density 1:4"));
    const auto noisy = cocone_test::sphereWithHoles(options(10000, 0.05), 3, angle);
    expectExact(noisy, reconstruct(noisy, "noise 5 %"));
  }
}

TEST(AutomaticMode, NoisyHemisphereIsExact)
{
  const auto s = cocone_test::hemisphere(options(10000, 0.05));
  expectExact(s, reconstruct(s, "noise 5 %"));
}

TEST(AutomaticMode, NoisyClosedSurfaces)
{
  // Noise of 15 % of the spacing: at most 2 spurious border loops.
  for (const auto& s : {cocone_test::torus(options(10000, 0.15)),
                        cocone_test::sphere(options(10000, 0.15)),
                        cocone_test::sphereWithHoles(options(10000, 0.15), 3, 0.5)}) {
    const Outcome o = reconstruct(s, "noise 15 %");
    EXPECT_LE(o.mesh.loops, std::size_t(s.boundary_loops) + 2) << s.name;
    EXPECT_GE(o.mesh.loops, std::size_t(s.boundary_loops)) << s.name;
    EXPECT_GE(o.mesh.used_share, 0.99) << s.name;
  }
}

TEST(AutomaticMode, AnisotropicSampling)
{
  // Scan lines three spacings apart (1:3 along and across), evenly and unevenly.
  for (const double ratio : {1.0, 4.0}) {
    const auto s = cocone_test::scanLineSheet(options(10000, 0.0, ratio));
    expectExact(s, reconstruct(s, ratio > 1.0 ? "density 1:4" : "clean"));
  }
}

TEST(AutomaticMode, NarrowSlit)
{
  // A slit three spacings wide and 0.8 long cut out of the curved sheet. A rim
  // point's Voronoi cell ends halfway across the slit, no wider than inside the
  // sheet: the ratio and spacing tests pass it and the slit is covered. Seen along
  // its pole line the rim point has its neighbours on one side: the half-disk test.
  const auto sheet = cocone_test::curvedSheet(options(10000));
  const double half = 1.5 * sheet.spacing, length = 0.4;
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : sheet.points)
    if (!(std::abs(p.y()) < half && std::abs(p.x()) < length))
      points.push_back(p);
  std::vector<int> rim; // within 0.7 spacings of a long side of the slit
  for (std::size_t i = 0; i < points.size(); ++i)
    if (std::abs(points[i].x()) < length - sheet.spacing &&
        std::abs(points[i].y()) < half + 0.7 * sheet.spacing)
      rim.push_back(static_cast<int>(i));

  const auto run = [&](double gap_angle) {
    pcl::cocone::Parameters parameters;
    parameters.gap_angle = gap_angle;
    return pcl::cocone::run(points, parameters, pcl::cocone::Stages::RECONSTRUCTION);
  };
  const pcl::cocone::Result result = run(pcl::cocone::Parameters().gap_angle);
  const auto topology = pcl::cocone::analyzeMesh(result.triangles, result.vertices);
  std::size_t found = 0;
  for (const int i : rim)
    found += std::binary_search(
        result.boundary_indices.begin(), result.boundary_indices.end(), i);
  std::printf("[ measured ] curved sheet, slit of 3 spacings: loops %zu euler %ld "
              "components %zu; slit rim points reported %zu of %zu\n",
              result.border_loops.size(),
              topology.euler,
              topology.components,
              found,
              rim.size());
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(result.border_loops.size(), 2u);
  EXPECT_EQ(topology.euler, 0);
  EXPECT_EQ(topology.components, 1u);
  EXPECT_GE(double(found), 0.9 * double(rim.size()));
  // Without the half-disk test the slit is covered.
  const pcl::cocone::Result covered = run(0.0);
  EXPECT_EQ(covered.border_loops.size(), 1u);
}

TEST(AutomaticMode, RandomSamplesHaveNoRims)
{
  // Area-uniform random samples have voids of a few spacings everywhere: the
  // half-disk test raises its angle with the median gap and reports none of them.
  for (const auto& s : {cocone_test::sphere(options(8000, 0.0, 1.0, false)),
                        cocone_test::torus(options(10000, 0.0, 1.0, false))}) {
    const Outcome o = reconstruct(s, "random");
    EXPECT_EQ(o.mesh.loops, 0u) << s.name;
    EXPECT_EQ(o.result.boundary_indices.size(), 0u) << s.name;
  }
}
