/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Reconstruction (stages 1-7) on surfaces with known topology.
 */

#include <pcl/surface/cocone/border_classification.h>
#include <pcl/surface/cocone/handle_removal.h>
#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/hole_reopening.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/repair.h>
#include <pcl/surface/cocone/triangulation.h>
#include <pcl/surface/cocone/voronoi_cell.h>
#include <pcl/surface/cocone/walk.h>

#include <gtest/gtest.h>

#include <support/cases.h>
#include <support/expect.h>
#include <support/metrics.h>
#include <support/surfaces.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numeric>
#include <ostream>
#include <random>
#include <set>
#include <tuple>

using cocone_test::options;
using cocone_test::paper;
using cocone_test::Sample;
using cocone_test::SampleOptions;
using pcl::cocone::Parameters;
using pcl::cocone::Result;

namespace {

struct Outcome {
  Result result;
  cocone_test::MeshScore mesh;
  cocone_test::BoundaryScore boundary;
};

Outcome
reconstruct(const Sample& s, Parameters parameters = Parameters(), const char* tag = "")
{
  Outcome run;
  run.result =
      pcl::cocone::run(s.points, parameters, pcl::cocone::Stages::RECONSTRUCTION);
  EXPECT_TRUE(run.result.error.empty()) << run.result.error;
  run.mesh = cocone_test::scoreMesh(s, run.result);
  run.boundary = cocone_test::scoreBoundary(s, run.result.boundary_indices);
  const auto& c = run.result.counts;
  std::printf(
      "[ measured ] %-18s %s %s rho %.2f%s: %s; boundary %s; repair dropped %zu "
      "(edges %zu, vertices %zu, orientation %zu) filled %zu\n",
      s.name.c_str(),
      tag,
      parameters.ratio > 0.0 ? "paper" : "auto",
      run.result.ratio,
      parameters.boundary_detection ? "" : " (plain Co-cone)",
      run.mesh.str().c_str(),
      run.boundary.str().c_str(),
      c.repair.dropped(),
      c.repair.nonmanifold_edge,
      c.repair.nonmanifold_vertex,
      c.repair.orientation,
      c.repair.filled);
  // Whatever the input, the output is an oriented 2-manifold with boundary.
  EXPECT_TRUE(run.mesh.topology.manifold()) << s.name << ": " << run.mesh.str();
  return run;
}

/** Append a band of 2 n triangles 0.6 wide about a circle of \a radius centred at
 * (x, 0, 0) in the plane z = 0: an annulus, or with \a twist a Moebius strip. */
void
addBand(std::vector<Eigen::Vector3d>& P,
        std::vector<pcl::cocone::Triangle>& mesh,
        int n,
        double x,
        double radius,
        bool twist)
{
  const int first = static_cast<int>(P.size());
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * M_PI * i / n;
    const Eigen::Vector3d radial(std::cos(t), std::sin(t), 0.0);
    const double turn = twist ? t / 2.0 : 0.0;
    const Eigen::Vector3d across =
        std::cos(turn) * radial + std::sin(turn) * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d centre = Eigen::Vector3d(x, 0.0, 0.0) + radius * radial;
    P.push_back(centre + 0.3 * across);
    P.push_back(centre - 0.3 * across);
  }
  for (int i = 0; i < n; ++i) {
    int a = first + 2 * ((i + 1) % n), b = a + 1;
    if (twist && i == n - 1)
      std::swap(a, b);
    const int c = first + 2 * i;
    mesh.push_back({c, c + 1, a});
    mesh.push_back({c + 1, b, a});
  }
}

/** Bands of 2 n triangles each (addBand()): an annulus about the origin, a Moebius
 * strip beside it, then, with three, a second annulus around the first. */
struct Bands {
  std::vector<Eigen::Vector3d> points;
  std::vector<pcl::cocone::Triangle> triangles;
};

Bands
bands(int n, int count)
{
  Bands b;
  addBand(b.points, b.triangles, n, 0.0, 1.0, false);
  addBand(b.points, b.triangles, n, 3.0, 1.0, true);
  if (count > 2)
    addBand(b.points, b.triangles, n, 0.0, 2.0, false);
  return b;
}

using Generator = std::function<Sample(const SampleOptions&)>;

struct ClosedCase {
  const char* name;
  Generator make;
  long euler;
};

const ClosedCase CLOSED_SURFACES[] = {
    {"sphere", [](const SampleOptions& o) { return cocone_test::sphere(o); }, 2},
    {"ellipsoid", [](const SampleOptions& o) { return cocone_test::ellipsoid(o); }, 2},
    {"torus", [](const SampleOptions& o) { return cocone_test::torus(o); }, 0},
};

/** Open surfaces with their number of border loops and the recall of the final
 * boundary list reached with the paper's fixed rho = 1.5 (clean, density 1:4). The
 * library's default (automatic rho and spacing test) reaches 0.95 on all; lower
 * floors are measured shortfalls of the fixed ratio (test_detection_surfaces.cpp). */
struct OpenCase {
  const char* name;
  Generator make;
  std::size_t loops;
  double paper_recall_clean, paper_recall_uneven;
};

void
PrintTo(const OpenCase& c, std::ostream* os)
{
  *os << c.name;
}

void
PrintTo(const ClosedCase& c, std::ostream* os)
{
  *os << c.name;
}

const OpenCase OPEN_SURFACES[] = {
    {"hemisphere",
     [](const SampleOptions& o) { return cocone_test::hemisphere(o); },
     1,
     0.95,
     0.95},
    {"monkey_saddle",
     [](const SampleOptions& o) { return cocone_test::monkeySaddle(o); },
     1,
     0.95,
     0.95},
    {"open_cylinder",
     [](const SampleOptions& o) { return cocone_test::openCylinder(o); },
     2,
     0.95,
     0.95},
    {"curved_sheet",
     [](const SampleOptions& o) { return cocone_test::curvedSheet(o); },
     1,
     0.70,
     0.72},
    {"scan_line_sheet",
     [](const SampleOptions& o) { return cocone_test::scanLineSheet(o); },
     1,
     0.95,
     0.92},
};

class ClosedSurface : public ::testing::TestWithParam<ClosedCase> {};
class OpenSurface : public ::testing::TestWithParam<OpenCase> {};

} // namespace

