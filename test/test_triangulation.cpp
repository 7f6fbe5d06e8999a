/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/triangulation.h>

#include <gtest/gtest.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

using namespace pcl::cocone;

TEST(UniquePoints, SkipsNonFiniteAndMergesDuplicates)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Eigen::Vector3d> in{
      {1, 2, 3}, {nan, 0, 0}, {0, 0, 0}, {1, 2, 3}, {0, inf, 0}, {1, 2, 3 + 1e-9}};
  const UniquePoints u = makeUniquePoints(in);
  ASSERT_EQ(u.points.size(), 3u);
  EXPECT_EQ(u.vertex_of_input[1], -1);
  EXPECT_EQ(u.vertex_of_input[4], -1);
  EXPECT_EQ(u.vertex_of_input[0], u.vertex_of_input[3]);
  EXPECT_NE(u.vertex_of_input[0], u.vertex_of_input[5]); // near-duplicate is distinct
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (u.vertex_of_input[i] >= 0) {
      EXPECT_EQ(u.points[u.vertex_of_input[i]], in[i]);
    }
  }
}

TEST(UniquePoints, VertexIdsDoNotDependOnInputOrder)
{
  const std::vector<Eigen::Vector3d> a{{3, 0, 0}, {1, 1, 1}, {0, 5, 0}, {2, 2, 2}};
  const std::vector<Eigen::Vector3d> b{a[2], a[0], a[3], a[1]};
  EXPECT_EQ(makeUniquePoints(a).points, makeUniquePoints(b).points);
}

TEST(UniquePoints, SameWithAnyThreadCount)
{
  // Enough points for the threads to sort parts, with duplicates, points that share
  // a Morton code and non-finite ones.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::vector<Eigen::Vector3d> in(200000);
  for (auto& p : in)
    p = {coordinate(random), coordinate(random), coordinate(random)};
  for (std::size_t i = 0; i < in.size(); i += 97)
    in[i] = in[i / 2];
  for (std::size_t i = 5; i < in.size(); i += 1001)
    in[i] = in[i - 1] + Eigen::Vector3d(1e-12, 0.0, 0.0);
  in[11].x() = std::numeric_limits<double>::quiet_NaN();
  const UniquePoints alone = makeUniquePoints(in);
  for (const int threads : {2, 3}) {
    const UniquePoints u = makeUniquePoints(in, threads);
    EXPECT_EQ(u.points, alone.points) << threads;
    EXPECT_EQ(u.vertex_of_input, alone.vertex_of_input) << threads;
  }
}

TEST(UniquePoints, SmallAndLargeCloudsNumberedAlike)
{
  // A small cloud is sorted by comparison, a large one by radix: the same order
  // along the Morton curve. The small cloud here is part of the large one with the
  // same bounding box (its two corners), so its vertices must come in the order
  // they have among the large cloud's; some share a Morton code.
  std::mt19937 random(3);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::vector<Eigen::Vector3d> large{{-1, -1, -1}, {1, 1, 1}};
  while (large.size() < 40000) {
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    large.push_back(p);
    if (large.size() % 50 == 0) // a neighbour within the same Morton cell
      large.push_back(p + Eigen::Vector3d(0.0, 1e-9, 0.0));
  }
  std::vector<Eigen::Vector3d> small;
  for (std::size_t i = 0; i < large.size(); i += 4)
    small.push_back(large[i]);
  small.push_back(large[1]);
  ASSERT_LT(small.size(), 16384u); // the comparison sort
  const UniquePoints all = makeUniquePoints(large);
  const UniquePoints part = makeUniquePoints(small);
  ASSERT_EQ(part.points.size(), small.size());
  std::vector<int> rank(part.points.size());
  for (std::size_t i = 0; i + 1 < small.size(); ++i)
    rank[part.vertex_of_input[i]] = all.vertex_of_input[4 * i];
  rank[part.vertex_of_input.back()] = all.vertex_of_input[1];
  EXPECT_TRUE(std::is_sorted(rank.begin(), rank.end()));
}

