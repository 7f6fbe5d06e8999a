/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/boundary.h>
#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/triangulation.h>
#include <pcl/surface/cocone/voronoi_cell.h>

#include <gtest/gtest.h>

#include "support/surfaces.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace pcl::cocone;

namespace {

Eigen::Vector3d
tilted(double degrees)
{
  const double a = degrees * M_PI / 180.0;
  return {std::sin(a), 0.0, std::cos(a)};
}

/** Four hand-made Voronoi cells: see the comments of each test. */
VoronoiCells
handMade()
{
  VoronoiCells vc;
  // v0: w 1, h 2, pole 0 deg  -> passes the ratio test at rho 1.5
  // v1: w 1, h 1, pole 0 deg  -> fails it
  // v2: w 1, h 2, pole 45 deg -> passes the ratio test
  // v3: w 1, h 2, pole 20 deg -> passes the ratio test
  vc.pole = {tilted(0), tilted(0), tilted(45), tilted(20)};
  vc.height_plus = {2, 1, 2, 2};
  vc.height_minus = {3, 3, 3, 3};
  vc.width = {1, 1, 1, 1};
  vc.on_hull = {0, 0, 0, 0};
  return vc;
}

} // namespace

TEST(DetectBoundary, RatioCondition)
{
  VoronoiCells vc = handMade();
  const BoundaryLabels l = detectBoundary(vc, {1.5, M_PI / 6});
  EXPECT_EQ(l.ratio_ok, (std::vector<std::uint8_t>{1, 0, 1, 1}));
  // No co-cone triangles: nothing constrains the normals.
  EXPECT_EQ(l.flat, (std::vector<std::uint8_t>{1, 0, 1, 1}));
  // rho 2.5 asks for h >= 2.5 w: nobody is flat.
  EXPECT_EQ(detectBoundary(vc, {2.5, M_PI / 6}).interior,
            (std::vector<std::uint8_t>{0, 0, 0, 0}));
  // Unbounded width never passes, even with an infinite height.
  vc.width[0] = std::numeric_limits<double>::infinity();
  vc.height_plus[0] = vc.height_minus[0] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(detectBoundary(vc, {1.5, M_PI / 6}).ratio_ok[0]);
}

TEST(DetectBoundary, NormalConditionAndGrowth)
{
  VoronoiCells vc = handMade();
  // The co-cone of v0 meets the dual edge of triangle (0, 2, 3): N_0 = {2, 3}.
  // v2's pole is 45 deg from v0's (> theta = 30 deg): v2 is not flat. v3 is 20 deg
  // off: flat.
  vc.triangles.push_back({{0, 2, 3}, 0b001});
  BoundaryLabels l = detectBoundary(vc, {1.5, M_PI / 6});
  EXPECT_EQ(l.flat, (std::vector<std::uint8_t>{1, 0, 0, 1}));
  EXPECT_EQ(l.interior, (std::vector<std::uint8_t>{1, 0, 0, 1}));

  // The co-cone of v3 meets the dual edge of (1, 2, 3): N_3 = {1, 2}. v2 is 25 deg
  // from v3 and passes the ratio test, so it joins R through v3; v1 fails the ratio
  // test and stays a boundary vertex.
  vc.triangles.push_back({{1, 2, 3}, 0b100});
  l = detectBoundary(vc, {1.5, M_PI / 6});
  EXPECT_EQ(l.flat, (std::vector<std::uint8_t>{1, 0, 0, 1}));
  EXPECT_EQ(l.interior, (std::vector<std::uint8_t>{1, 0, 1, 1}));

  // With theta = 20 deg the 25 deg step is too large: no growth.
  l = detectBoundary(vc, {1.5, 20.0 * M_PI / 180.0});
  EXPECT_EQ(l.interior, (std::vector<std::uint8_t>{1, 0, 0, 1}));
}

TEST(DetectBoundary, NormalConditionReadsTheDirection)
{
  // The same triangle, but now the co-cone of v2 meets its dual edge: N_2 = {0, 3},
  // so v0 and v3 are judged against v2 (45 and 25 deg): only v0 fails.
  VoronoiCells vc = handMade();
  vc.triangles.push_back({{0, 2, 3}, 0b010});
  const BoundaryLabels l = detectBoundary(vc, {1.5, M_PI / 6});
  EXPECT_EQ(l.flat, (std::vector<std::uint8_t>{0, 0, 1, 1}));
  // v0 passes the ratio test but cannot grow from v2 (45 deg): stays boundary.
  EXPECT_EQ(l.interior, (std::vector<std::uint8_t>{0, 0, 1, 1}));
}

