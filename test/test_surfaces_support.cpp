/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The ground truth of the test surfaces: point counts, distances, normals, spacing,
 * area and Euler characteristic (the latter two measured independently on a voxel
 * shell where the surface allows it), range views and outliers.
 */

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <support/surfaces.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

using cocone_test::Sample;
using cocone_test::SampleOptions;

namespace {

constexpr double kPi = 3.14159265358979323846;

SampleOptions
options(std::size_t n, bool even, std::uint64_t seed = 3)
{
  SampleOptions o;
  o.n = n;
  o.even = even;
  o.seed = seed;
  return o;
}

/** Brute-force mean nearest-neighbour distance among points with the same group
 *  (group (i) < 0: left out). */
double
meanNearest(const Sample& s, const std::function<int(std::size_t)>& group)
{
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (group(i) < 0)
      continue;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < s.points.size(); ++j)
      if (j != i && group(j) == group(i))
        best = std::min(best, (s.points[j] - s.points[i]).squaredNorm());
    sum += std::sqrt(best);
    ++count;
  }
  return sum / double(count);
}

/** Euler characteristic and volume of the voxels whose centres lie within delta of
 *  the surface (for delta below the reach: a shell homotopic to the surface, of
 *  volume 2 delta area + 4 pi / 3 euler delta^3). */
