/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/common/point_tests.h>
#include <pcl/surface/cocone_boundary.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <support/cases.h>
#include <support/metrics.h>
#include <support/surfaces.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace {

template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr
toCloud(const std::vector<Eigen::Vector3d>& points)
{
  typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
  for (const auto& p : points) {
    PointT q;
    q.x = static_cast<float>(p.x());
    q.y = static_cast<float>(p.y());
    q.z = static_cast<float>(p.z());
    cloud->push_back(q);
  }
  return cloud;
}

cocone_test::Sample
hemisphere(std::size_t n = 3000)
{
  cocone_test::SampleOptions o;
  o.n = n;
  return cocone_test::hemisphere(o);
}

std::vector<int>
detect(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud, bool* ok = nullptr)
{
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  pcl::PointIndices boundary;
  const bool success = cocone.detectBoundary(boundary);
  if (ok)
    *ok = success;
  return {boundary.indices.begin(), boundary.indices.end()};
}

} // namespace

TEST(CoConeBoundary, DefaultsAndSetterValidation)
{
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  EXPECT_DOUBLE_EQ(cocone.getRatio(), 0.0); // automatic
  EXPECT_DOUBLE_EQ(cocone.getSpacingFactor(), 3.0);
  EXPECT_DOUBLE_EQ(cocone.getNormalAngle(), M_PI / 6.0);
  EXPECT_DOUBLE_EQ(cocone.getCoconeAngle(), 3.0 * M_PI / 8.0);
  EXPECT_TRUE(cocone.getBoundaryDetection());
  cocone.setRatio(2.5);
  EXPECT_DOUBLE_EQ(cocone.getRatio(), 2.5);
  cocone.setRatio(-1.0);
  cocone.setRatio(std::numeric_limits<double>::quiet_NaN());
  cocone.setRatio(std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(cocone.getRatio(), 2.5);
  cocone.setSpacingFactor(-1.0);
  EXPECT_DOUBLE_EQ(cocone.getSpacingFactor(), 3.0);
  cocone.setSpacingFactor(0.0);
  EXPECT_DOUBLE_EQ(cocone.getSpacingFactor(), 0.0);
  cocone.setNormalAngle(0.0);
  cocone.setNormalAngle(2.0);
  EXPECT_DOUBLE_EQ(cocone.getNormalAngle(), M_PI / 6.0);
  cocone.setCoconeAngle(M_PI / 2.0);
  EXPECT_DOUBLE_EQ(cocone.getCoconeAngle(), 3.0 * M_PI / 8.0);
  cocone.setCoconeAngle(1.0);
  EXPECT_DOUBLE_EQ(cocone.getCoconeAngle(), 1.0);
}

TEST(CoConeBoundary, NoInputIsAnError)
{
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  pcl::PointIndices boundary;
  boundary.indices = {1, 2, 3};
  EXPECT_FALSE(cocone.detectBoundary(boundary));
  EXPECT_TRUE(boundary.indices.empty());
}

TEST(CoConeBoundary, TooFewPointsAreAnError)
{
  for (std::size_t n = 0; n < 4; ++n) {
    std::vector<Eigen::Vector3d> pts;
    for (std::size_t i = 0; i < n; ++i)
      pts.emplace_back(double(i), double(i * i), 1.0 - double(i));
    bool ok = true;
    EXPECT_TRUE(detect(toCloud<pcl::PointXYZ>(pts), &ok).empty());
    EXPECT_FALSE(ok) << n << " points";
  }
  // Many copies of three points are still three points.
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 30; ++i)
    pts.emplace_back(double(i % 3), double(i % 3 == 1), 0.0);
  bool ok = true;
  EXPECT_TRUE(detect(toCloud<pcl::PointXYZ>(pts), &ok).empty());
  EXPECT_FALSE(ok);
  // ... and all-identical points are one.
  ok = true;
  EXPECT_TRUE(
      detect(toCloud<pcl::PointXYZ>(std::vector<Eigen::Vector3d>(50, {1, 2, 3})), &ok)
          .empty());
  EXPECT_FALSE(ok);
}

TEST(CoConeBoundary, CollinearInputIsAnError)
{
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 100; ++i)
    pts.emplace_back(0.5 * i, 1.0 + i, -2.0 * i);
  bool ok = true;
  EXPECT_TRUE(detect(toCloud<pcl::PointXYZ>(pts), &ok).empty());
  EXPECT_FALSE(ok);
}

