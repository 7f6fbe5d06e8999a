/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The default (automatic) mode on holed, noisy, uneven and anisotropic samples.
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>

#include <gtest/gtest.h>

#include <support/cases.h>
#include <support/metrics.h>
#include <support/surfaces.h>

#include <cstdio>

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
