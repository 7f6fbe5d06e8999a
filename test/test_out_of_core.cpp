/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Out-of-core reconstruction (runOutOfCore()) against the in-memory tiling
 * (runTiled()) and one piece on generated surfaces.
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/out_of_core.h>
#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/tiling.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <support/cases.h>
#include <support/surfaces.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

using cocone_test::options;
using cocone_test::Sample;
using pcl::cocone::OutOfCoreResult;
using pcl::cocone::Parameters;
using pcl::cocone::Result;
using pcl::cocone::TilingOptions;
using pcl::cocone::Triangle;

namespace {

namespace fs = std::filesystem;

constexpr std::size_t POINTS = 30000;
constexpr std::size_t TILE_POINTS = 3000; // 16 tiles

/** The points of a vector, handed out in chunks; optionally failing on a pass. */
class VectorSource : public pcl::cocone::PointSource {
public:
  explicit VectorSource(const std::vector<Eigen::Vector3d>& points) : points_(points) {}

  bool
  rewind(std::string& error) override
  {
    ++passes;
    at_ = 0;
    if (fail_on_pass == passes) {
      error = "the source failed";
      return false;
    }
    return true;
  }

  bool
  read(std::vector<Eigen::Vector3d>& chunk, std::size_t max, std::string&) override
  {
    const std::size_t n = std::min(max, points_.size() - at_);
    chunk.assign(points_.begin() + static_cast<std::ptrdiff_t>(at_),
                 points_.begin() + static_cast<std::ptrdiff_t>(at_ + n));
    at_ += n;
    return true;
  }

  int passes = 0;
  int fail_on_pass = 0;

private:
  const std::vector<Eigen::Vector3d>& points_;
  std::size_t at_ = 0;
};

/** The mesh kept in memory. */
class VectorSink : public pcl::cocone::MeshSink {
public:
  bool
  begin(std::size_t v, std::size_t t, std::string& error) override
  {
    announced = {v, t};
    if (fail) {
      error = "the sink failed";
      return false;
    }
    return true;
  }

  bool
  addVertices(const std::vector<Eigen::Vector3d>& p,
              const std::vector<Eigen::Vector3d>& n,
              const std::vector<int>& i,
              std::string&) override
  {
    ids.insert(ids.end(), i.begin(), i.end());
    positions.insert(positions.end(), p.begin(), p.end());
    normals.insert(normals.end(), n.begin(), n.end());
    return true;
  }

  bool
  addTriangles(const std::vector<Triangle>& t, std::string&) override
  {
    triangles.insert(triangles.end(), t.begin(), t.end());
    return true;
  }

  bool
  end(std::string&) override
  {
    ended = true;
    return true;
  }