TEST_P(ClosedSurface, ClosedOutwardMesh)
{
  const auto s = GetParam().make(options(10000));
  const Outcome run = reconstruct(s);
  EXPECT_EQ(run.mesh.topology.boundary_edges, 0u);
  EXPECT_EQ(run.mesh.topology.euler, GetParam().euler);
  EXPECT_EQ(run.mesh.topology.components, 1u);
  EXPECT_GE(run.mesh.used_share, 0.995);
  EXPECT_GT(run.mesh.volume, 0.0);
  EXPECT_LE(run.boundary.reported_share, 0.005);
  EXPECT_LT(run.mesh.max_distance, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Reconstruction,
                         ClosedSurface,
                         ::testing::ValuesIn(CLOSED_SURFACES),
                         [](const auto& info) { return std::string(info.param.name); });

TEST_P(OpenSurface, KeepsTheBordersOpen)
{
  const auto s = GetParam().make(options(10000));
  const Outcome run = reconstruct(s);
  EXPECT_EQ(run.mesh.loops, GetParam().loops);
  EXPECT_EQ(run.mesh.topology.components, 1u);
  EXPECT_EQ(run.mesh.topology.euler, 2 - static_cast<long>(GetParam().loops));
  // No triangle spans a hole or cuts through the volume.
  EXPECT_LT(run.mesh.max_distance, 1.0);
  EXPECT_GE(run.mesh.used_share, 0.99);
  // Euler: triangles = 2 V - (border vertices) - 2 chi, about twice the points.
  EXPECT_NEAR(double(run.mesh.topology.triangles) / double(s.points.size()), 2.0, 0.1);
  EXPECT_GE(run.boundary.recall, 0.95);
  EXPECT_GE(run.boundary.precision, 0.90);
}

TEST_P(OpenSurface, PaperRatio)
{
  const auto s = GetParam().make(options(10000));
  const Outcome run = reconstruct(s, paper());
  EXPECT_EQ(run.mesh.loops, GetParam().loops);
  EXPECT_LT(run.mesh.max_distance, 1.0);
  EXPECT_GE(run.mesh.used_share, 0.99);
  EXPECT_GE(run.boundary.recall, GetParam().paper_recall_clean);
  EXPECT_GE(run.boundary.precision, 0.90);
  const auto uneven = GetParam().make(options(10000, 0.0, 4.0));
  const Outcome u = reconstruct(uneven, paper(), "density 1:4");
  EXPECT_EQ(u.mesh.loops, GetParam().loops);
  EXPECT_GE(u.boundary.recall, GetParam().paper_recall_uneven);
}

TEST_P(OpenSurface, UnevenDensity)
{
  const auto s = GetParam().make(options(10000, 0.0, 4.0));
  const Outcome run = reconstruct(s, Parameters(), "density 1:4");
  EXPECT_EQ(run.mesh.loops, GetParam().loops);
  EXPECT_LT(run.mesh.max_distance, 1.5);
  EXPECT_GE(run.boundary.recall, 0.95);
  EXPECT_GE(run.boundary.precision, 0.90);
}

TEST_P(OpenSurface, PlainCoconeCoversTheBorders)
{
  // Without boundary detection every vertex chooses triangles, also at the border,
  // where the Voronoi cells are not flat: the paper's Figures 2, 11 and 12.
  const auto s = GetParam().make(options(10000));
  Parameters plain;
  plain.boundary_detection = false;
  const Outcome without = reconstruct(s, plain);
  const Outcome with = reconstruct(s, paper());
  // Boundary detection never makes it worse, and somewhere makes a difference.
  EXPECT_LE(with.mesh.max_distance, without.mesh.max_distance + 1e-9);
  // Without boundary points pruning must still not erode the surface.
  EXPECT_GE(without.mesh.used_share, 0.99);
  RecordProperty("plain_max_distance", std::to_string(without.mesh.max_distance));
}

INSTANTIATE_TEST_SUITE_P(Reconstruction,
                         OpenSurface,
                         ::testing::ValuesIn(OPEN_SURFACES),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(Reconstruction, PlainCoconeCoversTheHemisphere)
{
  // The hemisphere's opening is a flat disk of convex-hull triangles: the plain
  // Co-cone closes it (or covers it with triangles far from the surface).
  const auto s = cocone_test::hemisphere(options(10000));
  Parameters plain;
  plain.boundary_detection = false;
  const Outcome without = reconstruct(s, plain);
  const Outcome with = reconstruct(s, paper());
  EXPECT_EQ(with.mesh.loops, 1u);
  EXPECT_TRUE(without.mesh.loops == 0 || without.mesh.max_distance > 2.0)
      << without.mesh.str();
}

TEST(Reconstruction, MonkeySaddleLikeThePaper)
{
  // The paper: 10,000 points, 19,600 triangles, a single boundary.
  const auto s = cocone_test::monkeySaddle(options(10000));
  const Outcome run = reconstruct(s);
  EXPECT_EQ(run.mesh.loops, 1u);
  EXPECT_NEAR(double(run.mesh.topology.triangles), 19600.0, 400.0);
}

TEST(Reconstruction, ThreeComponents)
{
  const auto s = cocone_test::threeComponents(options(12000));
  const Outcome run = reconstruct(s);
  EXPECT_EQ(run.mesh.topology.components, 3u);
  EXPECT_EQ(run.mesh.loops, 4u);
  EXPECT_LT(run.mesh.max_distance, 1.0);
  EXPECT_GE(run.mesh.used_share, 0.99);
  EXPECT_GE(run.boundary.recall, 0.95);
  EXPECT_GE(run.boundary.precision, 0.90);
}

TEST(Reconstruction, SphereWithHoles)
{
  const auto s = cocone_test::sphereWithHoles(options(10000), 3, 0.5);
  const Outcome open = reconstruct(s, paper(2.5));
  EXPECT_EQ(open.mesh.loops, 3u);
  EXPECT_EQ(open.mesh.topology.euler, -1);
  EXPECT_LT(open.mesh.max_distance, 1.0);
  // At rho = 1.5 the rims look flat and the convex-hull triangles over the holes
  // are chosen: the holes are covered (the limitation a later rule removes).
  const Outcome covered = reconstruct(s, paper(1.5));
  EXPECT_LT(covered.mesh.loops, 3u);
  EXPECT_GT(covered.mesh.max_distance, 2.0);
  // The automatic mode opens them with no parameter.
  const Outcome automatic = reconstruct(s);
  EXPECT_EQ(automatic.mesh.loops, 3u);
  EXPECT_EQ(automatic.mesh.topology.euler, -1);
  EXPECT_LT(automatic.mesh.max_distance, 1.0);
}

TEST(Reconstruction, CandidateRules)
{
  // The notes' two readings of CANDIDATETRIANGLEEXTRACTION, on surfaces with borders
  // and holes (paper's test, rho 2.5 so that the holes' rims are boundary).
  for (const auto& s : {cocone_test::sphereWithHoles(options(10000), 3, 0.5),
                        cocone_test::hemisphere(options(10000)),
                        cocone_test::monkeySaddle(options(10000))}) {
    Parameters literal = paper(2.5);
    literal.candidate_rule = pcl::cocone::CandidateRule::LITERAL;
    const Outcome a = reconstruct(s, paper(2.5), "interior chooses");
    const Outcome b = reconstruct(s, literal, "literal");
    // The literal rule keeps Delaunay triangles of three boundary vertices: across
    // holes, through the volume; the repair has to drop them and some stay.
    EXPECT_LT(a.mesh.max_distance, 1.0) << s.name;
    EXPECT_LE(a.result.counts.repair.dropped(), b.result.counts.repair.dropped())
        << s.name;
    EXPECT_LE(a.mesh.max_distance, b.mesh.max_distance) << s.name;
    EXPECT_EQ(a.mesh.loops, std::size_t(s.boundary_loops)) << s.name;
  }
}

TEST(Reconstruction, NoisyClosedSurface)
{
  // Noise of 15 % of the spacing: a few spurious holes after the repair.
  const auto s = cocone_test::torus(options(10000, 0.15));
  const Outcome run = reconstruct(s);
  EXPECT_LE(run.mesh.loops, 5u);
  EXPECT_GE(run.mesh.used_share, 0.95);
}

TEST(Repair, FilledHolesLeaveAnOrientedManifold)
{
  // A bumpy 12 x 12 grid sheet, two triangles per square, oriented alike.
  const int side = 12;
  std::vector<Eigen::Vector3d> P;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      P.emplace_back(i, j, 0.2 * std::sin(0.7 * i) * std::cos(0.5 * j));
  const auto id = [&](int i, int j) { return i * side + j; };
  std::vector<pcl::cocone::Triangle> all;
  for (int i = 0; i + 1 < side; ++i)
    for (int j = 0; j + 1 < side; ++j) {
      all.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      all.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  std::vector<pcl::cocone::Triangle> allowed = all;
  for (auto& t : allowed)
    std::sort(t.begin(), t.end());
  std::sort(allowed.begin(), allowed.end());
  // Holes: one triangle (3 edges), one square (4 edges), and the six triangles
  // around vertex (7, 7) (6 edges, but no allowed triangle spans it: stays open).
  const auto has = [](const pcl::cocone::Triangle& t, int v) {
    return std::find(t.begin(), t.end(), v) != t.end();
  };
  std::vector<pcl::cocone::Triangle> mesh;
  for (std::size_t k = 0; k < all.size(); ++k) {
    const auto& t = all[k];
    const bool one = k == 2 * (2 * (side - 1) + 2);  // square (2, 2)
    const bool square = k / 2 == 4 * (side - 1) + 6; // square (4, 6)
    const bool fan = has(t, id(7, 7));               // around (7, 7)
    if (!one && !square && !fan)
      mesh.push_back(t);
  }
  // As in the pipeline: repaired (here: turned to face outward), then filled.
  pcl::cocone::RepairCounts counts;
  pcl::cocone::repairManifold(P, mesh, counts);
  EXPECT_EQ(counts.dropped(), 0u);
  counts = {};
  const auto is_allowed = [&](const pcl::cocone::Triangle& t) {
    return std::binary_search(allowed.begin(), allowed.end(), t);
  };
  EXPECT_EQ(pcl::cocone::fillHoles(P, mesh, is_allowed, 6), 3u);
  const auto topology = pcl::cocone::analyzeMesh(mesh, P.size());
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(pcl::cocone::boundaryLoops(mesh, P.size()).size(), 2u); // outer, (7, 7)
  // A repair finds nothing left to do.
  const auto filled = mesh;
  pcl::cocone::repairManifold(P, mesh, counts);
  EXPECT_EQ(mesh, filled);
  EXPECT_EQ(counts.dropped(), 0u);
  EXPECT_EQ(counts.flipped, 0u);
}

TEST(Repair, IncidencesHandedOnMatchTheTriangles)
{
  const auto s = cocone_test::monkeySaddle(options(5000, 0.05));
  const Result r =
      pcl::cocone::run(s.points, Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_GT(r.triangles.size(), 5000u);
  using pcl::cocone::EdgeIncidences;
  const auto expect_grouped = [](const EdgeIncidences& inc,
                                 const std::vector<pcl::cocone::Triangle>& mesh) {
    const EdgeIncidences fresh(mesh);
    EXPECT_EQ(inc.edges, fresh.edges);
    EXPECT_EQ(inc.first, fresh.first);
    EXPECT_EQ(inc.triangle, fresh.triangle);
    EXPECT_EQ(inc.forward, fresh.forward);
  };
  // Every seventh triangle dropped, every fifth of the others turned over: the
  // repair turns them back.
  std::vector<pcl::cocone::Triangle> mesh, allowed;
  for (std::size_t t = 0; t < r.triangles.size(); ++t) {
    auto v = r.triangles[t];
    std::sort(v.begin(), v.end());
    allowed.push_back(v);
    if (t % 7 != 3) {
      v = r.triangles[t];
      if (t % 5 == 0)
        std::swap(v[1], v[2]);
      mesh.push_back(v);
    }
  }
  std::sort(allowed.begin(), allowed.end());
  pcl::cocone::RepairCounts counts;
  EdgeIncidences inc;
  pcl::cocone::repairManifold(r.positions, mesh, counts, 1, &inc);
  EXPECT_GT(counts.flipped, 0u);
  expect_grouped(inc, mesh);
  // The ribbons' step takes them on and hands on those of what it leaves.
  auto unfilled = mesh;
  EdgeIncidences kept = inc;
  pcl::cocone::dropRibbons(unfilled, r.positions.size(), &kept);
  expect_grouped(kept, unfilled);
  // Filling the holes adds the new triangles' incidences to them, as a grouping of
  // the filled mesh from scratch would have them.
  // Loops up to six edges: some holes take diagonals, edges the mesh had not.
  const std::size_t edges_before = inc.edges.size();
  const auto is_allowed = [&](const pcl::cocone::Triangle& t) {
    return std::binary_search(allowed.begin(), allowed.end(), t);
  };
  ASSERT_GT(pcl::cocone::fillHoles(r.positions, mesh, is_allowed, 6, &inc), 0u);
  EXPECT_GT(inc.edges.size(), edges_before);
  expect_grouped(inc, mesh);
  pcl::cocone::dropRibbons(mesh, r.positions.size(), &inc);
  expect_grouped(inc, mesh);
  EXPECT_EQ(pcl::cocone::boundaryLoops(inc, r.positions.size()),
            pcl::cocone::boundaryLoops(mesh, r.positions.size()));
}

TEST(Repair, IncidencesAddedRemovedAndThreadedAsIfGroupedAgain)
{
  using pcl::cocone::EdgeIncidences;
  using pcl::cocone::Triangle;
  const auto expect_same = [](const EdgeIncidences& a, const EdgeIncidences& b) {
    EXPECT_EQ(a.edges, b.edges);
    EXPECT_EQ(a.first, b.first);
    EXPECT_EQ(a.triangle, b.triangle);
    EXPECT_EQ(a.forward, b.forward);
  };
  std::mt19937 rng(7);
  // Random triangles over few vertices: most edges have several triangles, some
  // added ones meet old edges, some make new ones, before and after the old ones.
  const auto random_triangles = [&](std::size_t count, int vertices) {
    std::vector<Triangle> out;
    std::uniform_int_distribution<int> vertex(0, vertices - 1);
    while (out.size() < count) {
      const Triangle t{vertex(rng), vertex(rng), vertex(rng)};
      if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        out.push_back(t);
    }
    return out;
  };
  for (int trial = 0; trial < 300; ++trial) {
    const int vertices = 4 + trial % 40;
    std::vector<Triangle> mesh = random_triangles(trial % 50, vertices);
    const std::size_t old = mesh.size();
    const auto more = random_triangles(trial % 7, vertices + 3);
    mesh.insert(mesh.end(), more.begin(), more.end());
    EdgeIncidences grown(std::vector<Triangle>(mesh.begin(), mesh.begin() + old));
    grown.add(mesh, old);
    expect_same(grown, EdgeIncidences(mesh));

    std::vector<std::uint8_t> dropped(mesh.size());
    std::vector<Triangle> kept;
    for (std::size_t t = 0; t < mesh.size(); ++t) {
      dropped[t] = (rng() % 3 == 0) || trial % 11 == 0;
      if (!dropped[t])
        kept.push_back(mesh[t]);
    }
    grown.remove(dropped);
    expect_same(grown, EdgeIncidences(kept));
  }
  // Large enough for several threads to group parts of it.
  const auto large = random_triangles(200000, 30000);
  expect_same(EdgeIncidences(large, 3), EdgeIncidences(large, 1));
}

TEST(Walk, SameWalkAndIncidencesWithAnyThreadCount)
{
  // The co-cone triangles of a noisy saddle, all present: edges with three and more
  // triangles, of which the walk takes some; enough for three threads to find the
  // components and read the incidences in parts.
  const auto s = cocone_test::monkeySaddle(options(70000, 0.1));
  auto unique = pcl::cocone::makeUniquePoints(s.points);
  const auto dt = pcl::cocone::triangulate(std::move(unique.points));
  const auto cells = pcl::cocone::computeVoronoiCells(dt, 3.0 * M_PI / 8.0);
  std::vector<pcl::cocone::Triangle> triangles;
  for (const auto& t : cells.triangles)
    triangles.push_back(t.v);
  const pcl::cocone::TriangleComplex complex(dt.points, triangles);
  const std::vector<std::uint8_t> present(complex.numTriangles(), 1);
  const std::vector<std::uint8_t> boundary(dt.points.size(), 0);
  const auto walked = pcl::cocone::walk(complex, present, boundary);
  for (const int threads : {2, 3}) {
    const auto again = pcl::cocone::walk(complex, present, boundary, threads);
    EXPECT_EQ(again.triangles, walked.triangles) << threads;
    EXPECT_EQ(again.ids, walked.ids) << threads;
    EXPECT_EQ(again.components, walked.components) << threads;
    EXPECT_EQ(again.conflicts, walked.conflicts) << threads;
    EXPECT_EQ(again.reseeds, walked.reseeds) << threads;
  }
  ASSERT_EQ(walked.ids.size(), walked.triangles.size());
  ASSERT_GT(walked.triangles.size(), 10000u);
  ASSERT_LT(walked.triangles.size(), complex.numTriangles());
  const pcl::cocone::EdgeIncidences fresh(walked.triangles);
  std::size_t crowded = 0;
  for (std::size_t e = 0; e < fresh.edges.size(); ++e)
    crowded += fresh.count(e) > 2;
  EXPECT_GT(crowded, 0u);
  for (const int threads : {1, 3}) {
    const auto read = pcl::cocone::walkedIncidences(complex, walked, threads);
    EXPECT_EQ(read.edges, fresh.edges);
    EXPECT_EQ(read.first, fresh.first);
    EXPECT_EQ(read.triangle, fresh.triangle);
    EXPECT_EQ(read.forward, fresh.forward);
  }
}

TEST(Walk, TwistedBandHasOneConflict)
{
  // An annulus and a Moebius strip of 3,000 triangles each, as candidates: the walk
  // takes every triangle, the annulus oriented alike throughout, the strip with one
  // edge where its orientations meet the other way round.
  const int n = 1500;
  const auto [P, mesh] = bands(n, 2);
  const pcl::cocone::TriangleComplex complex(P, mesh);
  const std::vector<std::uint8_t> present(complex.numTriangles(), 1);
  const std::vector<std::uint8_t> boundary(P.size(), 0);
  for (const int threads : {1, 2}) {
    const auto walked = pcl::cocone::walk(complex, present, boundary, threads);
    EXPECT_EQ(walked.triangles.size(), mesh.size());
    EXPECT_EQ(walked.components, 2u);
    EXPECT_EQ(walked.conflicts, 1u);
    std::vector<pcl::cocone::Triangle> annulus;
    for (const auto& t : walked.triangles)
      if (t[0] < 2 * n)
        annulus.push_back(t);
    const auto topology = pcl::cocone::analyzeMesh(annulus, P.size());
    EXPECT_EQ(topology.orientation_conflicts, 0u);
    EXPECT_EQ(topology.components, 1u);
  }
}

TEST(Repair, BorderSliversArePeeledOneLayer)
{
  // A fan of a square grid's corner vertex, and along the bottom border a sample
  // just inside an edge between two border vertices: the triangle on that edge has
  // an obtuse angle at the sample, so it is peeled and the border passes through
  // the sample; a triangle whose apex is on the border is kept.
  //   bottom row: 0 (0,0), 1 (2,0), 2 (4,0); sample 3 (1,0.3) between 0 and 1;
  //   top row: 4 (0,2), 5 (2,2), 6 (4,2).
  const std::vector<Eigen::Vector3d> points = {
      {0, 0, 0}, {2, 0, 0}, {4, 0, 0}, {1, 0.3, 0}, {0, 2, 0}, {2, 2, 0}, {4, 2, 0}};
  std::vector<pcl::cocone::Triangle> mesh = {
      {0, 1, 3}, // on the border edge 0-1, obtuse at 3: peeled
      {0, 3, 4},
      {3, 1, 5},
      {3, 5, 4},
      {1, 2, 5}, // on the border edge 1-2, apex 5 on the border: kept
      {2, 6, 5}};
  pcl::cocone::EdgeIncidences incidences(mesh);
  auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
  ASSERT_EQ(loops.size(), 1u);
  const auto before = pcl::cocone::analyzeMesh(mesh, points.size());
  EXPECT_EQ(pcl::cocone::peelBorderSlivers(points, mesh, incidences, loops), 1u);
  EXPECT_EQ(mesh.size(), 5u);
  EXPECT_EQ(std::count(mesh.begin(), mesh.end(), pcl::cocone::Triangle{0, 1, 3}), 0);
  const auto after = pcl::cocone::analyzeMesh(mesh, points.size());
  EXPECT_TRUE(after.manifold());
  EXPECT_EQ(after.euler, before.euler);
  EXPECT_EQ(after.vertices, before.vertices);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_NE(std::find(loops[0].begin(), loops[0].end(), 3), loops[0].end());
  const pcl::cocone::EdgeIncidences fresh(mesh);
  EXPECT_EQ(incidences.edges, fresh.edges);
  EXPECT_EQ(loops, pcl::cocone::boundaryLoops(fresh, points.size()));
  // The exposed triangles 0-3-4 and 3-1-5 have their apexes on the border.
  EXPECT_EQ(pcl::cocone::peelBorderSlivers(points, mesh, incidences, loops), 0u);
}

TEST(Repair, BridgeAcrossAGapIsDroppedAndANarrowJoinKept)
{
  // Two square grids of spacing 1, the second `gap` beyond the first along x, joined
  // at their facing borders by a strip of two triangles (the walk's bridge between
  // two bodies a few spacings apart): the strip goes if its shared edge is longer
  // than 3 spacings, and stays where the grids are a spacing apart.
  const auto grids = [](double gap, std::vector<Eigen::Vector3d>& points) {
    constexpr int N = 6; // vertices per side
    points.clear();
    std::vector<pcl::cocone::Triangle> mesh;
    for (const double x0 : {0.0, N - 1 + gap}) {
      const int first = static_cast<int>(points.size());
      for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i)
          points.emplace_back(x0 + i, j, 0.0);
      const auto id = [first](int i, int j) { return first + j * N + i; };
      for (int j = 0; j + 1 < N; ++j)
        for (int i = 0; i + 1 < N; ++i) {
          mesh.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
          mesh.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    // The strip: the first grid's right border (i = N - 1) runs up, the second's
    // left border (i = 0) down; a2 -> a3 and b3 -> b2 are border edges.
    const int a2 = 2 * N + N - 1, a3 = 3 * N + N - 1, b2 = N * N + 2 * N,
              b3 = N * N + 3 * N;
    mesh.push_back({a3, a2, b2});
    mesh.push_back({a3, b2, b3});
    return mesh;
  };
  std::vector<Eigen::Vector3d> points;
  for (const double gap : {5.0, 1.0}) {
    std::vector<pcl::cocone::Triangle> mesh = grids(gap, points);
    const std::vector<double> spacing(points.size(), 1.0);
    ASSERT_EQ(pcl::cocone::analyzeMesh(mesh, points.size()).components, 1u);
    pcl::cocone::EdgeIncidences incidences(mesh);
    const std::size_t dropped =
        pcl::cocone::dropBridges(points, spacing, 3.0, mesh, &incidences);
    const auto after = pcl::cocone::analyzeMesh(mesh, points.size());
    EXPECT_TRUE(after.manifold());
    if (gap > 3.0) {
      EXPECT_EQ(dropped, 2u);
      EXPECT_EQ(after.components, 2u);
      EXPECT_EQ(pcl::cocone::boundaryLoops(mesh, points.size()).size(), 2u);
    }
    else {
      EXPECT_EQ(dropped, 0u);
      EXPECT_EQ(after.components, 1u);
    }
    const pcl::cocone::EdgeIncidences fresh(mesh);
    EXPECT_EQ(incidences.edges, fresh.edges);
    EXPECT_EQ(incidences.triangle, fresh.triangle);
  }
  // Without spacings nothing is judged.
  std::vector<pcl::cocone::Triangle> mesh = grids(5.0, points);
  EXPECT_EQ(pcl::cocone::dropBridges(points, {}, 3.0, mesh), 0u);
}

TEST(Repair, MoebiusStripIsCutWhereItCannotBeOriented)
{
  // A band of 2n triangles with a half twist: no orientation agrees all round, so
  // the orientation step grows it in Prim's order and drops a triangle at the seam.
  std::vector<Eigen::Vector3d> P;
  std::vector<pcl::cocone::Triangle> mesh;
  addBand(P, mesh, 40, 0.0, 1.0, true);
  pcl::cocone::RepairCounts counts;
  pcl::cocone::repairManifold(P, mesh, counts);
  EXPECT_GE(counts.orientation, 1u);
  EXPECT_LE(counts.dropped(), 3u);
  const auto topology = pcl::cocone::analyzeMesh(mesh, P.size());
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(topology.orientation_conflicts, 0u);
  EXPECT_EQ(topology.components, 1u);
}

TEST(Repair, OrientsEachComponentWithAnyThreadCount)
{
  // Long bands (enough triangles for the threads to share them): an annulus with
  // every third triangle turned over, a Moebius strip beside it, and a second
  // annulus around it. The annuli come out consistent (each turned to its positive
  // volume), the strip cut once, the same with one thread or two.
  const int n = 12000;
  auto [P, mesh] = bands(n, 3);
  for (std::size_t t = 0; t < mesh.size(); t += 6) // every third of the annuli's
    if (t < 2 * n || t >= 4 * n)
      std::swap(mesh[t][1], mesh[t][2]);
  std::vector<pcl::cocone::Triangle> two = mesh;
  pcl::cocone::RepairCounts counts, counts_two;
  pcl::cocone::repairManifold(P, mesh, counts);
  pcl::cocone::repairManifold(P, two, counts_two, 2);
  EXPECT_EQ(two, mesh);
  EXPECT_EQ(counts_two.flipped, counts.flipped);
  EXPECT_EQ(counts_two.orientation, counts.orientation);
  EXPECT_GE(counts.orientation, 1u);
  EXPECT_LE(counts.dropped(), 3u);
  EXPECT_GE(counts.flipped, static_cast<std::size_t>(2 * n / 3));
  const auto topology = pcl::cocone::analyzeMesh(mesh, P.size());
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(topology.orientation_conflicts, 0u);
  EXPECT_EQ(topology.components, 3u);
}

TEST(Reconstruction, SameOutputWhateverRanBefore)
{
  // A coarse random tube, whose holes the advancing front's patches close: CGAL's
  // advancing front broke ties by the addresses of its cells and front edges, so
  // the mesh changed with what the process had allocated before (here: another
  // reconstruction) and with the thread count.
  const auto s = cocone_test::tube(options(7000, 0.0, 1.0, false), 0.04);
  Parameters one;
  one.threads = 1;
  const Result a = pcl::cocone::run(s.points, one, pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_GT(a.counts.holes_filled, 0u);
  const auto other = cocone_test::tube(options(10000, 0.0, 1.0, false), 0.015);
  pcl::cocone::run(other.points, Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  for (const unsigned threads : {1u, 2u}) {
    Parameters p;
    p.threads = threads;
    const Result b = pcl::cocone::run(s.points, p, pcl::cocone::Stages::RECONSTRUCTION);
    EXPECT_EQ(b.polygons, a.polygons) << threads << " threads";
    EXPECT_EQ(b.counts.holes_filled, a.counts.holes_filled) << threads << " threads";
  }
}

TEST(Reconstruction, Deterministic)
{
  const auto s = cocone_test::monkeySaddle(options(5000, 0.05));
  const Result a =
      pcl::cocone::run(s.points, Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  const Result b =
      pcl::cocone::run(s.points, Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  EXPECT_EQ(a.polygons, b.polygons);
  EXPECT_EQ(a.boundary_indices, b.boundary_indices);
  // Whatever the number of threads.
  for (const unsigned threads : {0u, 2u, 3u}) {
    Parameters parallel;
    parallel.threads = threads;
    const Result p =
        pcl::cocone::run(s.points, parallel, pcl::cocone::Stages::RECONSTRUCTION);
    EXPECT_EQ(p.polygons, a.polygons) << threads << " threads";
    EXPECT_EQ(p.boundary_indices, a.boundary_indices) << threads << " threads";
  }
  // The input order does not matter: shuffle the points and map back.
  std::vector<int> order(s.points.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(11));
  std::vector<Eigen::Vector3d> shuffled;
  for (const int i : order)
    shuffled.push_back(s.points[i]);
  const Result c =
      pcl::cocone::run(shuffled, Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  std::vector<pcl::cocone::Triangle> mapped;
  for (auto t : c.polygons) {
    for (auto& v : t)
      v = order[v];
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    mapped.push_back(t);
  }
  std::vector<int> border;
  for (const int i : c.boundary_indices)
    border.push_back(order[i]);
  std::sort(border.begin(), border.end());
  EXPECT_EQ(border, a.boundary_indices);
  std::sort(mapped.begin(), mapped.end());
  std::vector<pcl::cocone::Triangle> original = a.polygons;
  for (auto& t : original)
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  std::sort(original.begin(), original.end());
  EXPECT_EQ(mapped, original);
}

TEST(HoleFilling, ClosesHolesAsNarrowAsTheSpacingAndKeepsWiderOnes)
{
  using pcl::cocone::EdgeIncidences;
  const cocone_test::Sample s = cocone_test::sphere(cocone_test::options(4000));
  const auto r = pcl::cocone::run(
      s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_TRUE(r.border_loops.empty());
  const std::size_t n = r.positions.size();
  // Per vertex the mean length of its edges, maximised over its neighbours (the
  // local spacing's definition over the mesh's edges).
  std::vector<double> length(n, 0.0), spacing(n, 0.0);
  std::vector<int> degree(n, 0);
  std::vector<std::vector<int>> ring(n);
  for (const auto& t : r.triangles)
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      length[a] += (r.positions[a] - r.positions[b]).norm();
      ++degree[a];
      ring[a].push_back(b);
    }
  for (std::size_t v = 0; v < n; ++v) {
    spacing[v] = length[v] / degree[v];
    for (const int w : ring[v])
      spacing[v] = std::max(spacing[v], length[w] / degree[w]);
  }
  // A hole cut around a vertex, its points left in place: 1.2 spacings in radius
  // (narrower than two local spacings) is closed, 5 is not.
  for (const double radius : {1.2, 5.0}) {
    SCOPED_TRACE(radius);
    const Eigen::Vector3d centre = r.positions[r.triangles[0][0]];
    std::vector<pcl::cocone::Triangle> mesh;
    for (const auto& t : r.triangles) {
      const Eigen::Vector3d c =
          (r.positions[t[0]] + r.positions[t[1]] + r.positions[t[2]]) / 3.0;
      if ((c - centre).norm() > radius * s.spacing)
        mesh.push_back(t);
    }
    EdgeIncidences inc(mesh);
    auto loops = pcl::cocone::boundaryLoops(inc, n);
    ASSERT_EQ(loops.size(), 1u);
    const std::size_t cut = mesh.size();
    const auto filled = pcl::cocone::fillUndersampledHoles(
        r.positions, spacing, mesh, inc, loops, 2.0, 1000);
    const auto topology = pcl::cocone::analyzeMesh(mesh, n);
    EXPECT_TRUE(topology.manifold());
    EXPECT_EQ(inc.edges, EdgeIncidences(mesh).edges);
    if (radius < 2.0) {
      EXPECT_EQ(filled.holes, 1u);
      EXPECT_TRUE(loops.empty());
      EXPECT_EQ(topology.boundary_edges, 0u);
      EXPECT_EQ(topology.euler, 2);
      EXPECT_EQ(mesh.size(), cut + filled.triangles);
    }
    else {
      EXPECT_EQ(filled.holes, 0u);
      EXPECT_EQ(loops.size(), 1u);
      EXPECT_EQ(mesh.size(), cut);
    }
  }
}

TEST(HoleFilling, RimTrianglesSetTheReachWhereTheSamplingIsFinerAlongTheRim)
{
  // Rows one unit apart, sampled every 0.2 along them: the local spacing (the mean
  // distance to the 6 nearest, 0.4) reads the rows, the triangles between them
  // (circumdiameter 1.02) the sampling across. A hole two rows tall and two units
  // wide needs an edge of 2 units (5 spacings): beyond a reach of 4 spacings, within
  // 5 rim-triangle diameters. One 8 units wide needs edges of more than 5.66 (half
  // its diagonal): beyond either.
  using pcl::cocone::EdgeIncidences;
  constexpr int columns = 61, rows = 13;
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i)
      points.emplace_back(0.2 * i, 1.0 * j, 0.0);
  const std::vector<double> spacing(points.size(), 0.4);
  const auto id = [&](int i, int j) { return j * columns + i; };
  struct Hole {
    double x0, y0, x1, y1;
    bool closed_by_rim;
  };
  for (const Hole& h :
       {Hole{4.0, 3.0, 6.0, 5.0, true}, Hole{2.0, 2.0, 10.0, 10.0, false}}) {
    SCOPED_TRACE(h.x1 - h.x0);
    std::vector<pcl::cocone::Triangle> mesh;
    for (int j = 0; j + 1 < rows; ++j)
      for (int i = 0; i + 1 < columns; ++i) {
        const double x = 0.2 * i + 0.1, y = j + 0.5; // the quad's centre
        if (x > h.x0 && x < h.x1 && y > h.y0 && y < h.y1)
          continue;
        mesh.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    for (const double rim_reach : {0.0, 5.0}) {
      SCOPED_TRACE(rim_reach);
      std::vector<pcl::cocone::Triangle> filled_mesh = mesh;
      EdgeIncidences inc(filled_mesh);
      auto loops = pcl::cocone::boundaryLoops(inc, points.size());
      ASSERT_EQ(loops.size(), 2u); // the grid's outline and the hole
      const auto filled =
          pcl::cocone::fillUndersampledHoles(points,
                                             spacing,
                                             filled_mesh,
                                             inc,
                                             loops,
                                             4.0,
                                             1000,
                                             {},
                                             pcl::cocone::HoleWeight::DIHEDRAL_ANGLES,
                                             rim_reach);
      const auto topology = pcl::cocone::analyzeMesh(filled_mesh, points.size());
      EXPECT_TRUE(topology.manifold());
      EXPECT_EQ(inc.edges, EdgeIncidences(filled_mesh).edges);
      const bool closed = h.closed_by_rim && rim_reach > 0.0;
      EXPECT_EQ(filled.holes, closed ? 1u : 0u);
      EXPECT_EQ(loops.size(), closed ? 1u : 2u);
    }
  }
}

TEST(HoleFilling, FlatSheetIsNotClosedByItsOtherSide)
{
  // A flat square grid: its outline's patch, whatever the reach, would lie on the
  // grid itself, folded flat back onto it, a closed piece of no volume. A bent
  // grid's outline (the corners raised out of the plane) is no such loop.
  using pcl::cocone::EdgeIncidences;
  constexpr int side = 6;
  for (const double lift : {0.0, 2.0}) {
    SCOPED_TRACE(lift);
    std::vector<Eigen::Vector3d> points;
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) {
        // Jittered in the plane, so that no three outline points are collinear.
        const double x = i - 2.5 + 0.2 * std::sin(7.0 * i + 3.0 * j),
                     y = j - 2.5 + 0.2 * std::cos(5.0 * i + 11.0 * j);
        points.emplace_back(x, y, lift * x * y / 6.25);
      }
    const std::vector<double> spacing(points.size(), 1.0);
    std::vector<pcl::cocone::Triangle> mesh;
    for (int j = 0; j + 1 < side; ++j)
      for (int i = 0; i + 1 < side; ++i) {
        const int a = j * side + i;
        mesh.push_back({a, a + 1, a + side + 1});
        mesh.push_back({a, a + side + 1, a + side});
      }
    EdgeIncidences inc(mesh);
    auto loops = pcl::cocone::boundaryLoops(inc, points.size());
    ASSERT_EQ(loops.size(), 1u);
    const auto filled = pcl::cocone::fillUndersampledHoles(
        points, spacing, mesh, inc, loops, 100.0, 1000);
    EXPECT_TRUE(pcl::cocone::analyzeMesh(mesh, points.size()).manifold());
    if (lift == 0.0) {
      EXPECT_EQ(filled.holes, 0u);
      EXPECT_EQ(loops.size(), 1u);
    }
    else {
      EXPECT_EQ(filled.holes, 1u);
      EXPECT_TRUE(loops.empty());
    }
  }
}

namespace {

/** A torus triangulated as a grid of \a around x \a along vertices (the tube's
 * circumference, the ring's), each quad split the same way: an oriented closed
 * mesh of genus 1, its meridians cycles of \a around edges. */
void
gridTorus(int around,
          int along,
          std::vector<Eigen::Vector3d>& points,
          std::vector<pcl::cocone::Triangle>& mesh)
{
  const double pi = std::acos(-1.0), ring = 0.2 * along, tube = 0.2 * around;
  points.clear();
  mesh.clear();
  for (int i = 0; i < along; ++i)
    for (int j = 0; j < around; ++j) {
      // Jittered, so that no three vertices are collinear.
      const double theta = 2.0 * pi * (i + 0.1 * std::sin(3.0 * i + 7.0 * j)) / along,
                   phi = 2.0 * pi * (j + 0.1 * std::cos(5.0 * i + 2.0 * j)) / around;
      points.emplace_back((ring + tube * std::cos(phi)) * std::cos(theta),
                          (ring + tube * std::cos(phi)) * std::sin(theta),
                          tube * std::sin(phi));
    }
  const auto id = [&](int i, int j) {
    return ((i + along) % along) * around + (j + around) % around;
  };
  for (int i = 0; i < along; ++i)
    for (int j = 0; j < around; ++j) {
      mesh.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
}

} // namespace

TEST(HandleCutting, HandleShortBothWaysIsCutAndTubesAreKept)
{
  // A handle with 3 samples round it and 8 along: no sample resolves it, cut (the
  // torus becomes a sphere). With 120 along it is a coarse tube (its meridians are
  // short, its way round long), and with 6 round a tunnel the sample resolves:
  // both kept. A hole elsewhere stays as it is.
  using pcl::cocone::EdgeIncidences;
  struct Case {
    int around, along;
    bool hole;
    std::size_t cut;
  };
  for (const Case c : {Case{3, 8, false, 1},
                       Case{3, 8, true, 1},
                       Case{3, 120, false, 0},
                       Case{6, 8, false, 0}}) {
    SCOPED_TRACE(std::to_string(c.around) + " round, " + std::to_string(c.along) +
                 " along" + (c.hole ? ", a hole" : ""));
    std::vector<Eigen::Vector3d> points;
    std::vector<pcl::cocone::Triangle> mesh;
    gridTorus(c.around, c.along, points, mesh);
    if (c.hole)
      mesh.erase(mesh.begin() + 4 * c.around, mesh.begin() + 4 * c.around + 2);
    const auto before = pcl::cocone::analyzeMesh(mesh, points.size());
    const auto loops = pcl::cocone::boundaryLoops(mesh, points.size());
    std::vector<std::vector<pcl::cocone::Triangle>> results;
    for (const int threads : {1, 2}) {
      std::vector<pcl::cocone::Triangle> cut_mesh = mesh;
      EdgeIncidences inc(cut_mesh);
      EXPECT_EQ(pcl::cocone::cutShortHandles(
                    points, cut_mesh, inc, pcl::cocone::MIN_TUNNEL_SAMPLES, threads),
                c.cut);
      const auto after = pcl::cocone::analyzeMesh(cut_mesh, points.size());
      EXPECT_TRUE(after.manifold());
      EXPECT_EQ(after.vertices, points.size()); // every vertex still in the mesh
      EXPECT_EQ(after.components, 1u);
      EXPECT_EQ(after.euler, before.euler + 2 * static_cast<long>(c.cut));
      // The borders unchanged, and the incidences those of the triangles.
      EXPECT_EQ(pcl::cocone::boundaryLoops(inc, points.size()), loops);
      EXPECT_EQ(inc.edges, EdgeIncidences(cut_mesh).edges);
      results.push_back(std::move(cut_mesh));
    }
    EXPECT_EQ(results[0], results[1]);
  }
}

TEST(HoleFilling, LoopsJoinedWhereTheOtherMeshJoinsThemThroughFreeSamples)
{
  // A grid torus whose tube lost two rows of triangles: a tube with two open rims,
  // the ring of samples between them in no triangle (a tunnel's wall the walk left
  // out). The other mesh, the whole torus, joins the two loops through them: with
  // join_loops the wall comes back and the genus with it; without, no patch of one
  // loop is a disk, so none is taken. A hole that one patch closes alone is not
  // taken with join_loops.
  const int around = 8, along = 16;
  std::vector<Eigen::Vector3d> points;
  std::vector<pcl::cocone::Triangle> torus;
  gridTorus(around, along, points, torus);
  std::vector<pcl::cocone::Triangle> tube;
  for (std::size_t t = 0; t < torus.size(); ++t) {
    const std::size_t row = t / (2 * around); // between rings row and row + 1
    if (row != 4 && row != 5)
      tube.push_back(torus[t]);
  }
  const std::vector<double> spacing(points.size(), 1.3);
  const auto sorted = [](std::vector<pcl::cocone::Triangle> mesh) {
    for (auto& t : mesh)
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    std::sort(mesh.begin(), mesh.end());
    return mesh;
  };
  for (const bool join : {false, true}) {
    SCOPED_TRACE(join ? "joining loops" : "one loop at a time");
    std::vector<pcl::cocone::Triangle> mesh = tube;
    pcl::cocone::EdgeIncidences incidences(mesh);
    auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
    ASSERT_EQ(loops.size(), 2u);
    const auto filled = pcl::cocone::fillHolesFromMesh(
        points, spacing, torus, mesh, incidences, loops, 2.75, 1000, 3, {}, join);
    if (!join) {
      EXPECT_EQ(filled.holes, 0u);
      EXPECT_EQ(mesh, tube);
      continue;
    }
    EXPECT_EQ(filled.holes, 2u);
    EXPECT_TRUE(loops.empty());
    EXPECT_EQ(sorted(mesh), sorted(torus));
    const auto topology = pcl::cocone::analyzeMesh(mesh, points.size());
    EXPECT_TRUE(topology.manifold());
    EXPECT_EQ(topology.euler, 0); // genus 1 again
    EXPECT_EQ(topology.components, 1u);
    EXPECT_EQ(topology.vertices, points.size());
    EXPECT_EQ(incidences.edges, pcl::cocone::EdgeIncidences(mesh).edges);
  }
  // One hole, closed by a patch of its own: left to the other passes.
  std::vector<pcl::cocone::Triangle> mesh = torus;
  mesh.erase(mesh.begin() + 4 * around, mesh.begin() + 4 * around + 2);
  const auto holed = mesh;
  pcl::cocone::EdgeIncidences incidences(mesh);
  auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
  EXPECT_EQ(
      pcl::cocone::fillHolesFromMesh(
          points, spacing, torus, mesh, incidences, loops, 2.75, 1000, 3, {}, true)
          .holes,
      0u);
  EXPECT_EQ(mesh, holed);
  EXPECT_EQ(
      pcl::cocone::fillHolesFromMesh(
          points, spacing, torus, mesh, incidences, loops, 2.75, 1000, 3, {}, false)
          .holes,
      1u);
}

TEST(HoleReopening, RingsRoundALoopGrowToTheWholeMesh)
{
  // A grid torus with one quad missing: its loop's first ring is the triangles with
  // a corner on it, each ring holds the one before, and enough rings reach every
  // triangle (the torus is one piece).
  const int around = 8, along = 16;
  std::vector<Eigen::Vector3d> points;
  std::vector<pcl::cocone::Triangle> mesh;
  gridTorus(around, along, points, mesh);
  mesh.erase(mesh.begin() + 4 * around, mesh.begin() + 4 * around + 2);
  const auto loops = pcl::cocone::boundaryLoops(mesh, points.size());
  ASSERT_EQ(loops.size(), 1u);
  const std::set<int> on_loop(loops[0].begin(), loops[0].end());
  std::vector<std::uint8_t> previous(mesh.size(), 0);
  for (int rings = 1; rings <= around + along; ++rings) {
    const auto within =
        pcl::cocone::trianglesRoundLoop(mesh, loops[0], rings, points.size());
    ASSERT_EQ(within.size(), mesh.size());
    for (std::size_t t = 0; t < mesh.size(); ++t) {
      EXPECT_LE(previous[t], within[t]); // each ring holds the one before
      if (rings == 1) {
        EXPECT_EQ(within[t] != 0,
                  on_loop.count(mesh[t][0]) + on_loop.count(mesh[t][1]) +
                          on_loop.count(mesh[t][2]) >
                      0);
      }
    }
    previous = within;
  }
  EXPECT_EQ(std::count(previous.begin(), previous.end(), 1),
            static_cast<std::ptrdiff_t>(mesh.size()));
}

TEST(HoleReopening, TheTrianglesLeftAreAManifold)
{
  // Holes of random shape in a grid torus (a blob of 4 to 40 triangles grown through
  // edges): the rings round a hole's loop can leave a vertex pinched between two
  // fans; trianglesRoundLoop() takes the rest of its star too, so what is left is
  // always an oriented manifold, holding the plain rings.
  const int around = 12, along = 24;
  std::vector<Eigen::Vector3d> points;
  std::vector<pcl::cocone::Triangle> torus;
  gridTorus(around, along, points, torus);
  const pcl::cocone::EdgeIncidences incidences(torus);
  std::mt19937 random(7);
  int holes = 0, widened = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // Grow the blob from a random triangle through random edges.
    std::vector<std::uint8_t> blob(torus.size(), 0);
    std::vector<std::size_t> grown = {random() % torus.size()};
    blob[grown[0]] = 1;
    const std::size_t size = 4 + random() % 37;
    while (grown.size() < size) {
      const pcl::cocone::Triangle& t = torus[grown[random() % grown.size()]];
      const int k = static_cast<int>(random() % 3);
      const std::size_t e = incidences.find(t[k], t[(k + 1) % 3]);
      for (std::size_t i = incidences.first[e]; i < incidences.first[e + 1]; ++i) {
        const std::size_t u = incidences.triangle[i];
        if (!blob[u]) {
          blob[u] = 1;
          grown.push_back(u);
        }
      }
    }
    std::vector<pcl::cocone::Triangle> mesh = torus;
    pcl::cocone::removeTriangles(mesh, blob);
    const auto loops = pcl::cocone::boundaryLoops(mesh, points.size());
    if (loops.size() != 1 || !pcl::cocone::analyzeMesh(mesh, points.size()).manifold())
      continue; // a blob pinching or splitting the torus is no one hole
    ++holes;
    for (int rings = 1; rings <= 3; ++rings) {
      const auto within =
          pcl::cocone::trianglesRoundLoop(mesh, loops[0], rings, points.size());
      // The plain rings.
      std::vector<std::uint8_t> reached(points.size(), 0);
      for (const int v : loops[0])
        reached[v] = 1;
      std::vector<std::uint8_t> plain(mesh.size(), 0);
      for (int ring = 0; ring < rings; ++ring) {
        std::vector<std::uint8_t> next = reached;
        for (std::size_t t = 0; t < mesh.size(); ++t)
          if (reached[mesh[t][0]] || reached[mesh[t][1]] || reached[mesh[t][2]]) {
            plain[t] = 1;
            next[mesh[t][0]] = next[mesh[t][1]] = next[mesh[t][2]] = 1;
          }
        reached = std::move(next);
      }
      std::vector<pcl::cocone::Triangle> left = mesh;
      pcl::cocone::removeTriangles(left, within);
      EXPECT_TRUE(pcl::cocone::analyzeMesh(left, points.size()).manifold())
          << "trial " << trial << ", " << rings << " rings";
      bool more = false;
      for (std::size_t t = 0; t < mesh.size(); ++t) {
        EXPECT_LE(plain[t], within[t]);
        more = more || within[t] > plain[t];
      }
      widened += more;
    }
  }
  EXPECT_GE(holes, 100);
  EXPECT_GT(widened, 0); // the pinches happen, or this test would not test them
}

TEST(HoleReopening, VerticesLeftOutAreInsertedIntoTheNewSurface)
{
  // A unit square of two triangles replaces the four round a centre vertex raised
  // by 0.3 (0.6 of its spacing): within a reach of 1 spacing, the centre goes back
  // into the triangle below it, split in three the same way round, and the mesh is
  // an oriented disk again; with a reach of 0.5 spacings, or no new triangle round
  // it, it stays out.
  const std::vector<Eigen::Vector3d> points = {
      {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.4, 0.6, 0.3}};
  const std::vector<pcl::cocone::Triangle> before = {
      {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  const std::vector<pcl::cocone::Triangle> square = {{0, 1, 2}, {0, 2, 3}};
  const std::vector<double> spacing(points.size(), 0.5);
  const std::vector<std::uint8_t> round(points.size(), 1);

  std::vector<pcl::cocone::Triangle> after = square;
  ASSERT_TRUE(pcl::cocone::insertLeftOut(points, spacing, before, after, round, 1.0));
  ASSERT_EQ(after.size(), 4U);
  EXPECT_EQ(after[0], square[0]); // the centre is above (0, 2, 3), not this one
  EXPECT_EQ(after[1], (pcl::cocone::Triangle{0, 2, 4}));
  EXPECT_EQ(after[2], (pcl::cocone::Triangle{2, 3, 4}));
  EXPECT_EQ(after[3], (pcl::cocone::Triangle{3, 0, 4}));
  const pcl::cocone::MeshTopology disk = pcl::cocone::analyzeMesh(after, points.size());
  EXPECT_TRUE(disk.manifold());
  EXPECT_EQ(disk.components, 1U);
  EXPECT_EQ(disk.euler, 1);
  EXPECT_EQ(disk.boundary_edges, 4U);

  after = square;
  EXPECT_FALSE(pcl::cocone::insertLeftOut(points, spacing, before, after, round, 0.5));
  EXPECT_EQ(after, square);
  EXPECT_FALSE(pcl::cocone::insertLeftOut(
      points, spacing, before, after, std::vector<std::uint8_t>(5, 0), 1.0));
  EXPECT_EQ(after, square);
  after = before; // nothing left out
  EXPECT_TRUE(pcl::cocone::insertLeftOut(points, spacing, before, after, round, 1.0));
  EXPECT_EQ(after, before);
}

TEST(HoleFilling, JoinedPatchesKeepAnOrientedManifold)
{
  // Grid tori with random rows and triangles taken out, the other mesh a torus with
  // triangles of its own taken out: whatever is joined or closed, the mesh stays an
  // oriented manifold whose incidences and loops are its own, every patch joining
  // loops adds one handle per loop it joins beyond the first.
  std::mt19937 random(11);
  std::size_t meshes = 0, handles = 0;
  for (int trial = 0; trial < 200; ++trial) {
    SCOPED_TRACE(trial);
    const int around = 4 + trial % 5, along = 8 + trial % 9;
    std::vector<Eigen::Vector3d> points;
    std::vector<pcl::cocone::Triangle> torus, mesh, other;
    gridTorus(around, along, points, torus);
    std::uniform_int_distribution<int> row(0, along - 1);
    std::vector<std::uint8_t> cut_row(static_cast<std::size_t>(along), 0);
    for (int k = 1 + trial % 3; k > 0; --k)
      cut_row[static_cast<std::size_t>(row(random))] = 1;
    std::bernoulli_distribution drop(0.03);
    for (std::size_t t = 0; t < torus.size(); ++t) {
      if (!cut_row[t / (2 * static_cast<std::size_t>(around))] && !drop(random))
        mesh.push_back(torus[t]);
      if (!drop(random))
        other.push_back(torus[t]);
    }
    const std::vector<double> spacing(points.size(), 1.3);
    const auto before = pcl::cocone::analyzeMesh(mesh, points.size());
    if (!before.manifold())
      continue; // a vertex whose triangles left two fans
    ++meshes;
    for (const bool join : {true, false}) {
      std::vector<pcl::cocone::Triangle> mesh_in = mesh;
      pcl::cocone::EdgeIncidences incidences(mesh_in);
      auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
      const std::size_t loops_before = loops.size();
      const auto filled = pcl::cocone::fillHolesFromMesh(
          points, spacing, other, mesh_in, incidences, loops, 2.75, 1000, 3, {}, join);
      const auto after = pcl::cocone::analyzeMesh(mesh_in, points.size());
      EXPECT_TRUE(after.manifold());
      EXPECT_EQ(incidences.edges, pcl::cocone::EdgeIncidences(mesh_in).edges);
      EXPECT_EQ(loops, pcl::cocone::boundaryLoops(mesh_in, points.size()));
      EXPECT_EQ(loops.size() + filled.holes, loops_before);
      // Each loop closed on its own adds one to the Euler characteristic; joined
      // loops add fewer (a handle each beyond the first), never more.
      EXPECT_LE(after.euler - before.euler, static_cast<long>(filled.holes));
      if (!join)
        EXPECT_EQ(after.euler - before.euler, static_cast<long>(filled.holes));
      else
        handles += static_cast<std::size_t>(static_cast<long>(filled.holes) -
                                            (after.euler - before.euler)) /
                   2;
    }
  }
  std::printf("[ measured ] %zu manifold tori, %zu handles made by joined patches\n",
              meshes,
              handles);
  EXPECT_GT(handles, 0u); // the cases exercise the joining
}

TEST(HoleFilling, PatchReplacesTheBandWhereTheMeshesDisagree)
{
  // A square grid of unit spacing cut along one diagonal, with a round hole, and
  // another mesh of the same points cut along the other diagonal: no patch of the
  // other mesh is bounded by the hole's loop (its diagonals are not the other
  // mesh's), so the band of triangles where they disagree is replaced with the
  // other mesh's, the hole closed; the grid's outer border, where the other mesh
  // ends too, stays.
  const int n = 16;
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      points.emplace_back(i, j, 0.0);
  const auto id = [&](int i, int j) { return j * n + i; };
  std::vector<pcl::cocone::Triangle> mesh, other;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      other.push_back({a, b, d});
      other.push_back({b, c, d});
      for (const pcl::cocone::Triangle& t :
           {pcl::cocone::Triangle{a, b, c}, pcl::cocone::Triangle{a, c, d}}) {
        // The hole: the triangles whose centroid is within 2.2 of the middle, so
        // that diagonals bound it.
        const Eigen::Vector3d centroid =
            (points[t[0]] + points[t[1]] + points[t[2]]) / 3.0 -
            Eigen::Vector3d(n / 2.0, n / 2.0, 0.0);
        if (centroid.norm() >= 2.2)
          mesh.push_back(t);
      }
    }
  const std::size_t cut = mesh.size();
  const std::vector<double> spacing(points.size(), 1.0);
  pcl::cocone::EdgeIncidences incidences(mesh);
  auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
  ASSERT_EQ(loops.size(), 2u);
  std::size_t hole_edges = 0;
  for (const auto& loop : loops)
    hole_edges = std::max(hole_edges, loop.size() == 4u * (n - 1) ? 0 : loop.size());

  // Only patches bounded by the loop itself: none.
  auto unchanged = mesh;
  auto unchanged_incidences = incidences;
  auto unchanged_loops = loops;
  const auto none = pcl::cocone::fillHolesFromMesh(points,
                                                   spacing,
                                                   other,
                                                   unchanged,
                                                   unchanged_incidences,
                                                   unchanged_loops,
                                                   2.75,
                                                   1000,
                                                   0);
  EXPECT_EQ(none.holes, 0u);
  EXPECT_EQ(unchanged, mesh);

  const auto filled = pcl::cocone::fillHolesFromMesh(
      points, spacing, other, mesh, incidences, loops, 2.75, 1000, 3);
  EXPECT_EQ(filled.holes, 1u);
  ASSERT_EQ(filled.rims.size(), 1u);
  EXPECT_EQ(filled.rims[0].size(), hole_edges);
  const auto topology = pcl::cocone::analyzeMesh(mesh, points.size());
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(topology.euler, 1); // a disk
  EXPECT_EQ(topology.components, 1u);
  EXPECT_EQ(topology.boundary_edges, 4u * (n - 1));
  EXPECT_EQ(mesh.size(), 2u * (n - 1) * (n - 1));
  EXPECT_GT(mesh.size(), cut);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].size(), 4u * (n - 1));
  // The incidences are those of the mesh.
  const pcl::cocone::EdgeIncidences fresh(mesh);
  EXPECT_EQ(incidences.edges, fresh.edges);
  EXPECT_EQ(incidences.triangle, fresh.triangle);
  // Every triangle faces as the grid's (+z).
  for (const auto& t : mesh)
    EXPECT_GT((points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).z(),
              0.0);
}

TEST(HoleFilling, PatchWithAHoleOfItsOwnIsClosedByDelaunayPatches)
{
  // A square grid of unit spacing with a round hole, and another mesh of the same
  // triangles that has a hole of its own inside it: the fan of the middle vertex.
  // The other mesh's patch stops at that hole, which a Delaunay patch of its
  // hexagon closes, so the grid's hole closes without the middle vertex; the grid's
  // outer border stays.
  const int n = 16;
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      points.emplace_back(i, j, 0.0);
  const int middle = (n / 2) * n + n / 2;
  std::vector<pcl::cocone::Triangle> mesh, other;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
      for (const pcl::cocone::Triangle& t :
           {pcl::cocone::Triangle{a, b, c}, pcl::cocone::Triangle{a, c, d}}) {
        const Eigen::Vector3d centroid =
            (points[t[0]] + points[t[1]] + points[t[2]]) / 3.0 - points[middle];
        if (centroid.norm() >= 2.2)
          mesh.push_back(t);
        if (std::find(t.begin(), t.end(), middle) == t.end())
          other.push_back(t);
      }
    }
  const std::vector<double> spacing(points.size(), 1.0);
  pcl::cocone::EdgeIncidences incidences(mesh);
  auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
  ASSERT_EQ(loops.size(), 2u);

  const auto filled = pcl::cocone::fillHolesFromMesh(
      points, spacing, other, mesh, incidences, loops, 2.75, 1000, 0);
  EXPECT_EQ(filled.holes, 1u);
  const auto topology = pcl::cocone::analyzeMesh(mesh, points.size());
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(topology.euler, 1); // a disk
  EXPECT_EQ(topology.components, 1u);
  EXPECT_EQ(topology.boundary_edges, 4u * (n - 1));
  // The middle vertex's six triangles become the hexagon's four.
  EXPECT_EQ(mesh.size(), 2u * (n - 1) * (n - 1) - 2u);
  for (const auto& t : mesh) {
    EXPECT_EQ(std::find(t.begin(), t.end(), middle), t.end());
    EXPECT_GT((points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).z(),
              0.0);
    for (int c = 0; c < 3; ++c)
      EXPECT_LE((points[t[c]] - points[t[(c + 1) % 3]]).norm(), 2.75);
  }
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].size(), 4u * (n - 1));
  const pcl::cocone::EdgeIncidences fresh(mesh);
  EXPECT_EQ(incidences.edges, fresh.edges);
  EXPECT_EQ(incidences.triangle, fresh.triangle);
}

TEST(HoleFilling, HoleWindingRoundATubeIsClosedByTheAdvancingFront)
{
  // A thin torus (about 12 samples round the tube) with a hole that winds two thirds
  // of the way round the tube along 14 spacings of it: the band round the hole is
  // no disk, so no patch is bounded by its loop, but the advancing front over the
  // whole piece and the samples in the hole closes it with the torus's genus. The same
  // hole on a true border, or longer than max_edges, stays; and a small hole in the
  // same piece is left to the patches (the piece is much larger than its hole).
  const auto s = cocone_test::torus(cocone_test::options(1000), 1.0, 0.1);
  const auto full = pcl::cocone::run(
      s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_EQ(pcl::cocone::analyzeMesh(full.triangles, full.vertices).euler, 0);
  std::vector<Eigen::Vector3d> points(full.vertices);
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (full.vertex_of_input[i] >= 0)
      points[full.vertex_of_input[i]] = s.points[i];
  const std::vector<double> spacing(points.size(), s.spacing);
  // The co-cone triangles: those of the whole torus, so the samples in the hole
  // are next to the piece.
  std::vector<pcl::cocone::CoconeTriangle> cocone;
  for (auto t : full.triangles) {
    std::sort(t.begin(), t.end());
    cocone.push_back({t, 7});
  }
  // Cut the triangles whose centroid is in the hole: along the tube within `along`
  // radians of the x axis, round it where the tube faces outwards (cos > -0.5).
  const auto cut = [&](double along) {
    std::vector<pcl::cocone::Triangle> mesh;
    for (const auto& t : full.triangles) {
      const Eigen::Vector3d c = (points[t[0]] + points[t[1]] + points[t[2]]) / 3.0;
      const double phi = std::atan2(c.y(), c.x());
      const double outward = std::hypot(c.x(), c.y()) - 1.0;
      if (std::abs(phi) >= along || outward < -0.5 * 0.1)
        mesh.push_back(t);
    }
    return mesh;
  };
  const auto close = [&](std::vector<pcl::cocone::Triangle>& mesh,
                         std::size_t max_edges,
                         bool on_true_border) {
    pcl::cocone::EdgeIncidences incidences(mesh);
    auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
    EXPECT_EQ(loops.size(), 1u);
    std::vector<std::uint8_t> true_border;
    if (on_true_border) {
      true_border.assign(points.size(), 0);
      for (const int v : loops.at(0))
        true_border[v] = 1;
    }
    const auto closed = pcl::cocone::closePiecesWithAdvancingFront(
        points, spacing, cocone, mesh, incidences, loops, 2.75, max_edges, true_border);
    const pcl::cocone::EdgeIncidences fresh(mesh);
    EXPECT_EQ(incidences.edges, fresh.edges);
    EXPECT_EQ(loops, pcl::cocone::boundaryLoops(fresh, points.size()));
    return closed;
  };

  auto mesh = cut(0.45);
  const auto loop_edges =
      pcl::cocone::boundaryLoops(pcl::cocone::EdgeIncidences(mesh), points.size())
          .at(0)
          .size();
  std::printf("[ measured ] hole winding round the tube: %zu edges, %zu vertices\n",
              loop_edges,
              pcl::cocone::analyzeMesh(mesh, points.size()).vertices);
  {
    auto patched = mesh;
    pcl::cocone::EdgeIncidences incidences(patched);
    auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
    EXPECT_EQ(pcl::cocone::fillUndersampledHoles(
                  points, spacing, patched, incidences, loops, 2.75, 1000)
                  .holes,
              0u);
  }
  for (const bool on_true_border : {true, false})
    for (const std::size_t max_edges : {loop_edges - 1, loop_edges}) {
      SCOPED_TRACE(on_true_border);
      SCOPED_TRACE(max_edges);
      auto closing = mesh;
      const auto closed = close(closing, max_edges, on_true_border);
      if (on_true_border || max_edges < loop_edges) {
        EXPECT_EQ(closed.holes, 0u);
        EXPECT_EQ(closing, mesh);
        continue;
      }
      EXPECT_EQ(closed.holes, 1u);
      ASSERT_EQ(closed.rims.size(), 1u);
      EXPECT_EQ(closed.rims[0].size(), loop_edges);
      const auto topology = pcl::cocone::analyzeMesh(closing, points.size());
      EXPECT_TRUE(topology.manifold());
      EXPECT_EQ(topology.boundary_edges, 0u);
      EXPECT_EQ(topology.components, 1u);
      EXPECT_EQ(topology.euler, 0);
      for (const auto& t : closing)
        for (int c = 0; c < 3; ++c)
          EXPECT_LE((points[t[c]] - points[t[(c + 1) % 3]]).norm(), 2.75 * s.spacing);
    }
  // A hole of a few triangles: the piece is far larger than its loop.
  auto small = cut(0.05);
  EXPECT_EQ(close(small, 1000, false).holes, 0u);
}

TEST(HoleFilling, SlitIsClosedByTheStripAcrossIt)
{
  // A jittered unit grid with a slit one cell wide and 20 long: the patch of least
  // perimeter is the strip across it (k - 2 triangles, every new edge joining the
  // slit's two sides within 1.6 spacings). A hole 6 spacings across stays open, as
  // does the slit on a true border or longer than max_edges.
  const int nx = 30, ny = 12;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      points.emplace_back(i + jitter(random), j + jitter(random), 0.0);
  const std::vector<double> spacing(points.size(), 1.0);
  const auto id = [&](int i, int j) { return j * nx + i; };
  const auto grid = [&](const std::function<bool(int, int)>& cut) {
    std::vector<pcl::cocone::Triangle> mesh;
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i)
        if (!cut(i, j)) {
          mesh.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
          mesh.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return mesh;
  };
  const auto slit = grid([](int i, int j) { return j == 5 && i >= 5 && i < 25; });
  const auto wide = grid(
      [](int i, int j) { return std::hypot(i + 0.5 - 15.0, j + 0.5 - 5.5) < 3.0; });
  const auto close = [&](std::vector<pcl::cocone::Triangle>& mesh,
                         std::size_t max_edges,
                         bool on_true_border) {
    pcl::cocone::EdgeIncidences incidences(mesh);
    auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
    EXPECT_EQ(loops.size(), 2u); // the grid's outline and the hole
    std::vector<std::uint8_t> true_border;
    if (on_true_border)
      true_border.assign(points.size(), 1);
    const auto closed =
        pcl::cocone::fillUndersampledHoles(points,
                                           spacing,
                                           mesh,
                                           incidences,
                                           loops,
                                           2.75,
                                           max_edges,
                                           true_border,
                                           pcl::cocone::HoleWeight::LEAST_PERIMETER);
    const pcl::cocone::EdgeIncidences fresh(mesh);
    EXPECT_EQ(incidences.edges, fresh.edges);
    EXPECT_EQ(loops, pcl::cocone::boundaryLoops(fresh, points.size()));
    return closed;
  };
  // The outline (78 edges) is beyond the reach everywhere across: never closed.
  auto mesh = slit;
  const auto closed = close(mesh, 1000, false);
  ASSERT_EQ(closed.holes, 1u);
  ASSERT_EQ(closed.rims.size(), 1u);
  const std::size_t k = closed.rims[0].size();
  EXPECT_EQ(k, 42u);
  EXPECT_EQ(closed.triangles, k - 2);
  EXPECT_EQ(mesh.size(), slit.size() + k - 2);
  const auto topology = pcl::cocone::analyzeMesh(mesh, points.size());
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(topology.euler, 1); // a disk again
  for (std::size_t t = slit.size(); t < mesh.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int a = mesh[t][c], b = mesh[t][(c + 1) % 3];
      EXPECT_LE((points[a] - points[b]).norm(), 1.6);
      EXPECT_LE(std::abs(a / nx - b / nx), 1); // within the slit's two rows
    }
  // Facing as the grid: every triangle counter-clockwise seen from +z.
  for (const auto& t : mesh)
    EXPECT_GT((points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).z(),
              0.0);
  for (const bool on_true_border : {true, false}) {
    auto kept = slit;
    EXPECT_EQ(close(kept, on_true_border ? 1000 : k - 1, on_true_border).holes, 0u);
    EXPECT_EQ(kept, slit);
  }
  auto open = wide;
  EXPECT_EQ(close(open, 1000, false).holes, 0u);
  EXPECT_EQ(open, wide);
}

TEST(HoleFilling, ThinPlateComesOutClosed)
{
  // A plate thinner than the spacing (0.02 thick, 0.02 to 0.014 spacings of even
  // samples): the walk leaves slits along its rim, where the two sheets meet within
  // a triangle; CGAL's patches fan out from one end of a slit with edges beyond the
  // reach, the least perimeter patch is the strip across it. 10,000 samples had 8
  // slits open before (CGAL's patches closed 13 of 21).
  for (const std::size_t n : {10000u, 20000u}) {
    SCOPED_TRACE(n);
    const auto s = cocone_test::thinPlate(cocone_test::options(n));
    const auto r = pcl::cocone::run(
        s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto m = cocone_test::scoreMesh(s, r);
    std::printf("[ measured ] thin plate, %zu points: %s\n", n, m.str().c_str());
    EXPECT_TRUE(cocone_test::closedSurface(m, 1, 2));
    EXPECT_LT(m.max_distance, 1.0); // spacings: the patches stay on the plate
  }
}

TEST(HoleFilling, NoisyThinPlateComesOutClosed)
{
  // A plate 0.05 thick (1.2 to 1.5 spacings of 8,000 samples) with noise of 0.3
  // spacings: where the two sheets meet within the noise the walk leaves loops in
  // crumpled clusters, each with a handle through it, that no patch of the loop
  // closes without keeping the handle. Reopened by a ring or two and closed again,
  // they close (before: 2 loops and 2 handles random, 1 and 1 even).
  for (const bool even : {false, true}) {
    SCOPED_TRACE(even ? "even" : "random");
    auto o = cocone_test::options(8000, 0.3, 1.0, even);
    o.seed = even ? 2 : 1;
    const auto s = cocone_test::thinPlate(o, 0.05);
    const auto r = pcl::cocone::run(
        s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto m = cocone_test::scoreMesh(s, r);
    std::printf("[ measured ] noisy thin plate, %s: %s\n",
                even ? "even" : "random",
                m.str().c_str());
    EXPECT_TRUE(cocone_test::closedSurface(m, 1, 2));
    EXPECT_GT(m.used_share, 0.98);
  }
}

TEST(HoleFilling, LoopsBeyondTheReopeningsBoundAreReopenedShortestFirst)
{
  // A plate 0.05 thick (about 2 spacings of 20,000 samples) with noise of a
  // spacing: the two sheets overlap within the noise, more than REOPENED_LOOPS
  // loops are left open before the reopening (28 to 36), and the reopening tries
  // the shortest rather than none. The sample does not resolve the plate (the mesh
  // keeps handles), so the bound is on what the reopening closes: 63 loops on the
  // two clouds before, 45 with it.
  std::size_t loops = 0;
  for (const std::uint64_t seed : {1, 2}) {
    auto o = cocone_test::options(20000, 1.0, 1.0, false);
    o.seed = seed;
    const auto s = cocone_test::thinPlate(o, 0.05);
    const auto r = pcl::cocone::run(
        s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto m = cocone_test::scoreMesh(s, r);
    std::printf("[ measured ] noisy plate 2 spacings thick, seed %d: %s\n",
                static_cast<int>(seed),
                m.str().c_str());
    EXPECT_TRUE(m.topology.manifold()) << m.str();
    loops += m.loops;
  }
  EXPECT_LE(loops, 50u);
}

TEST(HoleFilling, CoarseClosedSurfacesComeOutClosed)
{
  // Coarse random samples: cubes of 1,200 and 3,000 points (sharp edges and
  // corners; at 3,000 a corner's patch replaces a band of the mesh with the
  // advancing front's triangles) and the genus-2 surface of 1,500 leave undersampled
  // holes that the step closes. (The cube of 800 points left one only where a
  // sample by an edge was set aside as an outlier.)
  struct Case {
    cocone_test::Sample sample;
    long euler;
  };
  for (const auto& c :
       {Case{cocone_test::cube(cocone_test::options(1200, 0, 1, false)), 2},
        Case{cocone_test::cube(cocone_test::options(3000, 0, 1, false)), 2},
        Case{cocone_test::genus2(cocone_test::options(1500, 0, 1, false)), -2}}) {
    SCOPED_TRACE(c.sample.name);
    pcl::cocone::Parameters off;
    off.fill_undersampled_holes = false;
    const auto open =
        pcl::cocone::run(c.sample.points, off, pcl::cocone::Stages::RECONSTRUCTION);
    const auto r = pcl::cocone::run(c.sample.points,
                                    pcl::cocone::Parameters(),
                                    pcl::cocone::Stages::RECONSTRUCTION);
    EXPECT_GT(open.border_loops.size(), 0u);
    EXPECT_EQ(r.counts.holes_filled, open.border_loops.size());
    // The holes reported are the loops the mesh had without the step, in the
    // caller's ids, each from its lowest id.
    auto rims = open.border_loops;
    for (auto& rim : rims)
      std::rotate(rim.begin(), std::min_element(rim.begin(), rim.end()), rim.end());
    std::sort(rims.begin(), rims.end());
    EXPECT_EQ(r.filled_holes, rims);
    const auto m = cocone_test::scoreMesh(c.sample, r);
    EXPECT_TRUE(cocone_test::closedSurface(m, 1, c.euler));
  }
}

TEST(HoleFilling, RefinedPatchesAreFairAndStayOnTheSurface)
{
  // Two dropouts of an even sphere, 3 and 4 spacings across, closed (hole_width 0)
  // and then refined and faired (refineFilledHoles()): new vertices inside, the
  // mesh still closed and oriented, the patches as dense as the mesh round them
  // and on the sphere (the bilaplacian fairing of a cap with its tangent plane held
  // at the rim; the middle of a flat patch over the wider one would lie 0.13
  // spacings inside).
  const auto full = cocone_test::sphere(cocone_test::options(3000));
  const double h = full.spacing;
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : full.points)
    if ((p - full.points[100]).norm() > 1.5 * h &&
        (p - full.points[2000]).norm() > 2.0 * h)
      points.push_back(p);
  pcl::cocone::Parameters flat;
  flat.hole_width = 0.0;
  pcl::cocone::Parameters fair = flat;
  fair.refine_filled_holes = true;
  const auto a = pcl::cocone::run(points, flat, pcl::cocone::Stages::RECONSTRUCTION);
  const auto b = pcl::cocone::run(points, fair, pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_EQ(a.filled_holes.size(), 2u);
  EXPECT_EQ(b.filled_holes, a.filled_holes);
  EXPECT_EQ(a.added_vertices, 0u);
  ASSERT_GT(b.added_vertices, 2u);
  const std::size_t n = points.size();
  ASSERT_EQ(b.positions.size(), b.vertices + b.added_vertices);
  std::vector<Eigen::Vector3d> all = points;
  for (std::size_t k = 0; k < b.added_vertices; ++k)
    all.push_back(b.positions[b.vertices + k] + b.offset);
  const auto topology = pcl::cocone::analyzeMesh(b.polygons, all.size());
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(topology.boundary_edges, 0u);
  EXPECT_EQ(topology.orientation_conflicts, 0u);
  EXPECT_EQ(topology.euler, 2);
  double volume = 0.0;
  for (const auto& t : b.polygons)
    volume += all[t[0]].dot(all[t[1]].cross(all[t[2]])) / 6.0;
  EXPECT_GT(volume, 0.0);
  // The added vertices: caller ids after the points', on the sphere.
  double off_surface = 0.0;
  for (std::size_t k = n; k < all.size(); ++k)
    off_surface = std::max(off_surface, full.distance(all[k]));
  std::printf("[ measured ] %zu vertices added, %.4f spacings off the sphere at most\n",
              b.added_vertices,
              off_surface / h);
  EXPECT_LT(off_surface, 0.02 * h);
  // Outside the patches the mesh is as it was; inside, no edge longer than the
  // mesh's own round it.
  std::size_t kept = 0;
  double longest = 0.0, longest_added = 0.0;
  std::set<pcl::cocone::Triangle> before;
  for (auto t : a.polygons) {
    std::sort(t.begin(), t.end());
    before.insert(t);
    for (int c = 0; c < 3; ++c)
      longest = std::max(longest, (points[t[c]] - points[t[(c + 1) % 3]]).norm());
  }
  for (auto t : b.polygons) {
    std::sort(t.begin(), t.end());
    if (static_cast<std::size_t>(t[2]) < n) {
      kept += before.count(t);
      continue;
    }
    for (int c = 0; c < 3; ++c)
      longest_added = std::max(longest_added, (all[t[c]] - all[t[(c + 1) % 3]]).norm());
  }
  EXPECT_LE(longest_added, longest);
  EXPECT_GE(kept + 2 * 40, a.polygons.size()); // the two first patches' triangles
}

TEST(HoleFilling, TrueHolesFourSpacingsAcrossStayOpen)
{
  // Six round holes in an even sample of the sphere (whose spacing is the most
  // regular, so a hole there is the least likely to be undersampling), clean and
  // with noise of 0.3 spacings: every one stays open, as wider than 2.5 of the
  // triangles round it with no sample inside (classifyBorderLoops()), 4 spacings
  // across clean, 5 with noise, and 6. Measured limits: with noise 0.3 one of six
  // holes 4 across closes (the holes noise tears where registered views overlap are
  // as wide: Noise.RangeViewsOfAnOpenSurface); at 3 across (a sample or two
  // missing) all close. Without the classification the patches' reach alone closed
  // all six at 4 across and three at 5. Random samples leave holes up to 6 of their
  // (smaller) spacings covered by the reconstruction itself.
  const double spacing = cocone_test::sphere(cocone_test::options(10000)).spacing;
  for (const auto& [across, noise] : {std::pair{4.0, 0.0},
                                      std::pair{5.0, 0.3},
                                      std::pair{6.0, 0.0},
                                      std::pair{6.0, 0.3}}) {
    SCOPED_TRACE(testing::Message() << across << " across, noise " << noise);
    const auto s = cocone_test::sphereWithHoles(
        cocone_test::options(10000, noise), 6, 0.5 * across * spacing);
    const auto r = pcl::cocone::run(
        s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto m = cocone_test::scoreMesh(s, r);
    EXPECT_TRUE(m.topology.manifold()) << m.str();
    EXPECT_EQ(r.counts.holes_filled, 0u);
    EXPECT_EQ(r.counts.true_borders, 6u);
    EXPECT_EQ(m.loops, 6u) << m.str();
    EXPECT_EQ(m.topology.euler, 2 - 6);
  }
}

TEST(HoleFilling, OutlineOfAPieceIsATrueBorder)
{
  // A strip three samples wide, bent along its length (a one-view scan's ear cut
  // off from the head: PCL's 397-point bunny came out with its ear capped into a
  // closed pillow), beside a sheet with a hole of one missing sample. The strip's
  // outline is as narrow as the hole (2.4 of its triangles: within the hole width
  // of 2.5), and the strip's own middle row lies over it: but the loop runs round
  // its whole piece, the piece's outline, not a hole in it, and stays open.
  std::vector<Eigen::Vector3d> points;
  std::vector<pcl::cocone::Triangle> mesh;
  const auto grid = [&](int rows, int columns, const Eigen::Vector3d& at, double bend) {
    const int first = static_cast<int>(points.size());
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < columns; ++c) {
        const double x = c + 0.5 * (r % 2), u = x - 0.5 * columns;
        points.push_back(at + Eigen::Vector3d(x, 0.866 * r, bend * u * u));
      }
    const auto id = [first, columns](int r, int c) { return first + r * columns + c; };
    for (int r = 0; r + 1 < rows; ++r)
      for (int c = 0; c + 1 < columns; ++c)
        if (r % 2 == 0) {
          mesh.push_back({id(r, c), id(r, c + 1), id(r + 1, c)});
          mesh.push_back({id(r, c + 1), id(r + 1, c + 1), id(r + 1, c)});
        }
        else {
          mesh.push_back({id(r, c), id(r, c + 1), id(r + 1, c + 1)});
          mesh.push_back({id(r, c), id(r + 1, c + 1), id(r + 1, c)});
        }
    return id;
  };
  const auto strip = grid(3, 12, Eigen::Vector3d(0, 0, 20), 0.05);
  const auto sheet = grid(12, 12, Eigen::Vector3d(0, 0, 0), 0.0);
  // The hole: the six triangles round one sample of the sheet (row 5, column 5).
  const int hole = sheet(5, 5);
  mesh.erase(std::remove_if(mesh.begin(),
                            mesh.end(),
                            [&](const pcl::cocone::Triangle& t) {
                              return t[0] == hole || t[1] == hole || t[2] == hole;
                            }),
             mesh.end());
  std::vector<pcl::cocone::CoconeTriangle> cocone;
  for (auto t : mesh) {
    std::sort(t.begin(), t.end());
    cocone.push_back({t, 7});
  }
  std::sort(cocone.begin(), cocone.end(), [](const auto& a, const auto& b) {
    return a.v < b.v;
  });
  const pcl::cocone::EdgeIncidences incidences(mesh);
  const auto loops = pcl::cocone::boundaryLoops(incidences, points.size());
  ASSERT_EQ(loops.size(), 3u); // the strip's outline, the sheet's, the hole
  const auto border =
      pcl::cocone::classifyBorderLoops(points, mesh, loops, cocone, 2.5, 1000);
  std::size_t checked = 0;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    SCOPED_TRACE(testing::Message() << "loop of " << loops[l].size() << " edges");
    if (loops[l][0] <= strip(2, 11)) {
      EXPECT_EQ(border[l], 1); // the strip's outline
      ++checked;
    }
    else if (std::find(loops[l].begin(), loops[l].end(), sheet(5, 4)) !=
             loops[l].end()) {
      EXPECT_EQ(border[l], 0); // the hole
      ++checked;
    }
  }
  EXPECT_EQ(checked, 2u);
}

namespace {

/** A range scanner's grid over a curved height field, N x N samples of the unit
 * square with the sensor's jitter (0.05 of a spacing along the grid) and Gaussian
 * noise of \a noise spacings along z; the samples (i, j) that \a missing names
 * are left out. */
template <typename Missing>
std::vector<Eigen::Vector3d>
rangeGrid(int N, double noise, std::uint64_t seed, const Missing& missing)
{
  const double h = 1.0 / N;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) {
      if (missing(i, j))
        continue;
      const double x = (i + 0.05 * gauss(rng)) * h, y = (j + 0.05 * gauss(rng)) * h;
      points.emplace_back(
          x, y, 0.15 * std::sin(3 * x) * std::cos(2 * y) + noise * h * gauss(rng));
    }
  return points;
}

} // namespace

TEST(HoleFilling, RangeGridDropoutsStayOpen)
{
  // A range scanner's grid over a curved height field, 120 x 120 samples with
  // the sensor's jitter: six dropouts of 3 x 3 to 5 x 2 samples are true borders
  // (the sampling stops there), four single missing samples are undersampling
  // (dropouts of 2 x 2 and 2 x 3, 2.1 and 2.4 rim triangles wide, close).
  // With the scans' noise (0.15 spacings) and twice it: the mesh has the outline
  // and the six dropouts as its loops. Without the classification the filling
  // closes two of the dropouts.
  constexpr int N = 120;
  const int dropouts[][4] = {{20, 20, 3, 3},
                             {20, 60, 3, 4},
                             {60, 20, 2, 5},
                             {60, 60, 4, 4},
                             {95, 40, 4, 3},
                             {40, 95, 5, 2}};
  const int singles[][2] = {{30, 40}, {80, 90}, {100, 100}, {45, 10}};
  for (const double noise : {0.15, 0.3}) {
    SCOPED_TRACE(noise);
    const auto points = rangeGrid(N, noise, 7, [&](int i, int j) {
      bool missing = false;
      for (const auto& d : dropouts)
        missing |= i >= d[0] && i < d[0] + d[2] && j >= d[1] && j < d[1] + d[3];
      for (const auto& m : singles)
        missing |= i == m[0] && j == m[1];
      return missing;
    });
    for (const double width : {pcl::cocone::Parameters().hole_width, 0.0}) {
      pcl::cocone::Parameters p;
      p.hole_width = width;
      const auto r = pcl::cocone::run(points, p, pcl::cocone::Stages::RECONSTRUCTION);
      const auto topology = pcl::cocone::analyzeMesh(r.polygons, points.size());
      EXPECT_TRUE(topology.manifold());
      EXPECT_EQ(topology.components, 1u);
      if (width > 0.0) {
        EXPECT_EQ(r.border_loops.size(), 7u);
        EXPECT_EQ(r.counts.true_borders, 7u); // the outline too
        EXPECT_EQ(topology.euler, 1 - 6);
      }
      else
        EXPECT_LE(r.border_loops.size(), 5u);
    }
  }
}

TEST(HoleFilling, GapRoundAnIslandStaysOpen)
{
  // A range grid of 120 x 120 samples with the scans' jitter whose samples between
  // 8 and 12 spacings from the centre are missing: a ring-shaped dropout 4
  // spacings wide round an island of about 200 samples, where a scan's view was
  // occluded. Both rims are true borders (the sampling stops there): the ring's
  // points seen through the hole (the island's) must not read as samples that
  // split it into narrow openings. Truth: the outline, the ring's outer rim and
  // the island's rim; two components, Euler 0 + 1.
  for (const double noise : {0.15, 0.3}) {
    SCOPED_TRACE(noise);
    const auto points = rangeGrid(120, noise, 11, [](int i, int j) {
      const double r = std::hypot(i - 60.0, j - 60.0);
      return r >= 8.0 && r < 12.0;
    });
    const auto r = pcl::cocone::run(
        points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto topology = pcl::cocone::analyzeMesh(r.polygons, points.size());
    EXPECT_TRUE(topology.manifold());
    EXPECT_EQ(topology.components, 2u);
    EXPECT_EQ(r.border_loops.size(), 3u);
    EXPECT_EQ(topology.euler, 1);
  }
}

TEST(HoleFilling, TouchingSpheresComeOutApart)
{
  // Two spheres half a spacing apart: at the contact the sheets are closer than the
  // spacing, the walk bridges the gap with a few triangles and the hole filling
  // closes round them, a neck of 3 to 5 edges that makes the two one sphere (Euler
  // 2). No sample resolves such a neck: it is cut, and each sphere closed.
  struct Case {
    std::size_t n;
    bool even;
    double ratio;
    std::uint64_t seed;
  };
  for (const Case c : {Case{1000, true, 1.0, 1},
                       Case{1000, false, 1.0, 2},
                       Case{3000, true, 1.0, 2},
                       Case{3000, false, 8.0, 1}}) {
    auto o = cocone_test::options(c.n, 0.0, c.ratio, c.even);
    o.seed = c.seed;
    const auto s = cocone_test::twoTouchingSpheres(o);
    const auto r = pcl::cocone::run(
        s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto m = cocone_test::scoreMesh(s, r);
    std::printf("[ measured ] touching spheres, %zu %s samples 1:%g, seed %d: %s, "
                "%zu necks cut\n",
                c.n,
                c.even ? "even" : "random",
                c.ratio,
                static_cast<int>(c.seed),
                m.str().c_str(),
                r.counts.necks_cut);
    EXPECT_TRUE(cocone_test::closedSurface(m, 2, 4));
    EXPECT_GE(r.counts.necks_cut, 1u);
    // A sphere each: the triangles with corners on both are few (where the cut's
    // cycle ran, samples within half a spacing of the other sphere can end up on
    // its side: 0 to 37 triangles on these clouds).
    std::size_t mixed = 0;
    for (const auto& t : r.polygons) {
      const bool left = s.points[t[0]].x() < 0.0;
      mixed += (s.points[t[1]].x() < 0.0) != left || (s.points[t[2]].x() < 0.0) != left;
    }
    std::printf("[ measured ] %zu triangles across the gap\n", mixed);
    EXPECT_LE(mixed, r.polygons.size() / 100);
    // Without the hole filling nothing is cut.
    pcl::cocone::Parameters off;
    off.fill_undersampled_holes = false;
    EXPECT_EQ(pcl::cocone::run(s.points, off, pcl::cocone::Stages::RECONSTRUCTION)
                  .counts.necks_cut,
              0u);
  }
}

TEST(HoleFilling, LayersWithinASpacingOfALargerPieceGo)
{
  // A sphere's mesh and a small closed piece (a flattened octahedron a spacing
  // across) off its surface: within a spacing of it, the piece is a layer the
  // sample does not resolve from the sphere and goes; 3 spacings off, or as thick as
  // the spacing with its far side 2.7 spacings off, it is a body of its own and stays.
  const auto s = cocone_test::sphere(cocone_test::options(3000));
  const auto r = pcl::cocone::run(
      s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_TRUE(cocone_test::closedSurface(cocone_test::scoreMesh(s, r), 1, 2));
  const double h = s.spacing;
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  const Eigen::Vector3d t1 = n.cross(Eigen::Vector3d::UnitZ()).normalized(),
                        t2 = n.cross(t1);
  const auto with_piece =
      [&](double offset, double half_thickness, std::vector<Eigen::Vector3d>& points) {
        points = s.points;
        std::vector<pcl::cocone::Triangle> triangles = r.polygons;
        const int o = static_cast<int>(points.size());
        const Eigen::Vector3d c = (1.0 + offset * h) * n;
        for (const Eigen::Vector3d& d : {Eigen::Vector3d(0.5 * h * t1),
                                         Eigen::Vector3d(0.5 * h * t2),
                                         Eigen::Vector3d(half_thickness * h * n)}) {
          points.push_back(c + d);
          points.push_back(c - d);
        }
        // Vertices o + 2k and o + 2k + 1 on axis k (t1, t2, n: right-handed), + then -:
        // the eight faces, outward (turned where an odd number of their corners is -).
        for (const int a : {0, 1})
          for (const int b : {2, 3})
            for (const int z : {4, 5}) {
              const bool odd = (a + b + z) % 2 == 1;
              triangles.push_back(odd ? pcl::cocone::Triangle{o + a, o + z, o + b}
                                      : pcl::cocone::Triangle{o + a, o + b, o + z});
            }
        return triangles;
      };
  std::vector<Eigen::Vector3d> points;
  for (const auto& [offset, half_thickness, dropped] :
       {std::tuple<double, double, bool>{0.3, 0.1, true},
        std::tuple<double, double, bool>{3.0, 0.1, false},
        std::tuple<double, double, bool>{1.5, 1.2, false}}) {
    auto triangles = with_piece(offset, half_thickness, points);
    const auto topology = pcl::cocone::analyzeMesh(triangles, points.size());
    ASSERT_TRUE(topology.manifold());
    ASSERT_EQ(topology.closed_components, 2u);
    const std::vector<double> spacing(points.size(), h);
    EXPECT_EQ(pcl::cocone::dropLayers(points, spacing, triangles), dropped ? 8u : 0u)
        << "offset " << offset << " half thickness " << half_thickness;
    EXPECT_EQ(triangles.size(), r.polygons.size() + (dropped ? 0u : 8u));
  }
  // The sphere alone keeps everything.
  auto alone = r.polygons;
  EXPECT_EQ(
      pcl::cocone::dropLayers(s.points, std::vector<double>(s.points.size(), h), alone),
      0u);

  // Touching spheres half a spacing apart, 10,000 random samples: the patches
  // closed 4 flat pieces of 8 to 44 samples of the two caps between the spheres
  // (6 components, Euler 12), each within a spacing of the spheres' triangles.
  auto o = cocone_test::options(10000, 0.0, 1.0, false);
  o.seed = 2;
  const Outcome touching =
      reconstruct(cocone_test::twoTouchingSpheres(o), Parameters(), "random, seed 2");
  EXPECT_TRUE(cocone_test::closedSurface(touching.mesh, 2, 4));
}

TEST(HoleFilling, NearlyTouchingSpheres)
{
  // Two spheres of 5,000 random samples each, 2 spacings apart. The walk leaves
  // shards of 3 to 6 triangles across the gap, which the patches closed into 4
  // beads (7 components, Euler 12): pieces of fewer than 8 vertices go. Each sphere
  // then has a hole where it faces the other, round samples no mesh made a surface
  // of (the Co-cone's and the advancing front's triangles bridge the gap there),
  // which closes through them (fillHolesWithInnerSamples()): two closed spheres.
  const auto s = cocone_test::twoTouchingSpheres(
      cocone_test::options(10000, 0, 1, false), 1.0, 2.0);
  const auto r = pcl::cocone::run(
      s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  const auto m = cocone_test::scoreMesh(s, r);
  std::printf("[ measured ] spheres 2 spacings apart: %s; %zu triangles dropped\n",
              m.str().c_str(),
              r.counts.repair.speck);
  EXPECT_TRUE(cocone_test::closedSurface(m, 2, 4));
  EXPECT_LT(m.max_distance, 0.5); // each patch lies on its sphere
  EXPECT_GT(r.counts.repair.speck, 0u);
  std::size_t pieces = 0;
  const auto component = pcl::cocone::triangleComponents(r.triangles, &pieces);
  std::vector<std::size_t> size(pieces, 0);
  for (const int c : component)
    ++size[c];
  for (const std::size_t t : size)
    EXPECT_GT(t, s.points.size() / 4); // a sphere each
  // The points of the specks stay accounted for: vertices, in no triangle.
  for (const int v : r.vertex_of_input)
    EXPECT_GE(v, 0);
  // Every hole reported closed is closed in the mesh: no rim of a speck is listed.
  const auto border = pcl::cocone::borderVertices(r.polygons);
  for (const auto& rim : r.filled_holes)
    for (const int id : rim)
      EXPECT_FALSE(std::binary_search(border.begin(), border.end(), id));
  // Without the filling the mesh is as it was (the specks stay).
  pcl::cocone::Parameters off;
  off.fill_undersampled_holes = false;
  EXPECT_EQ(pcl::cocone::run(s.points, off, pcl::cocone::Stages::RECONSTRUCTION)
                .counts.repair.speck,
            0u);
}

TEST(HoleFilling, InnerSamplesOfTheOtherSheetStayOut)
{
  // Touching spheres half a spacing apart, 10,000 even samples: each sphere has a
  // hole where it faces the other, its free samples inside. Over the first hole's
  // round loop the quadratic height ran between the two caps, and its patch took
  // the other cap's samples too (60 triangles joined the spheres), leaving the
  // other hole without them: 1 loop, Euler 3. Each hole takes its own sheet's.
  auto o = cocone_test::options(10000, 0.0, 1.0, true);
  o.seed = 1;
  const Outcome touching =
      reconstruct(cocone_test::twoTouchingSpheres(o), Parameters(), "even, seed 1");
  const Result& r = touching.result;
  EXPECT_TRUE(cocone_test::closedSurface(touching.mesh, 2, 4));
  EXPECT_GT(r.counts.holes_filled, 1u);
  // No triangle joins the spheres (centred on the x axis either side of 0).
  std::size_t joining = 0;
  for (const auto& t : r.triangles) {
    int right = 0;
    for (const int v : t)
      right += r.positions[v].x() + r.offset.x() > 0.0;
    joining += right % 3 != 0;
  }
  EXPECT_EQ(joining, 0u);
}

TEST(HoleFilling, CoarseTubeComesOutClosed)
{
  // A knotted tube with about 6, 7 and 8 samples around its circumference (5,000,
  // 7,000 and 10,000 even samples): the flatness test flags every point (the Voronoi
  // cells are not long and thin), so the boundary-aware mesh is empty; the original
  // Co-cone's triangles make the tube, and where they leave small holes (6 at 5,000
  // samples, 29 at 3,000) the Delaunay patches close them. Before they did, 5,000
  // and 7,000 samples gave no triangle at all.
  for (const std::size_t n : {5000u, 7000u, 10000u}) {
    SCOPED_TRACE(n);
    const auto s = cocone_test::tube(cocone_test::options(n));
    pcl::cocone::Parameters off;
    off.fill_undersampled_holes = false;
    const auto open =
        pcl::cocone::run(s.points, off, pcl::cocone::Stages::RECONSTRUCTION);
    EXPECT_LT(open.triangles.size(), s.points.size() / 10);
    const auto r = pcl::cocone::run(
        s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto m = cocone_test::scoreMesh(s, r);
    std::printf("[ measured ] coarse tube, %zu points: %s\n", n, m.str().c_str());
    EXPECT_TRUE(cocone_test::closedSurface(m, 1, 0));
    // The labels stay the flatness test's (the paper's output).
    EXPECT_EQ(r.boundary_indices, open.boundary_indices);
  }
}

TEST(HoleFilling, CoarseRandomTubeTheWalkBreaksUpComesOutClosed)
{
  // The knotted tube with 8,000 and 10,000 random samples (7 to 8 round it): the
  // flatness test flags 40 to 66 % of the points, and the walk meshed short
  // stretches of tube (at 8,000 points 43 pieces, the largest with 5 % of the tube)
  // that the hole filling capped: 40 and 10 components. The original Co-cone's mesh
  // now stands in over the part the walk broke up.
  for (const std::size_t n : {8000u, 10000u}) {
    SCOPED_TRACE(n);
    const auto s = cocone_test::tube(cocone_test::options(n, 0.0, 1.0, false));
    const auto r = pcl::cocone::run(
        s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto m = cocone_test::scoreMesh(s, r);
    std::printf(
        "[ measured ] coarse random tube, %zu points: %s\n", n, m.str().c_str());
    EXPECT_GT(r.counts.unmeshed_parts, 0u);
    EXPECT_TRUE(cocone_test::closedSurface(m, 1, 0));
    EXPECT_GT(m.used_share, 0.98);
  }
}

TEST(HoleFilling, CoarseTubeTheWalkLeavesAStretchOfComesOutClosed)
{
  // The knotted tube with 10,000 even samples, seeds 2 and 3: the walk meshes one
  // piece over 66 and 88 % of the points; the stretch it leaves out was capped at
  // both ends (one closed piece, Euler 2). Now the original Co-cone's mesh stands in
  // over a part that leaves a tenth of its points out.
  for (const std::uint64_t seed : {2u, 3u}) {
    SCOPED_TRACE(seed);
    auto o = cocone_test::options(10000);
    o.seed = seed;
    const auto s = cocone_test::tube(o);
    const auto r = pcl::cocone::run(
        s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
    const auto m = cocone_test::scoreMesh(s, r);
    std::printf("[ measured ] coarse tube, seed %d: %s\n", int(seed), m.str().c_str());
    EXPECT_TRUE(cocone_test::closedSurface(m, 1, 0));
    EXPECT_GT(m.used_share, 0.98);
  }
}

TEST(HoleFilling, PatchWhoseCutDoesNotCloseIsNotTaken)
{
  // The knotted tube with 1,000 even samples, densities 1:8 (3 to 5 round it):
  // a patch of the original Co-cone's triangles is cut where two of its cut edges
  // enter one vertex, so the cut is no set of loops. It was taken as one, and the
  // Delaunay patches looked up an edge of it that no triangle has (a crash).
  const auto s = cocone_test::tube(cocone_test::options(1000, 0.0, 8.0, true));
  const auto r = pcl::cocone::run(
      s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_TRUE(r.error.empty()) << r.error;
  const auto m = cocone_test::scoreMesh(s, r);
  std::printf("[ measured ] tube of 1,000 points, 1:8: %s\n", m.str().c_str());
  EXPECT_TRUE(m.topology.manifold()) << m.str();
  EXPECT_GT(m.used_share, 0.8); // measured 0.88
}

TEST(HoleFilling, NoisyCoarseTubeIsMeshed)
{
  // The coarse tube with Gaussian noise of sigma local spacings: no point passes the
  // flatness test and the smoothing leaves it as it is (the jets would pull the tube
  // onto its axis), so the walk leaves specks over 2 to 18 % of the points; the
  // original Co-cone's mesh over the part stands in, its holes closed where the
  // patches can.
  for (const double sigma : {0.3, 0.5}) {
    for (const std::size_t n : {7000u, 10000u}) {
      SCOPED_TRACE(std::to_string(n) + " points, sigma " + std::to_string(sigma));
      const auto s = cocone_test::tube(cocone_test::options(n, sigma, 1.0, false));
      const auto r = pcl::cocone::run(
          s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
      const auto m = cocone_test::scoreMesh(s, r);
      std::printf("[ measured ] noisy coarse tube, %zu points, sigma %.1f: %s, %zu "
                  "triangles of the unmeshed part's Co-cone, smoothed %d\n",
                  n,
                  sigma,
                  m.str().c_str(),
                  r.counts.unmeshed_parts,
                  int(r.smoothed));
      EXPECT_TRUE(m.topology.manifold()) << m.str();
      EXPECT_GT(r.counts.unmeshed_parts, 0u);
      // Without it, the walk's specks held 2 to 18 % of the points.
      EXPECT_GT(m.used_share, 0.9);
      // Its triangles lie on the tube, within the noise (3 sigma of 0.5 spacings).
      EXPECT_LT(m.max_distance, 2.5) << m.str();
      EXPECT_GT(m.volume, 0.0);
      // The tube is closed; what the patches leave open. Measured: 8 / 1 loops at
      // sigma 0.3, 38 / 25 at 0.5 (7,000 / 10,000 points); with patches of at most
      // 2.75 local spacings (Parameters::hole_reach before), 18 / 6 and 55 / 37.
      EXPECT_LE(m.loops, sigma < 0.4 ? (n < 8000 ? 12u : 3u) : (n < 8000 ? 45u : 30u))
          << m.str();
    }
  }
}

TEST(Reconstruction, HolesInRollingGroundStayOpen)
{
  // Random samples of rolling ground (a height field, slopes under 6 degrees) with
  // six round holes 10 to 25 spacings across. Where the ground is on the convex
  // hull of the cloud (a dip, a crest) the rim points have Delaunay edges along the
  // hull hundreds of spacings long; counted in their local spacing, they made the
  // holes look sampled at their own scale, and the walk covered one with 11
  // triangles up to 19 spacings long (6 loops; localSpacing() now leaves such
  // edges out).
  constexpr std::size_t N = 100000;
  const std::array<Eigen::Vector3d, 6> holes{{{-0.75, 0.1, 0.06},
                                              {0.1, -0.75, 0.05},
                                              {0.8, -0.1, 0.07},
                                              {-0.1, 0.85, 0.05},
                                              {0.1, 0.3, 0.04},
                                              {0.55, 0.45, 0.08}}};
  // Within margin of a hole's circle (a triangle at the rim, between samples
  // round it, reaches in by a fraction of a spacing).
  const auto in_hole = [&](double x, double y, double margin = 0.0) {
    for (const auto& h : holes)
      if (std::hypot(x - h.x(), y - h.y()) < h.z() - margin)
        return true;
    return false;
  };
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  while (points.size() < N) {
    const double x = uniform(rng), y = uniform(rng);
    if (!in_hole(x, y))
      points.emplace_back(x, y, 0.05 * std::sin(2.1 * x + 0.3) * std::cos(1.7 * y));
  }
  const Result r =
      pcl::cocone::run(points, Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  ASSERT_TRUE(r.error.empty()) << r.error;
  const auto topology = pcl::cocone::analyzeMesh(r.triangles, r.vertices);
  const double spacing = std::sqrt(4.0 / N);
  std::size_t covering = 0;
  double longest = 0.0;
  for (const auto& t : r.polygons) {
    const Eigen::Vector3d c = (points[t[0]] + points[t[1]] + points[t[2]]) / 3.0;
    covering += in_hole(c.x(), c.y(), spacing);
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, (points[t[k]] - points[t[(k + 1) % 3]]).norm());
  }
  std::printf("[ measured ] rolling ground with 6 holes: %zu loops, Euler %ld, %zu "
              "triangles over a hole, longest edge %.1f spacings\n",
              r.border_loops.size(),
              topology.euler,
              covering,
              longest / spacing);
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(covering, 0u);
  EXPECT_EQ(r.border_loops.size(), 7u);
  EXPECT_EQ(topology.euler, 1 - 6);
  EXPECT_EQ(topology.components, 1u);
}

TEST(HandleCutting, AnyTriangleListIsSafe)
{
  // Random triangle lists on a few points (non-manifold edges and vertices, borders
  // on no loop, repeated triangles) and random tori with triangles taken out: no
  // crash, and what comes back is the list its incidences group.
  std::mt19937 random(7);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Eigen::Vector3d> points;
    std::vector<pcl::cocone::Triangle> mesh;
    if (trial % 2 == 0) {
      std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
      std::uniform_int_distribution<int> vertex(0, 9);
      for (int i = 0; i < 10; ++i)
        points.emplace_back(coordinate(random), coordinate(random), coordinate(random));
      for (int t = 0; t < 24; ++t) {
        const pcl::cocone::Triangle tri{vertex(random), vertex(random), vertex(random)};
        if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2])
          mesh.push_back(tri);
      }
    }
    else {
      gridTorus(3 + trial % 4, 4 + trial % 7, points, mesh);
      std::uniform_int_distribution<std::size_t> pick(0, mesh.size() - 1);
      for (int k = trial % 3; k > 0; --k)
        mesh.erase(mesh.begin() + static_cast<std::ptrdiff_t>(pick(random)));
    }
    pcl::cocone::EdgeIncidences inc(mesh);
    pcl::cocone::cutShortHandles(points, mesh, inc);
    EXPECT_EQ(inc.edges, pcl::cocone::EdgeIncidences(mesh).edges) << trial;
  }
}

TEST(HandleCutting, ThinPlateOfRandomSamplesComesOutWithoutHandles)
{
  // A plate thinner than the spacing, 20,000 random samples: where its two sheets
  // come within the spacing the walk closes a tunnel between them, one cycle of 3
  // to 5 edges round it, short both ways; the cut leaves it a closed genus-0 plate
  // (Euler 0 before, one handle).
  const auto s = cocone_test::thinPlate(cocone_test::options(20000, 0.0, 1.0, false));
  const auto r = pcl::cocone::run(
      s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  const auto m = cocone_test::scoreMesh(s, r);
  std::printf("[ measured ] thin plate, 20000 random samples, %zu handles cut: %s\n",
              r.counts.handles_cut,
              m.str().c_str());
  EXPECT_GE(r.counts.handles_cut, 1u);
  EXPECT_TRUE(cocone_test::closedSurface(m, 1, 2));
  EXPECT_LT(m.max_distance, 1.5); // spacings: the patches stay on the plate
}
