/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/triangulation.h>
#include <pcl/surface/cocone/voronoi_cell.h>

#include <gtest/gtest.h>

#include <support/surfaces.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace pcl::cocone;

namespace {

const double COS_COCONE = std::cos(3.0 * M_PI / 8.0);
const Eigen::Vector3d ORIGIN = Eigen::Vector3d::Zero();
const Eigen::Vector3d Z = Eigen::Vector3d::UnitZ();

double
angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  const double c = std::abs(a.normalized().dot(b.normalized()));
  return std::acos(std::min(1.0, c)) * 180.0 / M_PI;
}

} // namespace

TEST(IntersectCocone, SegmentInsideTheBand)
{
  const CoconeHit hit = intersectCocone(
      ORIGIN, Z, COS_COCONE, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), false);
  EXPECT_TRUE(hit.meets);
  EXPECT_NEAR(hit.max_distance, std::sqrt(2.0), 1e-12);
}

TEST(IntersectCocone, SegmentNearThePoleLineMisses)
{
  const CoconeHit hit = intersectCocone(ORIGIN,
                                        Z,
                                        COS_COCONE,
                                        Eigen::Vector3d(0, 0, 1),
                                        Eigen::Vector3d(0.1, 0, 0),
                                        false);
  EXPECT_FALSE(hit.meets);
  // The same segment below p: the co-cone is a double cone complement.
  EXPECT_FALSE(intersectCocone(ORIGIN,
                               Z,
                               COS_COCONE,
                               Eigen::Vector3d(0, 0, -1),
                               Eigen::Vector3d(0.1, 0, 0),
                               false)
                   .meets);
}

TEST(IntersectCocone, SegmentCrossingTheBandWithBothEndsOutside)
{
  // From (0.1, 0, 1) to (0.1, 0, -1): both ends are 5.7 degrees off the pole line,
  // far outside the co-cone, but the middle of the segment lies in it.
  const Eigen::Vector3d a(0.1, 0, 1), d(0, 0, -2);
  const double cot = std::cos(3.0 * M_PI / 8.0) / std::sin(3.0 * M_PI / 8.0);
  EXPECT_GT(std::abs(a.normalized().dot(Z)), COS_COCONE);
  EXPECT_GT(std::abs((a + d).normalized().dot(Z)), COS_COCONE);
  const CoconeHit hit = intersectCocone(ORIGIN, Z, COS_COCONE, a, d, false);
  EXPECT_TRUE(hit.meets);
  // Inside for |z| <= cot(3pi/8) * 0.1: the farthest point is where it leaves.
  const double z = 0.1 * cot;
  EXPECT_NEAR(hit.max_distance, std::sqrt(0.01 + z * z), 1e-12);
}

TEST(IntersectCocone, FarEndedSegmentFromItsNearEnd)
{
  // The Voronoi edge of a surface triangle between a cell inside (0.4 below p) and a
  // flat cell whose circumcenter lies 39,000 above: it passes 0.001 beside p, through
  // the co-cone for a few ten-thousandths. Followed from its near end (as the
  // co-cone pass does), the crossing is found; from the far end (measured: missed),
  // the quadratic's discriminant is a difference of terms 1e15 times its own size.
  const Eigen::Vector3d near(1e-3, 0, -0.4), far(6e-3, 0, 39000.0);
  const CoconeHit hit = intersectCocone(ORIGIN, Z, COS_COCONE, near, far - near, false);
  EXPECT_TRUE(hit.meets);
  EXPECT_GT(hit.max_distance, 1e-3);
  EXPECT_LT(hit.max_distance, 1.2e-3);
}

TEST(IntersectCocone, SegmentEndingInsideTheBand)
{
  const CoconeHit hit = intersectCocone(ORIGIN,
                                        Z,
                                        COS_COCONE,
                                        Eigen::Vector3d(0, 0, 1),
                                        Eigen::Vector3d(2, 0, -1),
                                        false);
  EXPECT_TRUE(hit.meets);
  EXPECT_NEAR(hit.max_distance, 2.0, 1e-12); // the end point (2, 0, 0)
}