void
voxelShell(const Sample& s, double h, double delta, int& euler, double& volume)
{
  Eigen::Vector3d lo = s.points.front(), hi = lo;
  for (const auto& p : s.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  lo -= Eigen::Vector3d::Constant(delta + 2.0 * h);
  hi += Eigen::Vector3d::Constant(delta + 2.0 * h);
  const std::array<long, 3> dims{static_cast<long>((hi.x() - lo.x()) / h) + 1,
                                 static_cast<long>((hi.y() - lo.y()) / h) + 1,
                                 static_cast<long>((hi.z() - lo.z()) / h) + 1};
  std::vector<char> in(dims[0] * dims[1] * dims[2]);
  const auto at = [&](long i, long j, long k) -> char {
    if (i < 0 || j < 0 || k < 0 || i >= dims[0] || j >= dims[1] || k >= dims[2])
      return 0;
    return in[(i * dims[1] + j) * dims[2] + k];
  };
  long cubes = 0;
  for (long i = 0; i < dims[0]; ++i)
    for (long j = 0; j < dims[1]; ++j)
      for (long k = 0; k < dims[2]; ++k) {
        const Eigen::Vector3d c = lo + h * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
        cubes += in[(i * dims[1] + j) * dims[2] + k] = s.distance(c) < delta;
      }
  // Cells of the union of closed voxels: vertex (i, j, k) is the corner shared by
  // voxels (i - 1 .. i, ...); an edge along an axis by 4 voxels, a face by 2.
  long vertices = 0, edges = 0, faces = 0;
  for (long i = 0; i <= dims[0]; ++i)
    for (long j = 0; j <= dims[1]; ++j)
      for (long k = 0; k <= dims[2]; ++k) {
        bool v = false;
        for (int a = 0; a < 8; ++a)
          v = v || at(i - (a & 1), j - (a >> 1 & 1), k - (a >> 2 & 1));
        vertices += v;
        // Edges from the vertex along x, y, z; faces at the vertex normal to x, y, z.
        edges +=
            at(i, j, k) || at(i, j - 1, k) || at(i, j, k - 1) || at(i, j - 1, k - 1);
        edges +=
            at(i, j, k) || at(i - 1, j, k) || at(i, j, k - 1) || at(i - 1, j, k - 1);
        edges +=
            at(i, j, k) || at(i - 1, j, k) || at(i, j - 1, k) || at(i - 1, j - 1, k);
        faces += at(i, j, k) || at(i - 1, j, k);
        faces += at(i, j, k) || at(i, j - 1, k);
        faces += at(i, j, k) || at(i, j, k - 1);
      }
  euler = static_cast<int>(vertices - edges + faces - cubes);
  volume = double(cubes) * h * h * h;
}

/** What every closed generator promises, on a noise-free sample. */
void
checkClosed(const Sample& s, std::size_t n, bool even, int euler, int components)
{
  SCOPED_TRACE(s.name + (even ? " even" : " random"));
  const std::size_t m = s.points.size();
  if (even)
    EXPECT_NEAR(double(m), double(n), 0.03 * double(n));
  else
    EXPECT_EQ(m, n);
  ASSERT_EQ(s.normals.size(), m);
  ASSERT_EQ(s.component.size(), m);
  ASSERT_EQ(s.near_boundary.size(), m);
  ASSERT_EQ(s.outlier.size(), m);
  EXPECT_TRUE(s.view.empty());
  EXPECT_TRUE(s.closed);
  EXPECT_EQ(s.euler, euler);
  EXPECT_EQ(s.components, components);
  EXPECT_EQ(s.boundary_loops, 0);
  EXPECT_TRUE(s.boundary_curve.empty());
  EXPECT_GT(s.area, 0.0);
  // Spacing: near sqrt (area / n) (about 0.85 of it even, 0.5 random).
  const double scale = std::sqrt(s.area / double(m));
  EXPECT_GT(s.spacing, 0.35 * scale);
  EXPECT_LT(s.spacing, 1.2 * scale);
  double flux = 0.0; // sum n . p dA = 3 volume > 0 for outward normals
  for (std::size_t i = 0; i < m; ++i) {
    EXPECT_NEAR(s.normals[i].norm(), 1.0, 1e-12);
    EXPECT_LT(s.distance(s.points[i]), 1e-9) << i;
    // The normal is normal: a step along it is that far from the surface.
    const double step = 0.1 * s.spacing;
    EXPECT_NEAR(s.distance(s.points[i] + step * s.normals[i]), step, 1e-9) << i;
    EXPECT_FALSE(s.near_boundary[i]);
    EXPECT_FALSE(s.outlier[i]);
    EXPECT_GE(s.component[i], 0);
    EXPECT_LT(s.component[i], components);
    flux += s.normals[i].dot(s.points[i]);
  }
  EXPECT_GT(flux, 0.0);
}

TEST(Genus2, GroundTruth)
{
  for (const bool even : {true, false}) {
    const Sample s = cocone_test::genus2(options(3000, even));
    checkClosed(s, 3000, even, -2, 1);
    EXPECT_NEAR(meanNearest(s, [](std::size_t) { return 0; }), s.spacing, 1e-12);
    // Area 2 A + pi r L + 4 pi chi(D) r^2 of the domain D (stadium minus holes).
    const double r = 0.3;
    const double domain = kPi + 4.0 - 2.0 * kPi * 0.25;
    const double length = 4.0 + 2.0 * kPi + 2.0 * kPi;
    EXPECT_NEAR(s.area, 2.0 * domain + kPi * r * length - 4.0 * kPi * r * r, 1e-9);
  }
  // Topology and area measured on a voxel shell of the distance function.
  const Sample s = cocone_test::genus2(options(500, true));
  int euler = 0;
  double volume = 0.0;
  const double delta = 0.06;
  voxelShell(s, 0.015, delta, euler, volume);
  EXPECT_EQ(euler, -2);
  EXPECT_NEAR(volume,
              2.0 * delta * s.area - 4.0 * kPi / 3.0 * 2.0 * delta * delta * delta,
              0.01 * volume);
}

TEST(ThinPlate, GroundTruth)
{
  for (const bool even : {true, false}) {
    const double thickness = 0.02;
    const Sample s = cocone_test::thinPlate(options(3000, even), thickness);
    checkClosed(s, 3000, even, 2, 1);
    // Spacing within each half; overall the nearest sample is mostly across.
    const auto half = [&](std::size_t i) { return s.normals[i].z() > 0.0 ? 0 : 1; };
    EXPECT_NEAR(meanNearest(s, half), s.spacing, 1e-12);
    if (even) {
      EXPECT_GT(s.spacing, 1.5 * thickness);
      EXPECT_LT(meanNearest(s, [](std::size_t) { return 0; }), 0.8 * s.spacing);
    }
    // Steiner: 2 A + pi r L + 4 pi r^2 for a convex domain.
    const double r = 0.5 * thickness, rc = 0.2;
    const double domain = 2.8 - (4.0 - kPi) * rc * rc;
    const double length = 4.0 * 0.8 + 4.0 * 0.5 + 2.0 * kPi * rc;
    EXPECT_NEAR(s.area, 2.0 * domain + kPi * r * length + 4.0 * kPi * r * r, 1e-9);
    // Both sheets evenly sampled: about as many points on each.
    std::size_t top = 0;
    for (const auto& n : s.normals)
      top += n.z() > 0.0;
    EXPECT_NEAR(double(top), 0.5 * s.points.size(), 0.05 * s.points.size());
  }
}

TEST(Cube, GroundTruth)
{
  for (const bool even : {true, false}) {
    const Sample s = cocone_test::cube(options(3000, even));
    checkClosed(s, 3000, even, 2, 1);
    EXPECT_NEAR(meanNearest(s, [](std::size_t) { return 0; }), s.spacing, 1e-12);
    EXPECT_DOUBLE_EQ(s.area, 24.0);
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      // A face normal, and the point on that face.
      int axis = 0;
      s.normals[i].cwiseAbs().maxCoeff(&axis);
      EXPECT_EQ(s.normals[i].cwiseAbs().sum(), 1.0);
      EXPECT_EQ(s.points[i][axis], s.normals[i][axis]);
      EXPECT_LE(s.points[i].cwiseAbs().maxCoeff(), 1.0);
    }
  }
  const Sample s = cocone_test::cube(options(500, true));
  EXPECT_DOUBLE_EQ(s.distance(Eigen::Vector3d(0.2, 0.3, 0.5)), 0.5);
  EXPECT_DOUBLE_EQ(s.distance(Eigen::Vector3d(2.0, 3.0, 0.5)), std::sqrt(5.0));
}

