/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Degenerate geometry and hostile input through the PCL class.
 */

#include <pcl/common/point_tests.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone_boundary.h>
#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <support/surfaces.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <memory>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

struct Output {
  std::vector<pcl::cocone::Triangle> polygons;
  std::vector<int> boundary;
  std::size_t loops = 0;
  pcl::cocone::MeshTopology topology;
};

Output
reconstruct(const Cloud::Ptr& cloud)
{
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  Output out;
  for (const auto& p : mesh.polygons) {
    EXPECT_EQ(p.vertices.size(), 3u);
    out.polygons.push_back({p.vertices[0], p.vertices[1], p.vertices[2]});
  }
  pcl::PointIndices b;
  cocone.getBoundaryPointIndices(b);
  out.boundary = b.indices;
  std::vector<pcl::Vertices> loops;
  cocone.getBoundaryLoops(loops);
  out.loops = loops.size();
  out.topology = pcl::cocone::analyzeMesh(out.polygons, cloud->size());
  EXPECT_TRUE(out.topology.manifold());
  for (const auto& t : out.polygons)
    for (const int v : t)
      EXPECT_TRUE(pcl::isFinite((*cloud)[v])) << "a polygon uses a skipped point";
  return out;
}

Cloud::Ptr
toCloud(const std::vector<Eigen::Vector3d>& points,
        double scale = 1.0,
        const Eigen::Vector3d& offset = Eigen::Vector3d::Zero())
{
  Cloud::Ptr cloud(new Cloud);
  for (const auto& p : points) {
    const Eigen::Vector3d q = scale * p + offset;
    cloud->push_back(pcl::PointXYZ(float(q.x()), float(q.y()), float(q.z())));
  }
  return cloud;
}

cocone_test::Sample
hemisphere(std::size_t n = 3000)
{
  cocone_test::SampleOptions o;
  o.n = n;
  auto s = cocone_test::hemisphere(o);
  // Snap to a 2^-9 grid: the points then stay exact in float after scaling by
  // powers of two or offsetting by 10^4 (14 + 9 bits).
  for (auto& p : s.points)
    for (int k = 0; k < 3; ++k)
      p[k] = std::round(p[k] * 512.0) / 512.0;
  return s;
}

} // namespace

TEST(Robustness, ScaleInvariance)
{
  // Exact predicates and power-of-two scales: the same mesh and boundary at 1e-6 and
  // 1e6 as at 1.
  const auto s = hemisphere();
  const Output ref = reconstruct(toCloud(s.points));
  ASSERT_GT(ref.polygons.size(), 5000u);
  EXPECT_EQ(ref.loops, 1u);
  for (const double scale : {std::ldexp(1.0, -20), std::ldexp(1.0, 20)}) {
    const Output o = reconstruct(toCloud(s.points, scale));
    EXPECT_EQ(o.polygons, ref.polygons) << "scale " << scale;
    EXPECT_EQ(o.boundary, ref.boundary) << "scale " << scale;
  }
}

TEST(Robustness, OffsetCloudGivesTheResultAtTheOrigin)
{
  // The library recentres in double before triangulating.
  const auto s = hemisphere();
  const Output ref = reconstruct(toCloud(s.points));
  const Output o = reconstruct(toCloud(s.points, 1.0, Eigen::Vector3d(1e4, -1e4, 1e4)));
  EXPECT_EQ(o.polygons, ref.polygons);
  EXPECT_EQ(o.boundary, ref.boundary);
}

TEST(Robustness, CoSphericalPoints)
{
  // Every point on one sphere: every Delaunay cell is degenerate.
  std::vector<Eigen::Vector3d> pts;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z);
    pts.emplace_back(
        r * std::cos(i * 2.399963229728653), r * std::sin(i * 2.399963229728653), z);
  }
  const Output o = reconstruct(toCloud(pts));
  EXPECT_EQ(o.topology.euler, 2);
  EXPECT_EQ(o.topology.boundary_edges, 0u);
  EXPECT_EQ(o.topology.vertices, std::size_t(n));
}

TEST(Robustness, IntegerLattice)
{
  // The surface of a 12 x 12 x 12 cube sampled on the integer lattice: co-spherical
  // and coplanar quadruples everywhere, sharp edges and corners.
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i <= 12; ++i)
    for (int j = 0; j <= 12; ++j)
      for (int k = 0; k <= 12; ++k)
        if (i == 0 || j == 0 || k == 0 || i == 12 || j == 12 || k == 12)
          pts.emplace_back(i, j, k);
  const Output o = reconstruct(toCloud(pts));
  EXPECT_GT(o.polygons.size(), pts.size()); // most of the cube is meshed
  // A full 3D lattice block (no surface at all) must not crash either.
  std::vector<Eigen::Vector3d> block;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 8; ++k)
        block.emplace_back(i, j, k);
  reconstruct(toCloud(block));
}