TEST(Triangulate, DimensionOfDegenerateInput)
{
  EXPECT_EQ(triangulate({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}).dimension, 1);
  const Triangulation flat = triangulate({{0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}});
  EXPECT_EQ(flat.dimension, 2);
  EXPECT_EQ(flat.number_of_cells, 2u);
  std::size_t visited = 0;
  forEachCell(flat, 0, 1, [&](const CellView& c, int) {
    EXPECT_EQ(c.corners, 3);
    EXPECT_EQ(c.v[3], -1);
    ++visited;
  });
  EXPECT_EQ(visited, 2u);
}

TEST(Triangulate, CellsNeighboursAndCircumcenters)
{
  std::vector<Eigen::Vector3d> P;
  for (int i = 0; i < 200; ++i) // a deterministic scatter
    P.emplace_back(std::sin(i * 1.7), std::cos(i * 2.3), std::sin(i * 0.9 + 1.0));
  const Triangulation dt = triangulate(makeUniquePoints(P).points);
  ASSERT_EQ(dt.dimension, 3);
  for (const int threads : {1, 2}) {
    // Per thread: cells, hull, own and shared facets.
    std::vector<std::array<std::size_t, 4>> count(threads, {0, 0, 0, 0});
    forEachCell(
        dt,
        CellView::CIRCUMCENTER | CellView::NEIGHBORS,
        threads,
        [&](const CellView& c, int thread) {
          ASSERT_LT(thread, threads);
          auto& [cells, hull, own, shared] = count[thread];
          ++cells;
          // The circumcenter is equidistant from the four vertices.
          const double r = (c.circumcenter - dt.points[c.v[0]]).norm();
          for (int i = 1; i < 4; ++i)
            EXPECT_NEAR((c.circumcenter - dt.points[c.v[i]]).norm(), r, 1e-9 * r);
          for (int i = 0; i < 4; ++i) {
            hull += c.facet[i] == FacetRole::HULL;
            shared += c.facet[i] == FacetRole::SHARED;
            if (c.facet[i] == FacetRole::OWN) {
              ++own;
              // The neighbour's circumcenter is equidistant from the shared facet.
              const Eigen::Vector3d& n = c.neighbor_circumcenter[i];
              const double rn = (n - dt.points[c.v[(i + 1) % 4]]).norm();
              EXPECT_NEAR((n - dt.points[c.v[(i + 2) % 4]]).norm(), rn, 1e-9 * rn);
              EXPECT_NEAR((n - dt.points[c.v[(i + 3) % 4]]).norm(), rn, 1e-9 * rn);
            }
          }
        });
    std::size_t cells = 0, hull = 0, own = 0, shared = 0;
    for (const auto& k : count) {
      cells += k[0];
      hull += k[1];
      own += k[2];
      shared += k[3];
    }
    // Every cell once; every interior facet visited from exactly one of its cells.
    EXPECT_EQ(cells, dt.number_of_cells);
    EXPECT_EQ(own, shared);
    EXPECT_EQ(4 * cells, hull + 2 * own);
    EXPECT_GT(hull, 0u);
  }
}

TEST(Triangulate, CircumcentersTheSameWhicheverPassComputesThem)
{
  // The first pass that reads the circumcenters computes them as it goes, unless
  // it reads its neighbours' too (then all are computed before it): both ways, and
  // in later passes, the same bits per cell.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> P;
  for (int i = 0; i < 3000; ++i)
    P.emplace_back(u(random), u(random), 0.1 * u(random));
  const std::vector<Eigen::Vector3d> points = makeUniquePoints(P).points;
  using Centers = std::vector<std::pair<std::array<int, 4>, Eigen::Vector3d>>;
  const auto centers = [](const Triangulation& dt, unsigned data, int threads) {
    Centers out;
    std::vector<Centers> part(threads);
    forEachCell(dt, data, threads, [&](const CellView& c, int thread) {
      auto v = c.v;
      std::sort(v.begin(), v.end());
      part[thread].emplace_back(v, c.circumcenter);
    });
    for (const auto& p : part)
      out.insert(out.end(), p.begin(), p.end());
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
      return a.first < b.first;
    });
    return out;
  };
  const Triangulation first_alone = triangulate(points);
  const Triangulation first_with_neighbours = triangulate(points);
  const Centers alone = centers(first_alone, CellView::CIRCUMCENTER, 2);
  const Centers with_neighbours =
      centers(first_with_neighbours, CellView::CIRCUMCENTER | CellView::NEIGHBORS, 2);
  ASSERT_EQ(alone.size(), first_alone.number_of_cells);
  EXPECT_TRUE(alone == with_neighbours);
  EXPECT_TRUE(alone == centers(first_alone, CellView::CIRCUMCENTER, 1));
  EXPECT_TRUE(alone ==
              centers(first_alone, CellView::NEIGHBORS | CellView::CIRCUMCENTER, 1));
}