TEST(Tube, GroundTruth)
{
  const double radius = 0.02;
  double length = 0.0; // the trefoil's length, with libm
  for (int k = 0; k < 4000; ++k) {
    const double t = 2.0 * kPi * (k + 0.5) / 4000;
    length += std::sqrt(17.0 + 8.0 * std::cos(3.0 * t) +
                        9.0 * std::cos(3.0 * t) * std::cos(3.0 * t));
  }
  length *= 2.0 * kPi / 4000;
  for (const bool even : {true, false}) {
    const Sample s = cocone_test::tube(options(3000, even));
    checkClosed(s, 3000, even, 0, 1);
    EXPECT_NEAR(meanNearest(s, [](std::size_t) { return 0; }), s.spacing, 1e-12);
    EXPECT_NEAR(s.area, 2.0 * kPi * radius * length, 1e-9);
    EXPECT_NEAR(s.distance(Eigen::Vector3d(0.0, -1.0, 0.0)), radius, 1e-12);
    // Against the nearest of 4000 curve points (libm), refined by a ternary
    // search, near the tube and farther.
    const auto at = [](double t) {
      return Eigen::Vector3d(std::sin(t) + 2.0 * std::sin(2.0 * t),
                             std::cos(t) - 2.0 * std::cos(2.0 * t),
                             -std::sin(3.0 * t));
    };
    const double h = 2.0 * kPi / 4000;
    for (std::size_t i = 0; i < s.points.size(); i += 97) {
      for (const double step : {-0.02, 0.05, 0.3}) {
        const Eigen::Vector3d q =
            s.points[i] + step * s.normals[i] + 0.1 * step * Eigen::Vector3d(1, -2, 3);
        int k = 0;
        for (int j = 1; j < 4000; ++j)
          if ((at(j * h) - q).squaredNorm() < (at(k * h) - q).squaredNorm())
            k = j;
        double lo = (k - 1) * h, hi = (k + 1) * h;
        for (int it = 0; it < 100; ++it) {
          const double a = lo + (hi - lo) / 3.0, b = hi - (hi - lo) / 3.0;
          if ((at(a) - q).squaredNorm() < (at(b) - q).squaredNorm())
            hi = b;
          else
            lo = a;
        }
        const double best = (at(0.5 * (lo + hi)) - q).squaredNorm();
        EXPECT_NEAR(s.distance(q), std::abs(std::sqrt(best) - radius), 1e-12);
      }
    }
  }
  // Coarse: 6 to 10 samples around the tube with the default n.
  const Sample s = cocone_test::tube(options(10000, true));
  const double around = 2.0 * kPi * radius / s.spacing;
  EXPECT_GE(around, 6.0);
  EXPECT_LE(around, 10.0);
}