TEST(Robustness, OutliersDoNotDestroyTheMesh)
{
  const auto s = hemisphere();
  auto cloud = toCloud(s.points);
  // 20 points far off the surface, up to 10 radii away.
  for (int i = 0; i < 20; ++i)
    cloud->push_back(pcl::PointXYZ(float(10.0 * std::sin(i * 1.3)),
                                   float(10.0 * std::cos(i * 2.1)),
                                   float(5.0 + 5.0 * std::sin(i * 0.7))));
  const Output o = reconstruct(cloud);
  std::vector<char> used(cloud->size(), 0);
  for (const auto& t : o.polygons)
    for (const int v : t)
      used[v] = 1;
  std::size_t surface_used = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    surface_used += used[i];
  EXPECT_GE(surface_used, s.points.size() * 99 / 100);
  EXPECT_EQ(o.loops, 1u);
}

TEST(Robustness, OrganizedCloudWithHoles)
{
  // A range-image-like organized cloud: a height field on a 60 x 50 grid with NaN
  // pixels (sensor drop-outs).
  Cloud::Ptr cloud(new Cloud(60, 50));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int r = 0; r < 50; ++r)
    for (int c = 0; c < 60; ++c) {
      const float x = c * 0.02f, y = r * 0.02f;
      const bool dropout = (r * 7 + c * 13) % 23 == 0;
      (*cloud)(c, r) = dropout ? pcl::PointXYZ(nan, nan, nan)
                               : pcl::PointXYZ(x, y, 0.3f * x * x - 0.2f * y * y);
    }
  cloud->is_dense = false;
  const Output o = reconstruct(cloud);
  EXPECT_GT(o.polygons.size(), 4000u);
  for (const int i : o.boundary)
    EXPECT_TRUE(pcl::isFinite((*cloud)[i]));
}

TEST(Robustness, NearDuplicates)
{
  // Every point twice, the copy 1e-9 away: tiny Delaunay edges everywhere.
  const auto s = hemisphere(2000);
  std::vector<Eigen::Vector3d> pts = s.points;
  for (const auto& p : s.points)
    pts.push_back(p + Eigen::Vector3d(1e-9, -1e-9, 1e-9));
  std::vector<pcl::cocone::Triangle> none;
  pcl::cocone::Parameters parameters;
  const auto r = pcl::cocone::run(pts, parameters, pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_TRUE(r.error.empty());
  EXPECT_TRUE(pcl::cocone::analyzeMesh(r.triangles, r.vertices).manifold());
  EXPECT_GT(r.triangles.size(), s.points.size());
}

#if defined(__SANITIZE_ADDRESS__)
#define COCONE_TEST_UNDER_ASAN
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define COCONE_TEST_UNDER_ASAN
#endif
#endif
#ifndef COCONE_TEST_UNDER_ASAN
TEST(Robustness, OutOfMemoryIsAnErrorNotATermination)
{
  // Cap the address space a little above what the process holds: the pipeline's
  // allocations fail, and it reports it instead of terminating. (Not under
  // AddressSanitizer, which reserves terabytes of address space.)
  cocone_test::SampleOptions o;
  o.n = 100000;
  o.even = false;
  const auto s = cocone_test::torus(o);
  auto cloud = std::make_shared<Cloud>();
  for (const auto& p : s.points)
    cloud->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  pcl::PolygonMesh mesh;

  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  statm >> pages;
  ASSERT_GT(pages, 0u);
  rlimit old;
  ASSERT_EQ(::getrlimit(RLIMIT_AS, &old), 0);
  rlimit capped = old;
  capped.rlim_cur = pages * ::sysconf(_SC_PAGESIZE) + (32u << 20);
  ASSERT_EQ(::setrlimit(RLIMIT_AS, &capped), 0);
  cocone.reconstruct(mesh);
  ASSERT_EQ(::setrlimit(RLIMIT_AS, &old), 0);

  EXPECT_TRUE(mesh.polygons.empty());
  pcl::PointIndices boundary;
  cocone.getBoundaryPointIndices(boundary);
  EXPECT_TRUE(boundary.indices.empty());
  // With the memory back, the same object succeeds.
  cocone.reconstruct(mesh);
  EXPECT_GT(mesh.polygons.size(), 190000u);
}
#endif