TEST(CoConeBoundary, NonFinitePointsAreSkipped)
{
  const auto s = hemisphere();
  const auto clean = detect(toCloud<pcl::PointXYZ>(s.points));
  ASSERT_FALSE(clean.empty());

  // Insert a NaN or Inf point before every 7th point; map the clean result over.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  auto cloud = toCloud<pcl::PointXYZ>({});
  std::vector<int> new_index;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (i % 7 == 0)
      cloud->push_back(i % 2 ? pcl::PointXYZ(nan, 0, 0) : pcl::PointXYZ(0, inf, 0));
    new_index.push_back(static_cast<int>(cloud->size()));
    cloud->push_back(pcl::PointXYZ(static_cast<float>(s.points[i].x()),
                                   static_cast<float>(s.points[i].y()),
                                   static_cast<float>(s.points[i].z())));
  }
  cloud->is_dense = false;
  std::vector<int> expected;
  for (const int i : clean)
    expected.push_back(new_index[i]);
  EXPECT_EQ(detect(cloud), expected);
}

TEST(CoConeBoundary, DuplicatesShareTheirLabel)
{
  const auto s = hemisphere();
  auto cloud = toCloud<pcl::PointXYZ>(s.points);
  const std::size_t n = cloud->size();
  // Append a copy of every point: each copy must get its original's label.
  for (std::size_t i = 0; i < n; ++i)
    cloud->push_back((*cloud)[i]);
  const auto clean = detect(toCloud<pcl::PointXYZ>(s.points));
  std::vector<int> expected;
  for (const int i : clean)
    expected.push_back(i);
  for (const int i : clean)
    expected.push_back(i + static_cast<int>(n));
  EXPECT_EQ(detect(cloud), expected);
}

TEST(CoConeBoundary, IndicesSelectASubsetAndRefertoTheCloud)
{
  const auto s = hemisphere();
  const auto clean = detect(toCloud<pcl::PointXYZ>(s.points));
  // Put the hemisphere's points at odd positions, junk at even ones.
  auto cloud = toCloud<pcl::PointXYZ>({});
  pcl::IndicesPtr indices(new pcl::Indices);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    cloud->push_back(pcl::PointXYZ(100.0f + float(i % 13), float(i % 5), float(i % 3)));
    indices->push_back(static_cast<int>(cloud->size()));
    cloud->push_back(pcl::PointXYZ(static_cast<float>(s.points[i].x()),
                                   static_cast<float>(s.points[i].y()),
                                   static_cast<float>(s.points[i].z())));
  }
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  cocone.setIndices(indices);
  pcl::PointIndices boundary;
  ASSERT_TRUE(cocone.detectBoundary(boundary));
  std::vector<int> expected;
  for (const int i : clean)
    expected.push_back(2 * i + 1);
  EXPECT_EQ(std::vector<int>(boundary.indices.begin(), boundary.indices.end()),
            expected);
  pcl::PointIndices again;
  cocone.getBoundaryPointIndices(again);
  EXPECT_EQ(again.indices, boundary.indices);

  // An index outside the cloud is an error, not a crash.
  indices->push_back(static_cast<int>(cloud->size()) + 10);
  cocone.setIndices(indices);
  EXPECT_FALSE(cocone.detectBoundary(boundary));
  EXPECT_TRUE(boundary.indices.empty());
}

TEST(CoConeBoundary, FlatWallHasItsOutlineAsBoundary)
{
  // An exactly planar wall scan, tilted (the plane z = x + 2 y / 4 holds exactly in
  // float for these dyadic coordinates), interior jittered in the plane: its outline
  // points are boundary, its inner points interior.
  std::vector<Eigen::Vector3d> pts;
  const int nx = 60, ny = 40;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const bool edge = i == 0 || j == 0 || i == nx - 1 || j == ny - 1;
      const double jx = edge ? 0.0 : ((i * 7 + j * 13) % 9 - 4) / 32.0;
      const double jy = edge ? 0.0 : ((i * 11 + j * 5) % 9 - 4) / 32.0;
      const double x = i + jx, y = j + jy;
      pts.emplace_back(x, y, x + y / 2.0);
    }
  const auto boundary = detect(toCloud<pcl::PointXYZ>(pts));
  std::vector<bool> is_boundary(pts.size(), false);
  for (const int i : boundary)
    is_boundary[i] = true;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const bool edge = i == 0 || j == 0 || i == nx - 1 || j == ny - 1;
      EXPECT_EQ(is_boundary[i * ny + j], edge) << i << ", " << j;
    }
}