TEST(Triangulate, EveryEdgeStoodForByACell)
{
  std::vector<Eigen::Vector3d> P;
  std::mt19937 random(3);
  std::normal_distribution<double> g;
  for (int i = 0; i < 2000; ++i) { // a sphere: every point on the hull
    const Eigen::Vector3d x(g(random), g(random), g(random));
    P.push_back(x.normalized());
  }
  for (int i = 0; i < 2000; ++i)
    P.emplace_back(g(random), g(random), g(random));
  const Triangulation dt = triangulate(makeUniquePoints(P).points);
  ASSERT_EQ(dt.dimension, 3);
  const auto edge = [](int a, int b) {
    return std::make_pair(std::min(a, b), std::max(a, b));
  };
  std::vector<std::pair<int, int>> all, stood_for;
  std::size_t slots = 0;
  forEachCell(dt, CellView::EDGES, 1, [&](const CellView& c, int) {
    for (int e = 0; e < 6; ++e) {
      const auto& ends = CellView::EDGE_ENDS[e];
      all.push_back(edge(c.v[ends[0]], c.v[ends[1]]));
      if (c.edges & (1u << e))
        stood_for.push_back(all.back());
    }
    slots += 6;
  });
  const std::size_t offers = stood_for.size();
  for (auto* edges : {&all, &stood_for}) {
    std::sort(edges->begin(), edges->end());
    edges->erase(std::unique(edges->begin(), edges->end()), edges->end());
  }
  EXPECT_EQ(stood_for, all);
  // Far fewer than the six edges of every cell (about a third of them).
  EXPECT_LT(offers, slots / 2) << offers << " of " << slots;
}

TEST(Triangulate, FacetsFaceAwayFromTheirCellsAndTheHullOutward)
{
  // A cube of random points with a near-flat lid: cells flat to rounding on the
  // hull, where n . (p - p0) in floating point is noise.
  std::vector<Eigen::Vector3d> P;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 3000; ++i)
    P.emplace_back(u(random), u(random), u(random));
  for (int i = 0; i < 500; ++i)
    P.emplace_back(u(random), u(random), 2.0 + 1e-13 * u(random));
  const Triangulation dt = triangulate(makeUniquePoints(P).points);
  ASSERT_EQ(dt.dimension, 3);
  const auto& X = dt.points;
  const auto normal = [&](const std::array<int, 3>& f) {
    return Eigen::Vector3d((X[f[1]] - X[f[0]]).cross(X[f[2]] - X[f[0]]));
  };
  // Each facet's sides as its cells see them: the two cells of an interior facet
  // opposite, the one cell of a hull facet as the hull facet.
  std::vector<std::pair<std::array<int, 3>, int>> sides;
  std::size_t checked = 0;
  forEachCell(dt, CellView::FACETS, 1, [&](const CellView& c, int) {
    for (int i = 0; i < 4; ++i) {
      std::array<int, 3> f;
      for (int k = 0, m = 0; k < 4; ++k)
        if (k != i)
          f[m++] = c.v[k];
      std::sort(f.begin(), f.end());
      sides.emplace_back(f, c.outwardSide(i));
      // Where floating point is sure of the side, the same.
      const double s = normal(f).dot(X[c.v[i]] - X[f[0]]);
      if (std::abs(s) > 1e-9) {
        EXPECT_EQ(c.outwardSide(i), s > 0.0 ? -1 : 1);
        ++checked;
      }
    }
  });
  EXPECT_GT(checked, sides.size() * 9 / 10);
  std::vector<std::pair<std::array<int, 3>, int>> hull;
  const Eigen::Vector3d inside(0.0, 0.0, 0.5);
  forEachHullFacet(dt, [&](const HullFacet& h) {
    hull.emplace_back(h.v, h.outward);
    // The hull is convex and contains the inside point.
    EXPECT_GT(h.outward * normal(h.v).dot(X[h.v[0]] - (inside - dt.offset)), 0.0);
  });
  std::sort(sides.begin(), sides.end());
  std::sort(hull.begin(), hull.end());
  std::size_t interior = 0, h = 0;
  for (std::size_t k = 0; k < sides.size(); ++k) {
    if (k + 1 < sides.size() && sides[k + 1].first == sides[k].first) {
      EXPECT_EQ(sides[k].second, -sides[k + 1].second);
      ++interior;
      ++k;
    }
    else {
      ASSERT_LT(h, hull.size());
      EXPECT_EQ(hull[h], sides[k]);
      ++h;
    }
  }
  EXPECT_EQ(h, hull.size());
  EXPECT_EQ(4 * dt.number_of_cells, 2 * interior + hull.size());
  EXPECT_GT(hull.size(), 100u);
}