TEST(TwoTouchingSpheres, GroundTruth)
{
  for (const bool even : {true, false}) {
    const Sample s = cocone_test::twoTouchingSpheres(options(3000, even));
    checkClosed(s, 3000, even, 4, 2);
    const auto own = [&](std::size_t i) { return s.component[i]; };
    EXPECT_NEAR(meanNearest(s, own), s.spacing, 1e-12);
    EXPECT_NEAR(s.area, 8.0 * kPi, 1e-12);
    // The centres are 2 + gap spacings apart, gap 0.5.
    const double c = 1.0 + 0.25 * s.spacing;
    std::size_t count[2] = {0, 0};
    double closest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      const int k = s.component[i];
      ++count[k];
      const Eigen::Vector3d centre(k == 0 ? -c : c, 0.0, 0.0);
      EXPECT_NEAR((s.points[i] - centre).norm(), 1.0, 1e-12);
      EXPECT_EQ(s.normals[i].x() > 0.0, s.points[i].x() > centre.x());
      if (k == 0)
        for (std::size_t j = 0; j < s.points.size(); ++j)
          if (s.component[j] == 1)
            closest = std::min(closest, (s.points[j] - s.points[i]).norm());
    }
    EXPECT_NEAR(double(count[0]), double(count[1]), 0.1 * s.points.size());
    EXPECT_GE(closest, 0.5 * s.spacing);
    EXPECT_LT(closest, 3.0 * s.spacing);
    EXPECT_NEAR(s.distance(Eigen::Vector3d::Zero()), 0.25 * s.spacing, 1e-12);
  }
}

TEST(Sphere, DensityRatioEight)
{
  SampleOptions o = options(20000, false);
  o.density_ratio = 8.0;
  const Sample s = cocone_test::sphere(o);
  // Caps x > 0.9 and x < -0.9 (equal areas; x uniform on the sphere): mean density
  // 1 + 3.5 (x + 1) at x = +-0.95.
  double high = 0, low = 0;
  for (const auto& p : s.points) {
    high += p.x() > 0.9;
    low += p.x() < -0.9;
  }
  EXPECT_NEAR(high / low, 7.825 / 1.175, 0.6);
  // Even: the local spacing scales with 1 / sqrt (density).
  o.even = true;
  o.n = 8000;
  const Sample e = cocone_test::sphere(o);
  const auto cap = [&](std::size_t i) {
    return e.points[i].x() > 0.9 ? 0 : e.points[i].x() < -0.9 ? 1 : -1;
  };
  double near[2] = {0, 0};
  std::size_t in[2] = {0, 0};
  for (std::size_t i = 0; i < e.points.size(); ++i) {
    const int k = cap(i);
    if (k < 0)
      continue;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < e.points.size(); ++j)
      if (j != i)
        best = std::min(best, (e.points[j] - e.points[i]).norm());
    near[k] += best;
    ++in[k];
  }
  EXPECT_NEAR((near[1] / in[1]) / (near[0] / in[0]), std::sqrt(7.825 / 1.175), 0.3);
}