template <typename PointT>
class CoConeBoundaryTyped : public ::testing::Test {};
using XYZTypes = ::testing::Types<pcl::PointXYZ,
                                  pcl::PointXYZI,
                                  pcl::PointXYZL,
                                  pcl::PointXYZRGBA,
                                  pcl::PointXYZRGB,
                                  pcl::PointXYZRGBL,
                                  pcl::PointXYZLAB,
                                  pcl::PointXYZHSV,
                                  pcl::InterestPoint,
                                  pcl::PointNormal,
                                  pcl::PointXYZRGBNormal,
                                  pcl::PointXYZINormal,
                                  pcl::PointXYZLNormal,
                                  pcl::PointWithRange,
                                  pcl::PointWithViewpoint,
                                  pcl::PointWithScale,
                                  pcl::PointSurfel,
                                  pcl::PointDEM>;
TYPED_TEST_SUITE(CoConeBoundaryTyped, XYZTypes);

TYPED_TEST(CoConeBoundaryTyped, EveryInstantiatedTypeRuns)
{
  const auto s = hemisphere(1500);
  const auto cloud = toCloud<TypeParam>(s.points);
  pcl::CoConeBoundary<TypeParam> cocone;
  cocone.setInputCloud(cloud);
  pcl::PointIndices boundary;
  ASSERT_TRUE(cocone.detectBoundary(boundary));
  const auto score = cocone_test::scoreBoundary(
      s, std::vector<int>(boundary.indices.begin(), boundary.indices.end()));
  EXPECT_GE(score.precision, 0.9) << score.str();

  // Both reconstruct overloads. Every field of every point survives into the mesh's
  // cloud: give the non-xyz fields distinct values first.
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    TypeParam& p = (*cloud)[i];
    const Eigen::Vector3f xyz = p.getVector3fMap();
    auto* bytes = reinterpret_cast<unsigned char*>(&p);
    for (std::size_t b = 0; b < sizeof(TypeParam); ++b)
      bytes[b] = static_cast<unsigned char>((i * 31 + b * 7) % 251);
    p.getVector3fMap() = xyz;
  }
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  EXPECT_GT(mesh.polygons.size(), 2500u);
  EXPECT_EQ(std::size_t(mesh.cloud.width) * mesh.cloud.height, cloud->size());
  pcl::PCLPointCloud2 expected;
  pcl::toPCLPointCloud2(*cloud, expected);
  EXPECT_EQ(mesh.cloud.fields.size(), expected.fields.size());
  EXPECT_EQ(mesh.cloud.data, expected.data);
  pcl::PointCloud<TypeParam> points;
  std::vector<pcl::Vertices> polygons;
  cocone.reconstruct(points, polygons);
  EXPECT_EQ(points.size(), cloud->size());
  ASSERT_EQ(polygons.size(), mesh.polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i)
    EXPECT_EQ(polygons[i].vertices, mesh.polygons[i].vertices);
}