TEST(DetectBoundary, PoleLinesNotVectors)
{
  // Opposite pole vectors are the same line: angle 0.
  VoronoiCells vc = handMade();
  vc.pole[3] = -tilted(0);
  vc.triangles.push_back({{0, 2, 3}, 0b001});
  EXPECT_TRUE(detectBoundary(vc, {1.5, M_PI / 6}).flat[3]);
}

TEST(DetectBoundary, SameLabelsWithSeveralThreads)
{
  // Enough co-cone triangles (about two a point) for the passes over them to run in
  // parts, and noise, so that the growth of R has points to take.
  cocone_test::SampleOptions o;
  o.n = 80000;
  o.even = false;
  o.noise = 0.15;
  o.seed = 3;
  const auto s = cocone_test::monkeySaddle(o);
  const Triangulation dt = triangulate(makeUniquePoints(s.points).points);
  const VoronoiCells cells = computeVoronoiCells(dt, 3.0 * M_PI / 8.0);
  ASSERT_GT(cells.triangles.size(), 2u * 65536u);
  const std::vector<double> spacing = localSpacing(dt.points, cells);
  const FlatnessParameters parameters{1.5, M_PI / 6, 3.0};
  const BoundaryLabels alone = detectBoundary(cells, parameters, spacing);
  const auto count = [](const std::vector<std::uint8_t>& x) {
    return std::count(x.begin(), x.end(), 1);
  };
  EXPECT_GT(count(alone.interior), count(alone.flat));                   // grown
  EXPECT_LT(count(alone.interior), static_cast<long>(dt.points.size())); // a border
  for (const int threads : {2, 3}) {
    EXPECT_EQ(localSpacing(dt.points, cells, threads), spacing) << threads;
    EXPECT_EQ(localSpacing(cells, meanSpacing(dt.points, cells, threads), threads),
              spacing)
        << threads;
    const BoundaryLabels l = detectBoundary(cells, parameters, spacing, threads);
    EXPECT_EQ(l.ratio_ok, alone.ratio_ok) << threads;
    EXPECT_EQ(l.flat, alone.flat) << threads;
    EXPECT_EQ(l.interior, alone.interior) << threads;
  }
}

TEST(LargestAngularGap, SameAsSortingTheAngles)
{
  // The gap found without sorting is one of the sorted angles' gaps, and the largest:
  // few angles (two share one extreme), ties, angles on a coarse grid.
  const auto sorted_gap = [](std::vector<double> a) {
    std::sort(a.begin(), a.end());
    double gap = a.front() + 2.0 * M_PI - a.back();
    for (std::size_t i = 1; i < a.size(); ++i)
      gap = std::max(gap, a[i] - a[i - 1]);
    return gap;
  };
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<double> a(2 + trial % 40);
    for (double& x : a)
      x = angle(random);
    if (trial % 3 == 0)
      for (double& x : a)
        x = std::round(x * 4.0) / 4.0;
    ASSERT_EQ(largestAngularGap(a), sorted_gap(a)) << a.size() << " angles";
  }
  EXPECT_EQ(largestAngularGap({0.5}), 2.0 * M_PI);
  EXPECT_DOUBLE_EQ(largestAngularGap({1.0, 1.0, 1.0}), 2.0 * M_PI);
  EXPECT_DOUBLE_EQ(largestAngularGap({-3.0, 3.0}), 6.0);
}

TEST(LargestAngularGap, DirectionsAsTheirAngles)
{
  // The gap of plane directions is that of their atan2 angles: random directions of
  // random lengths, few and many, repeated ones, directions on a coarse grid of
  // angles (exact ties, opposite pairs), zero vectors.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), length(1e-3, 1e3);
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<Eigen::Vector2d> d(2 + trial % 40);
    for (auto& x : d) {
      double a = angle(random);
      if (trial % 3 == 0)
        a = std::round(a * 4.0) / 4.0;
      x = length(random) * Eigen::Vector2d(std::cos(a), std::sin(a));
    }
    if (trial % 5 == 0)
      d[trial % d.size()] = d[0];
    if (trial % 7 == 0)
      d[trial % d.size()].setZero();
    std::vector<double> a;
    for (const auto& x : d)
      a.push_back(std::atan2(x.y(), x.x()));
    const double expected = largestAngularGap(a);
    ASSERT_NEAR(largestDirectionGap(d), expected, 1e-12 * (1.0 + expected))
        << d.size() << " directions";
  }
  std::vector<Eigen::Vector2d> one{{1.0, 2.0}};
  EXPECT_EQ(largestDirectionGap(one), 2.0 * M_PI);
  std::vector<Eigen::Vector2d> same{{1.0, 2.0}, {2.0, 4.0}, {0.5, 1.0}};
  EXPECT_EQ(largestDirectionGap(same), 2.0 * M_PI);
  std::vector<Eigen::Vector2d> opposite{{1.0, 0.0}, {-2.0, 0.0}};
  EXPECT_DOUBLE_EQ(largestDirectionGap(opposite), M_PI);
  std::vector<Eigen::Vector2d> narrow{{1.0, 1e-9}, {1.0, -1e-9}};
  EXPECT_NEAR(largestDirectionGap(narrow), 2.0 * M_PI - 2e-9, 1e-15);
}