  bool fail = false, ended = false;
  std::array<std::size_t, 2> announced{};
  std::vector<Eigen::Vector3d> positions, normals;
  std::vector<int> ids;
  std::vector<Triangle> triangles;
};

Sample
surface(const std::string& name)
{
  if (name == "torus")
    return cocone_test::torus(options(POINTS, 0.0, 1.0, false));
  if (name == "sphere_with_holes")
    return cocone_test::sphereWithHoles(options(POINTS, 0.0, 1.0, false));
  if (name == "saddle")
    return cocone_test::monkeySaddle(options(POINTS, 0.0, 1.0, false));
  Sample s = cocone_test::torus(options(POINTS, 0.3, 1.0, false));
  s.name = "noisy_torus";
  return s;
}

/** Oriented triangles over ids, each starting at its lowest id, sorted. */
std::vector<Triangle>
canonical(std::vector<Triangle> t)
{
  for (auto& v : t)
    std::rotate(v.begin(), std::min_element(v.begin(), v.end()), v.end());
  std::sort(t.begin(), t.end());
  return t;
}

std::size_t
symmetricDifference(const std::vector<Triangle>& a, const std::vector<Triangle>& b)
{
  std::vector<Triangle> d;
  std::set_symmetric_difference(
      a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(d));
  return d.size();
}

/** A fresh directory for the work files. */
fs::path
workDirectory(const std::string& name)
{
  const fs::path d = fs::temp_directory_path() / ("cocone_out_of_core_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

class OutOfCore : public ::testing::TestWithParam<std::string> {};

/** On every point (the cut's sample is the whole cloud) the tiles are runTiled()'s,
 * so the stitch of their files must give runTiled()'s mesh: the same oriented
 * triangles, loops, labels and normals. */
TEST_P(OutOfCore, SameMeshAsTheInMemoryTiling)
{
  const Sample s = surface(GetParam());
  Parameters parameters;
  parameters.threads = 2;
  TilingOptions tiling;
  tiling.tile_points = TILE_POINTS;
  pcl::cocone::TilingReport report;
  const Result tiled = pcl::cocone::runTiled(s.points, parameters, tiling, {}, &report);
  ASSERT_TRUE(tiled.error.empty()) << tiled.error;

  VectorSource source(s.points);
  VectorSink sink;
  const fs::path dir = workDirectory(GetParam());
  const OutOfCoreResult r =
      pcl::cocone::runOutOfCore(source, parameters, tiling, dir.string(), sink);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(source.passes, 2);
  EXPECT_TRUE(sink.ended);
  EXPECT_TRUE(fs::is_empty(dir)) << "the work files are removed";
  EXPECT_EQ(sink.announced[0], sink.positions.size());
  EXPECT_EQ(sink.announced[1], sink.triangles.size());
  EXPECT_EQ(r.tiling.tiles, report.tiles);
  EXPECT_EQ(r.tiling.halo_points, report.halo_points);

  ASSERT_EQ(sink.ids.size(), tiled.positions.size());
  const std::vector<int>& id = sink.ids;
  std::size_t normals_differ = 0, positions_differ = 0;
  for (std::size_t v = 0; v < id.size(); ++v) {
    const int w = tiled.vertex_of_input[static_cast<std::size_t>(id[v])];
    ASSERT_GE(w, 0);
    ASSERT_EQ(tiled.representative[w], id[v]);
    positions_differ +=
        (tiled.positions[w] + tiled.offset - sink.positions[v]).norm() > 1e-9;
    const Eigen::Vector3d &a = tiled.normals[w], &b = sink.normals[v];
    normals_differ +=
        a.allFinite() != b.allFinite() || (a.allFinite() && (a - b).norm() > 1e-9);
  }
  std::vector<Triangle> ours = sink.triangles;
  for (auto& t : ours)
    for (int& v : t)
      v = id[v];
  const std::size_t differ =
      symmetricDifference(canonical(ours), canonical(tiled.polygons));
  std::vector<std::vector<int>> loops = tiled.border_loops;
  for (auto& loop : loops)
    std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end()), loop.end());
  std::sort(loops.begin(), loops.end());
  const auto topology = pcl::cocone::analyzeMesh(ours, s.points.size());
  std::printf("[ measured ] %-18s %zu tiles, %zu triangles (%zu in runTiled()), %zu "
              "oriented triangles differ, %zu normals differ; loops %zu (truth %d), "
              "Euler %ld (truth %d); work files at most %.1f MB\n",
              GetParam().c_str(),
              r.tiling.tiles,
              ours.size(),
              tiled.polygons.size(),
              differ,
              normals_differ,
              r.border_loops.size(),
              s.boundary_loops,
              topology.euler,
              s.euler,
              double(r.disk_bytes) / 1e6);
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(normals_differ, 0u);
  EXPECT_EQ(positions_differ, 0u);
  EXPECT_EQ(r.border_loops, loops);
  EXPECT_EQ(r.boundary_indices, tiled.boundary_indices);
  EXPECT_EQ(r.outlier_indices, tiled.outlier_indices);
  EXPECT_EQ(r.vertices, tiled.vertices);
  EXPECT_EQ(r.holes_filled, tiled.filled_holes.size());
  EXPECT_EQ(r.tiling.patches_flipped, report.patches_flipped);
  EXPECT_EQ(topology.euler, s.euler);
  EXPECT_EQ(r.euler, topology.euler);
  EXPECT_EQ(r.components, topology.components);
  EXPECT_EQ(static_cast<int>(r.border_loops.size()), s.boundary_loops);
  EXPECT_EQ(topology.nonmanifold_edges, 0u);
  EXPECT_EQ(topology.nonmanifold_vertices, 0u);
  EXPECT_EQ(topology.orientation_conflicts, 0u);
}

/** Cut on a sample (as for a cloud above OUT_OF_CORE_SAMPLE_POINTS): other tiles,
 * the same surface. */
TEST_P(OutOfCore, CutOnASampleGivesTheTopologyOfOnePiece)
{
  const Sample s = surface(GetParam());
  Parameters parameters;
  parameters.threads = 2;
  const Result one =
      pcl::cocone::run(s.points, parameters, pcl::cocone::Stages::RECONSTRUCTION);
  TilingOptions tiling;
  tiling.tile_points = TILE_POINTS;
  VectorSource source(s.points);
  VectorSink sink;
  const fs::path dir = workDirectory(GetParam() + "_sampled");
  const OutOfCoreResult r = pcl::cocone::runOutOfCore(
      source, parameters, tiling, dir.string(), sink, 4000); // stride 8
  ASSERT_TRUE(r.error.empty()) << r.error;
  const auto topology = pcl::cocone::analyzeMesh(sink.triangles, sink.positions.size());
  std::printf("[ measured ] %-18s sampled cut: %zu tiles, %zu triangles (one piece "
              "%zu), loops %zu, Euler %ld\n",
              GetParam().c_str(),
              r.tiling.tiles,
              sink.triangles.size(),
              one.polygons.size(),
              r.border_loops.size(),
              topology.euler);
  EXPECT_GE(r.tiling.tiles, 8u);
  EXPECT_LE(r.tiling.tiles, 32u);
  EXPECT_EQ(topology.euler, s.euler);
  EXPECT_EQ(r.euler, topology.euler);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(static_cast<int>(r.border_loops.size()), s.boundary_loops);
  EXPECT_EQ(topology.nonmanifold_edges + topology.nonmanifold_vertices +
                topology.orientation_conflicts,
            0u);
  EXPECT_NEAR(double(sink.triangles.size()),
              double(one.polygons.size()),
              0.005 * double(one.polygons.size()));
}

INSTANTIATE_TEST_SUITE_P(
    Surfaces,
    OutOfCore,
    ::testing::Values("torus", "sphere_with_holes", "saddle", "noisy_torus"),
    [](const auto& info) { return info.param; });

TEST(OutOfCoreInput, FailuresGiveAnErrorAndLeaveNoFile)
{
  const Sample s = cocone_test::torus(options(5000, 0.0, 1.0, false));
  Parameters parameters;
  TilingOptions tiling;
  tiling.tile_points = 1500;
  const fs::path dir = workDirectory("failures");
  {
    VectorSource source(s.points);
    VectorSink sink;
    TilingOptions small = tiling;
    small.tile_points = 10;
    const auto r =
        pcl::cocone::runOutOfCore(source, parameters, small, dir.string(), sink);
    EXPECT_NE(r.error.find("tile_points"), std::string::npos) << r.error;
    EXPECT_EQ(source.passes, 0);
  }
  {
    VectorSource source(s.points);
    VectorSink sink;
    const auto r = pcl::cocone::runOutOfCore(
        source, parameters, tiling, (dir / "missing").string(), sink);
    EXPECT_NE(r.error.find("no directory"), std::string::npos) << r.error;
  }
  for (const int pass : {1, 2}) {
    VectorSource source(s.points);
    source.fail_on_pass = pass;
    VectorSink sink;
    const auto r =
        pcl::cocone::runOutOfCore(source, parameters, tiling, dir.string(), sink);
    EXPECT_EQ(r.error, "the source failed");
    EXPECT_TRUE(fs::is_empty(dir));
  }
  {
    VectorSource source(s.points);
    VectorSink sink;
    sink.fail = true;
    const auto r =
        pcl::cocone::runOutOfCore(source, parameters, tiling, dir.string(), sink);
    EXPECT_EQ(r.error, "the sink failed");
    EXPECT_TRUE(fs::is_empty(dir));
  }
  {
    Parameters refine = parameters;
    refine.refine_filled_holes = true;
    VectorSource source(s.points);
    VectorSink sink;
    const auto r =
        pcl::cocone::runOutOfCore(source, refine, tiling, dir.string(), sink);
    EXPECT_FALSE(r.error.empty());
  }
  {
    // Non-finite points are read, counted and in no triangle.
    std::vector<Eigen::Vector3d> points = s.points;
    points.insert(points.begin() + 7,
                  Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
    VectorSource source(points);
    VectorSink sink;
    const auto r =
        pcl::cocone::runOutOfCore(source, parameters, tiling, dir.string(), sink);
    ASSERT_TRUE(r.error.empty()) << r.error;
    EXPECT_EQ(r.points, points.size());
    EXPECT_EQ(r.finite, points.size() - 1);
    EXPECT_EQ(pcl::cocone::analyzeMesh(sink.triangles, sink.positions.size()).euler, 0);
  }
}

} // namespace

namespace {

TEST(OutOfCoreTiling, TilesFitTheMemoryBesideTheCloud)
{
  using pcl::cocone::automaticOutOfCoreTiling;
  const std::size_t gb = std::size_t{1} << 30;
  bool fits = false;
  // 100M points in 8 GB with 2 threads: 2.4 GB for the cloud, two tiles of 1.6M
  // points (1,625 bytes per core point with its halo) in the rest.
  TilingOptions t = automaticOutOfCoreTiling(100000000, 8 * gb, 2, &fits);
  EXPECT_TRUE(fits);
  EXPECT_EQ(t.tile_points, 1600000u);
  EXPECT_EQ(t.tiles_in_flight, 2u);
  EXPECT_LE(100000000.0 * pcl::cocone::OUT_OF_CORE_BYTES_PER_POINT +
                t.tiles_in_flight * 1.25 * pcl::cocone::ONE_PIECE_BYTES_PER_POINT *
                    double(t.tile_points),
            8.0 * double(gb));
  // Room for one tile of the smallest size, not two: one in flight.
  const std::size_t one = 1000 * 24 + 1625 * 1500;
  t = automaticOutOfCoreTiling(1000, one, 2, &fits);
  EXPECT_TRUE(fits);
  EXPECT_EQ(t.tiles_in_flight, 1u);
  EXPECT_EQ(t.tile_points, 1250u);
  // Not even that: the smallest tiles, one at a time, and a warning flag.
  t = automaticOutOfCoreTiling(100000000, gb, 2, &fits);
  EXPECT_FALSE(fits);
  EXPECT_EQ(t.tile_points, pcl::cocone::MINIMUM_TILE_POINTS);
  EXPECT_EQ(t.tiles_in_flight, 1u);
  // Unknown memory: tiles of a million points, one per thread.
  t = automaticOutOfCoreTiling(100000000, 0, 2, &fits);
  EXPECT_TRUE(fits);
  EXPECT_EQ(t.tile_points, 1000000u);
  EXPECT_EQ(t.tiles_in_flight, 2u);
}

} // namespace