TEST(CoConeBoundary, ReconstructWithoutInputIsAnError)
{
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  pcl::PolygonMesh mesh;
  mesh.polygons.resize(3);
  cocone.reconstruct(mesh); // PCL's base class would dereference the missing cloud
  EXPECT_TRUE(mesh.polygons.empty());
  pcl::PointCloud<pcl::PointXYZ> points;
  std::vector<pcl::Vertices> polygons(2);
  cocone.reconstruct(points, polygons);
  EXPECT_TRUE(polygons.empty());
  // Too few points: a defined empty mesh.
  cocone.setInputCloud(toCloud<pcl::PointXYZ>({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  cocone.reconstruct(mesh);
  EXPECT_TRUE(mesh.polygons.empty());
  EXPECT_EQ(mesh.cloud.width * mesh.cloud.height, 0u);
}

TEST(CoConeBoundary, MeshIndicesReferToTheInputCloud)
{
  // The hemisphere at odd positions behind junk, NaN points and duplicates; setIndices
  // selects the hemisphere's points (and their duplicates and NaNs).
  const auto s = hemisphere();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto cloud = toCloud<pcl::PointXYZ>({});
  pcl::IndicesPtr indices(new pcl::Indices);
  std::vector<int> position;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    cloud->push_back(pcl::PointXYZ(50.0f + float(i % 7), float(i % 3), float(i % 5)));
    position.push_back(static_cast<int>(cloud->size()));
    indices->push_back(static_cast<int>(cloud->size()));
    cloud->push_back(pcl::PointXYZ(static_cast<float>(s.points[i].x()),
                                   static_cast<float>(s.points[i].y()),
                                   static_cast<float>(s.points[i].z())));
    if (i % 10 == 0) { // a NaN point and a duplicate, both selected
      indices->push_back(static_cast<int>(cloud->size()));
      cloud->push_back(pcl::PointXYZ(nan, nan, nan));
      indices->push_back(static_cast<int>(cloud->size()));
      cloud->push_back(cloud->at(position.back()));
    }
  }
  cloud->is_dense = false;
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  cocone.setIndices(indices);
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  ASSERT_GT(mesh.polygons.size(), 5000u);
  std::vector<bool> selected(cloud->size(), false);
  for (const int i : *indices)
    selected[i] = true;
  std::vector<bool> used(cloud->size(), false);
  for (const auto& p : mesh.polygons)
    for (const auto v : p.vertices) {
      ASSERT_LT(std::size_t(v), cloud->size());
      EXPECT_TRUE(selected[v]);
      EXPECT_TRUE(pcl::isFinite((*cloud)[v]));
      used[v] = true;
    }
  // Duplicates are represented by their first occurrence.
  for (std::size_t i = 0; i < s.points.size(); ++i)
    EXPECT_TRUE(used[position[i]]) << i;

  // Border loops: closed chains of border edges of the mesh.
  std::vector<pcl::Vertices> loops;
  cocone.getBoundaryLoops(loops);
  ASSERT_EQ(loops.size(), 1u);
  std::map<std::pair<int, int>, int> edge_count;
  for (const auto& p : mesh.polygons)
    for (int k = 0; k < 3; ++k) {
      const int a = p.vertices[k], b = p.vertices[(k + 1) % 3];
      ++edge_count[{std::min(a, b), std::max(a, b)}];
    }
  const auto& loop = loops.front().vertices;
  ASSERT_GT(loop.size(), 50u);
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const int a = loop[k], b = loop[(k + 1) % loop.size()];
    EXPECT_EQ((edge_count[{std::min(a, b), std::max(a, b)}]), 1) << a << "-" << b;
  }

  // Normals: one per cloud point, NaN off the mesh, outward on the hemisphere.
  pcl::PointCloud<pcl::Normal> normals;
  cocone.getPointNormals(normals);
  ASSERT_EQ(normals.size(), cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const bool in_mesh = selected[i] && pcl::isFinite((*cloud)[i]);
    EXPECT_EQ(std::isfinite(normals[i].normal_x), in_mesh) << i;
    const float outward =
        in_mesh ? normals[i].getNormalVector3fMap().dot((*cloud)[i].getVector3fMap())
                : 1.0f;
    EXPECT_GT(outward, 0.9f) << i;
  }
}

TEST(CoConeBoundary, FilledHolesReferToTheInputCloud)
{
  // A dropout near the hemisphere's pole, 3 spacings across, the points behind junk
  // that setIndices leaves out: with a hole width of 4 rim triangles the hole is
  // closed and its rim reported in the cloud's indices; without the hole filling
  // the rim is the mesh's second border loop.
  const auto s = hemisphere();
  std::size_t pole = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (s.points[i].z() > s.points[pole].z())
      pole = i;
  const Eigen::Vector3d centre = s.points[pole];
  auto cloud = toCloud<pcl::PointXYZ>({});
  pcl::IndicesPtr indices(new pcl::Indices);
  for (const auto& p : s.points) {
    if ((p - centre).norm() < 1.5 * s.spacing)
      continue;
    cloud->push_back(pcl::PointXYZ(9.0f, 9.0f, 9.0f)); // junk, not selected
    indices->push_back(static_cast<int>(cloud->size()));
    cloud->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  }
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  cocone.setIndices(indices);
  cocone.setMaxHoleWidth(4.0);
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  std::vector<pcl::Vertices> rims, loops;
  cocone.getFilledHoles(rims);
  cocone.getBoundaryLoops(loops);
  ASSERT_EQ(rims.size(), 1u);
  EXPECT_EQ(loops.size(), 1u);
  EXPECT_EQ(cocone.getReconstructionCounts().holes_filled, 1u);
  std::map<std::pair<int, int>, int> edge_count;
  for (const auto& p : mesh.polygons)
    for (int k = 0; k < 3; ++k) {
      const int a = p.vertices[k], b = p.vertices[(k + 1) % 3];
      ++edge_count[{std::min(a, b), std::max(a, b)}];
    }
  const std::vector<int> rim(rims[0].vertices.begin(), rims[0].vertices.end());
  ASSERT_GE(rim.size(), 6u);
  EXPECT_EQ(rim[0], *std::min_element(rim.begin(), rim.end()));
  for (std::size_t k = 0; k < rim.size(); ++k) {
    const int a = rim[k], b = rim[(k + 1) % rim.size()];
    EXPECT_EQ(a % 2, 1) << "not a selected point";
    EXPECT_LT((cloud->at(a).getVector3fMap().cast<double>() - centre).norm(),
              3.0 * s.spacing);
    EXPECT_EQ((edge_count[{std::min(a, b), std::max(a, b)}]), 2) << a << "-" << b;
  }

  // Refined and faired: the added vertices follow the cloud's points in the mesh.
  cocone.setRefineFilledHoles(true);
  pcl::PolygonMesh refined;
  cocone.reconstruct(refined);
  const std::size_t added = cocone.getNumberOfAddedPoints();
  EXPECT_GT(added, 0u);
  pcl::PointCloud<pcl::PointXYZ> vertices;
  pcl::fromPCLPointCloud2(refined.cloud, vertices);
  ASSERT_EQ(vertices.size(), cloud->size() + added);
  EXPECT_EQ(refined.polygons.size(), mesh.polygons.size() + 2 * added);
  std::size_t uses_added = 0;
  for (const auto& p : refined.polygons)
    for (const auto v : p.vertices) {
      ASSERT_LT(static_cast<std::size_t>(v), vertices.size());
      EXPECT_TRUE(static_cast<std::size_t>(v) >= cloud->size() || v % 2 == 1);
      uses_added += static_cast<std::size_t>(v) >= cloud->size();
    }
  EXPECT_GE(uses_added, 3 * added);
  for (std::size_t k = cloud->size(); k < vertices.size(); ++k)
    EXPECT_LT((vertices[k].getVector3fMap().cast<double>() - centre).norm(),
              2.0 * s.spacing);
  cocone.setRefineFilledHoles(false);

  cocone.setFillUndersampledHoles(false);
  cocone.reconstruct(mesh);
  cocone.getFilledHoles(rims);
  cocone.getBoundaryLoops(loops);
  EXPECT_TRUE(rims.empty());
  ASSERT_EQ(loops.size(), 2u);
  const auto& hole = loops[0].vertices.size() < loops[1].vertices.size()
                         ? loops[0].vertices
                         : loops[1].vertices;
  std::vector<int> a(hole.begin(), hole.end()), b = rim;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
}

TEST(CoConeBoundary, NoiseAndOutliers)
{
  // A noisy hemisphere (sigma half a spacing, random samples) and 5 points 10 radii
  // away.
  const auto s = cocone_test::hemisphere(cocone_test::options(6000, 0.5, 1, false));
  auto cloud = toCloud<pcl::PointXYZ>(s.points);
  cloud->header.frame_id = "scan";
  const int n = static_cast<int>(s.points.size());
  for (const auto& p : {pcl::PointXYZ(10, 0, 0.5f),
                        pcl::PointXYZ(-10, 0, 0.5f),
                        pcl::PointXYZ(0, 10, 0.5f),
                        pcl::PointXYZ(0, -10, 0.5f),
                        pcl::PointXYZ(0, 0, 10)})
    cloud->push_back(p);
  const std::vector<int> far = {n, n + 1, n + 2, n + 3, n + 4};

  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  EXPECT_TRUE(cocone.getNoiseHandling());
  cocone.setInputCloud(cloud);
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  ASSERT_GT(mesh.polygons.size(), 5000u);

  pcl::PointIndices outliers;
  cocone.getOutlierIndices(outliers);
  EXPECT_EQ(outliers.header.frame_id, "scan");
  EXPECT_TRUE(std::is_sorted(outliers.indices.begin(), outliers.indices.end()));
  for (const int i : far)
    EXPECT_TRUE(std::binary_search(outliers.indices.begin(), outliers.indices.end(), i))
        << i;
  // Outliers are in no triangle.
  std::vector<bool> is_outlier(cloud->size(), false);
  for (const int i : outliers.indices)
    is_outlier[i] = true;
  for (const auto& p : mesh.polygons)
    for (const auto v : p.vertices)
      ASSERT_FALSE(is_outlier[v]) << v;

  EXPECT_TRUE(cocone.isSmoothed());
  EXPECT_GE(cocone.getNoiseLevel(), 0.35);
  EXPECT_LE(cocone.getNoiseLevel(), 0.7);
  EXPECT_LT(cocone.getNoiseLevelAfterSmoothing(), 0.5 * cocone.getNoiseLevel());

  // A level per input point (all are finite and used).
  std::vector<float> levels;
  cocone.getPointNoiseLevels(levels);
  ASSERT_EQ(levels.size(), cloud->size());
  for (std::size_t i = 0; i < levels.size(); ++i)
    EXPECT_TRUE(std::isfinite(levels[i])) << i;

  // The smoothed cloud: finite where used, NaN at the outliers, near the input and
  // nearer the true surface than the noisy points.
  pcl::PointCloud<pcl::PointXYZ> smoothed;
  cocone.getSmoothedCloud(smoothed);
  ASSERT_EQ(smoothed.size(), cloud->size());
  EXPECT_EQ(smoothed.header.frame_id, "scan");
  double input_error = 0.0, smoothed_error = 0.0;
  for (int i = 0; i < static_cast<int>(cloud->size()); ++i) {
    if (is_outlier[i]) {
      EXPECT_FALSE(pcl::isFinite(smoothed[i])) << i;
      continue;
    }
    ASSERT_TRUE(pcl::isFinite(smoothed[i])) << i;
    EXPECT_LT((smoothed[i].getVector3fMap() - (*cloud)[i].getVector3fMap()).norm(),
              3.0 * s.spacing)
        << i;
    input_error += s.distance((*cloud)[i].getVector3fMap().cast<double>());
    smoothed_error += s.distance(smoothed[i].getVector3fMap().cast<double>());
  }
  EXPECT_LT(smoothed_error, 0.5 * input_error);

  // Normals: NaN at the outliers.
  pcl::PointCloud<pcl::Normal> normals;
  cocone.getPointNormals(normals);
  for (const int i : far)
    EXPECT_FALSE(std::isfinite(normals[i].normal_x)) << i;

  // setIndices on a subset (every other hemisphere point and the far ones): the
  // outliers are still indices into the input cloud, among those selected.
  pcl::IndicesPtr indices(new pcl::Indices);
  for (int i = 0; i < n; i += 2)
    indices->push_back(i);
  indices->insert(indices->end(), far.begin(), far.end());
  std::vector<bool> selected(cloud->size(), false);
  for (const int i : *indices)
    selected[i] = true;
  cocone.setIndices(indices);
  cocone.reconstruct(mesh);
  ASSERT_GT(mesh.polygons.size(), 2000u);
  cocone.getOutlierIndices(outliers);
  for (const int i : far)
    EXPECT_TRUE(std::binary_search(outliers.indices.begin(), outliers.indices.end(), i))
        << i;
  for (const int i : outliers.indices)
    EXPECT_TRUE(selected[i]) << i;
  cocone.getPointNoiseLevels(levels);
  cocone.getSmoothedCloud(smoothed);
  ASSERT_EQ(levels.size(), cloud->size());
  ASSERT_EQ(smoothed.size(), cloud->size());
  is_outlier.assign(cloud->size(), false);
  for (const int i : outliers.indices)
    is_outlier[i] = true;
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(std::isfinite(levels[i]), selected[i]) << i;
    EXPECT_EQ(pcl::isFinite(smoothed[i]), selected[i] && !is_outlier[i]) << i;
  }

  // Without noise handling: no outliers, no smoothing, no levels; the smoothed cloud
  // is the input.
  pcl::CoConeBoundary<pcl::PointXYZ> plain;
  plain.setNoiseHandling(false);
  EXPECT_FALSE(plain.getNoiseHandling());
  plain.setInputCloud(cloud);
  plain.reconstruct(mesh);
  ASSERT_GT(mesh.polygons.size(), 5000u);
  plain.getOutlierIndices(outliers);
  EXPECT_TRUE(outliers.indices.empty());
  EXPECT_FALSE(plain.isSmoothed());
  EXPECT_EQ(plain.getNoiseLevel(), 0.0);
  plain.getPointNoiseLevels(levels);
  ASSERT_EQ(levels.size(), cloud->size());
  EXPECT_TRUE(std::none_of(
      levels.begin(), levels.end(), [](float l) { return std::isfinite(l); }));
  plain.getSmoothedCloud(smoothed);
  ASSERT_EQ(smoothed.size(), cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i)
    EXPECT_EQ(smoothed[i].getVector3fMap(), (*cloud)[i].getVector3fMap()) << i;
}