TEST(Generators, Reproducible)
{
  const auto same = [](const Sample& a, const Sample& b) {
    return a.points == b.points && a.normals == b.normals;
  };
  SampleOptions o = options(1000, true);
  o.noise = 0.2;
  o.density_ratio = 3.0;
  EXPECT_TRUE(same(cocone_test::genus2(o), cocone_test::genus2(o)));
  EXPECT_TRUE(same(cocone_test::thinPlate(o), cocone_test::thinPlate(o)));
  EXPECT_TRUE(same(cocone_test::cube(o), cocone_test::cube(o)));
  EXPECT_TRUE(same(cocone_test::tube(o), cocone_test::tube(o)));
  EXPECT_TRUE(
      same(cocone_test::twoTouchingSpheres(o), cocone_test::twoTouchingSpheres(o)));
  const Sample base = cocone_test::sphere(options(4000, true));
  EXPECT_TRUE(same(cocone_test::rangeViews(base, 4, 1.0, 7, 0.1),
                   cocone_test::rangeViews(base, 4, 1.0, 7, 0.1)));
  EXPECT_FALSE(same(cocone_test::rangeViews(base, 4, 1.0, 7, 0.1),
                    cocone_test::rangeViews(base, 4, 1.0, 8, 0.1)));
  // Noise along the normal, sigma a fraction of the spacing.
  o.density_ratio = 1.0;
  const Sample clean = cocone_test::cube(options(1000, true));
  const Sample noisy = cocone_test::cube(o);
  ASSERT_EQ(clean.points.size(), noisy.points.size());
  double sum2 = 0.0;
  for (std::size_t i = 0; i < clean.points.size(); ++i) {
    const Eigen::Vector3d d = noisy.points[i] - clean.points[i];
    EXPECT_NEAR(d.cross(clean.normals[i]).norm(), 0.0, 1e-12);
    sum2 += d.squaredNorm();
  }
  EXPECT_NEAR(
      std::sqrt(sum2 / clean.points.size()), 0.2 * clean.spacing, 0.02 * clean.spacing);
}

TEST(RangeViews, CoverAndRegistration)
{
  const Sample base = cocone_test::sphere(options(8000, true));
  // Without error or noise the views are disjoint subsets of the sites.
  const Sample exact = cocone_test::rangeViews(base, 4, 0.0, 1);
  ASSERT_EQ(exact.view.size(), exact.points.size());
  EXPECT_TRUE(exact.closed);
  EXPECT_EQ(exact.euler, 2);
  EXPECT_EQ(exact.boundary_loops, 0);
  EXPECT_EQ(exact.components, 1);
  EXPECT_LT(exact.points.size(), base.points.size());
  EXPECT_GT(exact.points.size(), base.points.size() / 3);
  auto sorted = exact.points;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
  for (const auto& p : exact.points)
    EXPECT_LT(exact.distance(p), 1e-12);

  const double error = 1.0;
  const Sample s = cocone_test::rangeViews(base, 6, error, 2);
  EXPECT_TRUE(s.closed);
  EXPECT_EQ(s.euler, 2);
  ASSERT_EQ(s.outlier.size(), s.points.size());
  std::vector<Eigen::Vector3d> mean(6, Eigen::Vector3d::Zero());
  std::vector<double> off(6, 0.0);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    ASSERT_GE(s.view[i], 0);
    ASSERT_LT(s.view[i], 6);
    mean[s.view[i]] += s.normals[i];
    const double d = s.distance(s.points[i]);
    EXPECT_LE(d, error * s.spacing * (1.0 + 1e-9));
    off[s.view[i]] = std::max(off[s.view[i]], d);
  }
  for (int v = 0; v < 6; ++v) {
    EXPECT_GT(mean[v].norm(), 0.0) << v;
    EXPECT_GT(off[v], 0.05 * error * s.spacing) << v;
  }
  // Each site faces the camera of its view (a unit sphere: the bounding box centre
  // is about 0, half its diagonal about sqrt 3), and the views overlap: every view
  // but the first keeps sites that an earlier one saw as well.
  std::vector<std::size_t> shared(6, 0);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    int facing = 0;
    for (int v = 0; v < 6; ++v) {
      const double z = 1.0 - (2.0 * v + 1.0) / 6.0,
                   phi = v * kPi * (3.0 - std::sqrt(5.0));
      const Eigen::Vector3d camera =
          4.0 * std::sqrt(3.0) *
          Eigen::Vector3d(std::sqrt(1.0 - z * z) * std::cos(phi),
                          std::sqrt(1.0 - z * z) * std::sin(phi),
                          z);
      // Within the registration error of the site.
      if (s.normals[i].dot(camera - s.points[i]) > -0.05) {
        facing += v < s.view[i];
        if (v == s.view[i])
          facing += 100;
      }
    }
    EXPECT_GE(facing, 100) << i;
    shared[s.view[i]] += facing > 100;
  }
  for (int v = 1; v < 6; ++v)
    EXPECT_GT(shared[v], 0u) << v;

  // One view sees part of the surface: the truth is unknown.
  const Sample part = cocone_test::rangeViews(base, 1, 0.0, 3);
  EXPECT_FALSE(part.closed);
  EXPECT_EQ(part.boundary_loops, -1);
  EXPECT_EQ(part.components, -1);
  std::size_t rim = 0;
  for (std::size_t i = 0; i < part.points.size(); ++i)
    rim += part.near_boundary[i];
  EXPECT_GT(rim, 0u);
  EXPECT_LT(rim, part.points.size() / 2);

  // A torus needs more views (its hole hides the inner side from most directions).
  const Sample torus =
      cocone_test::rangeViews(cocone_test::torus(options(8000, true)), 8, 0.5, 4);
  EXPECT_TRUE(torus.closed);
  EXPECT_EQ(torus.euler, 0);
}