TEST(IntersectCocone, SegmentAwayFromP)
{
  // Off-centre p and a segment that stays in the pole's double cone.
  const Eigen::Vector3d p(5, 5, 5);
  EXPECT_FALSE(intersectCocone(p,
                               Z,
                               COS_COCONE,
                               p + Eigen::Vector3d(0.2, 0, 3),
                               Eigen::Vector3d(0, 0.2, 3),
                               false)
                   .meets);
}

TEST(IntersectCocone, RayLeavingTheBand)
{
  // Starts in the band and runs along the pole: bounded part inside.
  const CoconeHit hit = intersectCocone(
      ORIGIN, Z, COS_COCONE, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1), true);
  EXPECT_TRUE(hit.meets);
  const double cot = std::cos(3.0 * M_PI / 8.0) / std::sin(3.0 * M_PI / 8.0);
  EXPECT_NEAR(hit.max_distance, std::sqrt(1.0 + cot * cot), 1e-12);
}

TEST(IntersectCocone, RayEnteringTheBandIsUnbounded)
{
  // Starts near the pole line but runs sideways: the far part lies in the co-cone.
  const CoconeHit hit = intersectCocone(
      ORIGIN, Z, COS_COCONE, Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0), true);
  EXPECT_TRUE(hit.meets);
  EXPECT_TRUE(std::isinf(hit.max_distance));
}

TEST(IntersectCocone, RayAlongThePoleMisses)
{
  EXPECT_FALSE(intersectCocone(ORIGIN,
                               Z,
                               COS_COCONE,
                               Eigen::Vector3d(0.1, 0, 1),
                               Eigen::Vector3d(0, 0, 1),
                               true)
                   .meets);
}

TEST(IntersectCocone, RayCrossingTheBandThenLeaving)
{
  // Neither the start nor the direction is in the co-cone, yet the ray crosses it.
  const Eigen::Vector3d a(0.1, 0, 1), d(0, 0.05, -1);
  EXPECT_GT(std::abs(a.normalized().dot(Z)), COS_COCONE);
  EXPECT_GT(std::abs(d.normalized().dot(Z)), COS_COCONE);
  const CoconeHit hit = intersectCocone(ORIGIN, Z, COS_COCONE, a, d, true);
  EXPECT_TRUE(hit.meets);
  EXPECT_TRUE(std::isfinite(hit.max_distance));
  EXPECT_LT(hit.max_distance, 0.2);
}

TEST(VoronoiCells, PolesFollowTheSphereNormal)
{
  cocone_test::SampleOptions o;
  o.n = 4000;
  o.even = false; // random samples: the Delaunay triangulation is not degenerate
  const auto s = cocone_test::sphere(o);
  const auto unique = makeUniquePoints(s.points);
  const Triangulation dt = triangulate(unique.points);
  const VoronoiCells vc = computeVoronoiCells(dt, 3.0 * M_PI / 8.0);
  ASSERT_EQ(vc.pole.size(), unique.points.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const int v = unique.vertex_of_input[i];
    worst = std::max(worst, angleDeg(vc.pole[v], s.normals[i]));
    // Every point of a sphere sample is on the convex hull.
    EXPECT_TRUE(vc.on_hull[v]);
    EXPECT_TRUE(std::isinf(vc.height_plus[v]));
  }
  EXPECT_LT(worst, 3.0);
}

TEST(VoronoiCells, PolesFollowTheTorusNormal)
{
  // Inside the torus hole and on its inner side the points are not on the hull:
  // there the positive pole is a finite Voronoi vertex.
  cocone_test::SampleOptions o;
  o.n = 6000;
  const auto s = cocone_test::torus(o);
  const auto unique = makeUniquePoints(s.points);
  const VoronoiCells vc =
      computeVoronoiCells(triangulate(unique.points), 3.0 * M_PI / 8.0);
  double worst = 0.0;
  std::size_t inner = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const int v = unique.vertex_of_input[i];
    worst = std::max(worst, angleDeg(vc.pole[v], s.normals[i]));
    inner += !vc.on_hull[v];
  }
  EXPECT_GT(inner, s.points.size() / 3);
  EXPECT_LT(worst, 5.0);
}

TEST(VoronoiCells, PolesFollowACurvedSheetNormal)
{
  cocone_test::SampleOptions o;
  o.n = 5000;
  const auto s = cocone_test::curvedSheet(o);
  const auto unique = makeUniquePoints(s.points);
  const VoronoiCells vc =
      computeVoronoiCells(triangulate(unique.points), 3.0 * M_PI / 8.0);
  double worst = 0.0;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (!s.near_boundary[i])
      worst =
          std::max(worst, angleDeg(vc.pole[unique.vertex_of_input[i]], s.normals[i]));
  EXPECT_LT(worst, 5.0);
}