/** The cells of a triangulation as sorted vertex ids, sorted. */
std::vector<std::array<int, 4>>
sortedCells(const Triangulation& dt)
{
  std::vector<std::array<int, 4>> out;
  forEachCell(dt, 0, 1, [&](const CellView& c, int) {
    auto v = c.v;
    std::sort(v.begin(), v.end());
    out.push_back(v);
  });
  std::sort(out.begin(), out.end());
  return out;
}

/** The same from CGAL's Delaunay_triangulation_3, the reference. */
std::vector<std::array<int, 4>>
cgalCells(const std::vector<Eigen::Vector3d>& points)
{
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Delaunay = CGAL::Delaunay_triangulation_3<
      K,
      CGAL::Triangulation_data_structure_3<
          CGAL::Triangulation_vertex_base_with_info_3<int, K>,
          CGAL::Delaunay_triangulation_cell_base_3<K>>>;
  std::vector<std::pair<K::Point_3, int>> sites;
  for (std::size_t i = 0; i < points.size(); ++i)
    sites.emplace_back(K::Point_3(points[i].x(), points[i].y(), points[i].z()),
                       static_cast<int>(i));
  const Delaunay dt(sites.begin(), sites.end());
  std::vector<std::array<int, 4>> out;
  for (const auto c : dt.finite_cell_handles()) {
    std::array<int, 4> v;
    for (int i = 0; i < 4; ++i)
      v[i] = c->vertex(i)->info();
    std::sort(v.begin(), v.end());
    out.push_back(v);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Triangulate, SameCellsAsCgalOnDegenerateInput)
{
  // Grid points: nearly every cell has co-spherical neighbours, and most points
  // reach the hull in the plane of a hull facet, so only CGAL's symbolic
  // perturbation (of spheres, and of circles on the hull) makes the triangulation
  // unique. Then points on a sphere of integer radius (all co-spherical), and a
  // random sample of a torus.
  std::mt19937 random(5);
  std::uniform_real_distribution<double> u(0.0, 19.0);
  std::vector<std::vector<Eigen::Vector3d>> clouds(3);
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      for (int k = 0; k < 20; ++k)
        clouds[0].emplace_back(i, j, k);
  for (int i = 0; i < 4000; ++i)
    clouds[0].emplace_back(u(random), u(random), u(random));
  for (int i = -25; i <= 25; ++i)
    for (int j = -25; j <= 25; ++j)
      for (int k = -25; k <= 25; ++k)
        if (i * i + j * j + k * k == 625)
          clouds[1].emplace_back(i, j, k);
  clouds[1].emplace_back(0.5, 0.25, 0.125);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  for (int i = 0; i < 20000; ++i) {
    const double a = angle(random), b = angle(random);
    clouds[2].emplace_back(
        (3 + std::cos(b)) * std::cos(a), (3 + std::cos(b)) * std::sin(a), std::sin(b));
  }
  for (const auto& cloud : clouds) {
    const std::vector<Eigen::Vector3d> points = makeUniquePoints(cloud).points;
    const Triangulation dt = triangulate(points);
    ASSERT_EQ(dt.dimension, 3);
    const auto cells = sortedCells(dt);
    EXPECT_GT(cells.size(), points.size());
    EXPECT_EQ(cells.size(), dt.number_of_cells);
    EXPECT_TRUE(cells == cgalCells(dt.points));
  }
}

TEST(Triangulate, SameCellsWithSeveralThreads)
{
  // Enough points that every thread gets a stretch of the curve (ten thousand
  // each): a grid (co-spherical points everywhere: only the symbolic perturbation
  // decides), a torus sample (a surface, as scans are), a random volume.
  std::mt19937 random(11);
  std::vector<std::vector<Eigen::Vector3d>> clouds(3);
  for (int i = 0; i < 36; ++i)
    for (int j = 0; j < 36; ++j)
      for (int k = 0; k < 36; ++k)
        clouds[0].emplace_back(i, j, k);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), u(0.0, 1.0);
  for (int i = 0; i < 45000; ++i) {
    const double a = angle(random), b = angle(random);
    clouds[1].emplace_back(
        (3 + std::cos(b)) * std::cos(a), (3 + std::cos(b)) * std::sin(a), std::sin(b));
    clouds[2].emplace_back(u(random), u(random), u(random));
  }
  for (const auto& cloud : clouds) {
    const std::vector<Eigen::Vector3d> points = makeUniquePoints(cloud).points;
    const auto alone = sortedCells(triangulate(points, 1));
    for (const int threads : {2, 3, 4}) {
      const Triangulation dt = triangulate(points, threads);
      ASSERT_EQ(dt.dimension, 3);
      EXPECT_TRUE(sortedCells(dt) == alone) << threads << " threads";
      // The neighbours: every interior facet between two cells that share it.
      std::size_t hull = 0, own = 0, shared = 0, far = 0;
      forEachCell(dt,
                  CellView::CIRCUMCENTER | CellView::NEIGHBORS,
                  1,
                  [&](const CellView& c, int) {
                    for (int i = 0; i < 4; ++i) {
                      hull += c.facet[i] == FacetRole::HULL;
                      shared += c.facet[i] == FacetRole::SHARED;
                      if (c.facet[i] != FacetRole::OWN)
                        continue;
                      ++own;
                      const Eigen::Vector3d& n = c.neighbor_circumcenter[i];
                      const double r = (n - dt.points[c.v[(i + 1) % 4]]).norm();
                      for (const int k : {2, 3})
                        far += std::abs((n - dt.points[c.v[(i + k) % 4]]).norm() - r) >
                               1e-9 * r;
                    }
                  });
      EXPECT_EQ(own, shared);
      EXPECT_EQ(4 * dt.number_of_cells, hull + 2 * own);
      EXPECT_EQ(far, 0u);
    }
  }
}

TEST(Triangulate, RecentresLargeCoordinates)
{
  std::vector<Eigen::Vector3d> P{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (auto& p : P)
    p += Eigen::Vector3d(5e6, 5e6, 1e3);
  const Triangulation dt = triangulate(P);
  ASSERT_EQ(dt.dimension, 3);
  EXPECT_LT(dt.points[0].norm(), 1.0);
  EXPECT_EQ(dt.points[0] + dt.offset, P[0]);
}

TEST(Circumcenter, NearlyFlatTetrahedronStaysFinite)
{
  // A sliver: the circumcenter is far away but still equidistant.
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(0.7, 0.2, 1e-9);
  const Eigen::Vector3d cc = tetrahedronCircumcenter(a, b, c, d);
  ASSERT_TRUE(std::isfinite(cc.z()));
  EXPECT_GT(std::abs(cc.z()), 1e6);
  const double r = (cc - a).norm();
  for (const auto& x : {b, c, d})
    EXPECT_NEAR((cc - x).norm(), r, 1e-9 * r);
  const Eigen::Vector3d t = triangleCircumcenter(a, b, c);
  EXPECT_NEAR(t.x(), 0.5, 1e-15);
  EXPECT_NEAR(t.y(), 0.5, 1e-15);
}