TEST(HalfDiskTest, GridBorderAndInterior)
{
  // A 20 x 20 range-grid-like sheet, slightly curved so that the triangulation is
  // three-dimensional and the poles follow the normal (+z): the outermost rows and
  // columns have their neighbours on one side, the points inside all around.
  const int n = 20;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = i + 0.01 * std::sin(7.0 * i + 3.0 * j),
                   y = j + 0.01 * std::cos(5.0 * i + 11.0 * j);
      points.emplace_back(x, y, 0.002 * (x * x + y * y));
    }
  const UniquePoints unique = makeUniquePoints(points);
  const Triangulation dt = triangulate(unique.points);
  ASSERT_EQ(dt.dimension, 3);
  const VoronoiCells cells = computeVoronoiCells(dt, 3.0 * M_PI / 8.0);
  const HalfDisk h = halfDiskTest(
      dt.points, cells, localSpacing(dt.points, cells), 1.75, 80.0 * M_PI / 180.0, 2);
  std::size_t border = 0, border_rim = 0, inside_rim = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = unique.vertex_of_input[i * n + j];
      const bool outer = i == 0 || j == 0 || i == n - 1 || j == n - 1;
      border += outer;
      border_rim += outer && h.rim[v];
      inside_rim += !outer && h.rim[v];
      if (outer) { // a half plane, up to the jitter
        EXPECT_GT(h.gap[v], 0.95 * M_PI) << i << " " << j;
      }
    }
  EXPECT_EQ(border_rim, border);
  EXPECT_EQ(inside_rim, 0u);
  EXPECT_NEAR(h.angle, 80.0 * M_PI / 180.0, 1e-12);
}

TEST(HalfDiskTest, LargeCloudBorder)
{
  // Above 131,072 points the gap angle comes from a sample of the gaps and only the
  // points whose one-ring leaves a gap above it get their two-ring: the rim still
  // runs along the border of a hemisphere (at height 0), and does not depend on
  // the number of threads.
  cocone_test::SampleOptions o;
  o.n = 140000;
  o.even = false;
  o.seed = 5;
  const auto s = cocone_test::hemisphere(o);
  const UniquePoints unique = makeUniquePoints(s.points);
  const Triangulation dt = triangulate(unique.points);
  const VoronoiCells cells = computeVoronoiCells(dt, 3.0 * M_PI / 8.0);
  const std::vector<double> spacing = localSpacing(dt.points, cells);
  const double gap_angle = 80.0 * M_PI / 180.0;
  const HalfDisk h = halfDiskTest(dt.points, cells, spacing, 1.75, gap_angle);
  // Random samples: the median gap is about 75 degrees, the angle about twice 80.
  EXPECT_GT(h.angle, 1.8 * gap_angle);
  EXPECT_LT(h.angle, 2.6 * gap_angle);
  std::size_t border = 0, border_rim = 0, rim = 0, far_rim = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const int v = unique.vertex_of_input[i];
    border += s.near_boundary[i];
    border_rim += s.near_boundary[i] && h.rim[v];
    rim += h.rim[v];
    far_rim += h.rim[v] && s.points[i].z() > 3.0 * s.spacing;
  }
  // Measured: 122 rim points, 110 of the 477 within a spacing of the border (the
  // gap angle of a random sample, 176 degrees, is met by the outermost points only;
  // the flatness test labels the rest), 6 higher than 3 spacings.
  EXPECT_GT(rim, border / 5);
  EXPECT_GT(border_rim, 8 * rim / 10);
  EXPECT_LT(far_rim, rim / 10);
  const HalfDisk two = halfDiskTest(dt.points, cells, spacing, 1.75, gap_angle, 2);
  EXPECT_EQ(two.angle, h.angle);
  EXPECT_EQ(two.gap, h.gap);
  EXPECT_EQ(two.rim, h.rim);
}