TEST(Outliers, FlyingPixels)
{
  const Sample base = cocone_test::sphere(options(3000, true));
  const Sample s = cocone_test::withOutliers(base, 0.1, 5.0, 9);
  ASSERT_EQ(s.points.size(), base.points.size());
  std::size_t count = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (!s.outlier[i]) {
      EXPECT_EQ(s.points[i], base.points[i]);
      EXPECT_EQ(s.component[i], 0);
      continue;
    }
    ++count;
    const double d = s.distance(s.points[i]) / s.spacing;
    EXPECT_GE(d, 1.0 - 1e-9);
    EXPECT_LE(d, 5.0 + 1e-9);
    EXPECT_FALSE(s.near_boundary[i]);
    EXPECT_EQ(s.component[i], -1);
  }
  EXPECT_EQ(count, static_cast<std::size_t>(0.1 * s.points.size() + 0.5));
  EXPECT_EQ(s.euler, base.euler);
  EXPECT_EQ(s.spacing, base.spacing);
}

TEST(Outliers, Scattered)
{
  const Sample base =
      cocone_test::rangeViews(cocone_test::cube(options(6000, true)), 6, 0.5, 5);
  const Sample s = cocone_test::withScatteredOutliers(base, 0.05, 11);
  const std::size_t n = base.points.size();
  ASSERT_EQ(s.points.size(), n + static_cast<std::size_t>(0.05 * n + 0.5));
  ASSERT_EQ(s.view.size(), s.points.size());
  ASSERT_EQ(s.outlier.size(), s.points.size());
  double far = 0.0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    EXPECT_EQ(s.outlier[i], i >= n);
    if (i < n) {
      EXPECT_EQ(s.points[i], base.points[i]);
      continue;
    }
    EXPECT_EQ(s.view[i], -1);
    EXPECT_EQ(s.component[i], -1);
    EXPECT_FALSE(s.near_boundary[i]);
    EXPECT_EQ(s.normals[i], Eigen::Vector3d::Zero());
    EXPECT_LE(s.points[i].cwiseAbs().maxCoeff(), 1.0 + 0.1 + 2.0 * s.spacing);
    far = std::max(far, s.distance(s.points[i]));
  }
  EXPECT_GT(far, 0.5); // some deep inside or far outside the cube
  EXPECT_THROW(cocone_test::withOutliers(base, 1.5, 2.0, 1), std::invalid_argument);
  EXPECT_THROW(cocone_test::withOutliers(base, 0.1, 0.5, 1), std::invalid_argument);
  EXPECT_THROW(cocone_test::rangeViews(base, 0, 0.0, 1), std::invalid_argument);
}

} // namespace