TEST(VoronoiCells, HullPolesOfATetrahedronPointAway)
{
  // A regular tetrahedron with a point at its centre: each corner's Voronoi cell is
  // unbounded, and its pole is the sum of the three hull facet normals, i.e. the
  // direction from the centre to the corner.
  std::vector<Eigen::Vector3d> P{
      {1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}, {0, 0, 0}};
  const auto unique = makeUniquePoints(P);
  const Triangulation dt = triangulate(unique.points);
  ASSERT_EQ(dt.dimension, 3);
  ASSERT_EQ(dt.number_of_cells, 4u);
  const VoronoiCells vc = computeVoronoiCells(dt, 3.0 * M_PI / 8.0);
  for (int i = 0; i < 4; ++i) {
    const int v = unique.vertex_of_input[i];
    EXPECT_TRUE(vc.on_hull[v]);
    EXPECT_NEAR(vc.pole[v].dot(P[i].normalized()), 1.0, 1e-12);
    EXPECT_TRUE(std::isinf(vc.height_plus[v]));
  }
  const int centre = unique.vertex_of_input[4];
  EXPECT_FALSE(vc.on_hull[centre]);
  EXPECT_TRUE(std::isfinite(vc.height_plus[centre]));
}

TEST(VoronoiCells, PlanarPointsHaveNormalPoles)
{
  // A flat grid: poles along the plane normal at infinity, width finite inside.
  std::vector<Eigen::Vector3d> P;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      P.emplace_back(i + 0.01 * j * j, j, 2.0);
  const auto unique = makeUniquePoints(P);
  const Triangulation dt = triangulate(unique.points);
  ASSERT_EQ(dt.dimension, 2);
  const VoronoiCells vc = computeVoronoiCells(dt, 3.0 * M_PI / 8.0);
  for (std::size_t v = 0; v < unique.points.size(); ++v) {
    EXPECT_NEAR(std::abs(vc.pole[v].z()), 1.0, 1e-12);
    EXPECT_TRUE(std::isinf(vc.height(v)));
  }
  EXPECT_FALSE(vc.triangles.empty());
}

TEST(VoronoiCells, NearestDelaunayNeighbours)
{
  for (const bool planar : {false, true}) {
    std::vector<Eigen::Vector3d> P;
    for (int i = 0; i < 300; ++i) // a deterministic scatter
      P.emplace_back(
          std::sin(i * 1.7), std::cos(i * 2.3), planar ? 0.0 : std::sin(i * 0.9));
    const Triangulation dt = triangulate(makeUniquePoints(P).points);
    ASSERT_EQ(dt.dimension, planar ? 2 : 3);
    // The Delaunay neighbours from the cells' edges.
    std::vector<std::vector<int>> around(dt.points.size());
    forEachCell(dt, 0, 1, [&](const CellView& c, int) {
      for (int i = 0; i < c.corners; ++i)
        for (int j = 0; j < c.corners; ++j)
          if (i != j)
            around[c.v[i]].push_back(c.v[j]);
    });
    for (const unsigned int threads : {1u, 2u}) {
      const VoronoiCells vc = computeVoronoiCells(dt, 3.0 * M_PI / 8.0, threads);
      ASSERT_EQ(vc.nearest.size(), dt.points.size());
      for (std::size_t v = 0; v < dt.points.size(); ++v) {
        std::vector<int> e = around[v];
        std::sort(e.begin(), e.end());
        e.erase(std::unique(e.begin(), e.end()), e.end());
        const auto d2 = [&](int w) {
          return static_cast<float>((dt.points[w] - dt.points[v]).squaredNorm());
        };
        std::stable_sort(
            e.begin(), e.end(), [&](int a, int b) { return d2(a) < d2(b); });
        e.resize(VoronoiCells::NEAREST, -1);
        const std::vector<int> kept(vc.nearest[v].begin(), vc.nearest[v].end());
        EXPECT_EQ(kept, e) << "vertex " << v << (planar ? " (planar)" : "");
      }
    }
  }
}
