/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * cocone_scan_eval: score border detection on range scans against the scans' own
 * truth. A range image's grid is the scanned surface's mesh: neighbouring valid
 * pixels whose 3D edges are short form triangles, and that mesh's borders (outline
 * and occlusion holes) are the truth. Each scan is then treated as an unorganized
 * cloud and given to
 *  - this library at its default, and with the paper's test (no spacing and no
 *    half-disk test) at rho = 1.5 and at rho = 2.5;
 *  - pcl::BoundaryEstimation (normals from 20 neighbours, 20 neighbours, pi/2);
 *  - pcl::GreedyProjectionTriangulation (the borders of its mesh).
 *
 *   cocone_scan_eval SCAN.ply [SCAN.ply ...]
 *
 * A reported border point is correct if a true border point lies within 2 median
 * grid spacings; a true border point is found if a reported one lies that close.
 * Holes of the grid with at most 8 border vertices (a pixel or two missing) are below
 * the sampling resolution and do not count.
 */

#include <pcl/common/point_tests.h>
#include <pcl/features/boundary.h>
#include <pcl/features/normal_3d.h>
#include <pcl/io/ply_io.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/search/kdtree.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone_boundary.h>
#include <pcl/surface/gp3.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

/** Border loops of the grid with at most this many vertices (up to about two
 * missing pixels) do not count as holes. */
constexpr std::size_t MIN_LOOP = 8;

struct Truth {
  std::vector<int> border; // indices into the compact cloud
  std::size_t loops = 0;
  double spacing = 0.0; // median grid edge
};

/** Triangulate the range grid and take its borders. */
Truth
gridTruth(const Cloud& organized, const std::vector<int>& compact_of)
{
  const int w = organized.width, h = organized.height;
  const auto valid = [&](int r, int c) { return pcl::isFinite(organized(c, r)); };
  std::vector<double> lengths;
  for (int r = 0; r + 1 < h; ++r)
    for (int c = 0; c + 1 < w; ++c)
      if (valid(r, c) && valid(r, c + 1))
        lengths.push_back(
            (organized(c, r).getVector3fMap() - organized(c + 1, r).getVector3fMap())
                .norm());
  Truth truth;
  std::nth_element(
      lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  truth.spacing = lengths[lengths.size() / 2];
  const double longest = 4.0 * truth.spacing; // longer edges jump across depth gaps
  const auto close = [&](int r0, int c0, int r1, int c1) {
    return (organized(c0, r0).getVector3fMap() - organized(c1, r1).getVector3fMap())
               .norm() < longest;
  };
  std::vector<pcl::cocone::Triangle> triangles;
  for (int r = 0; r + 1 < h; ++r)
    for (int c = 0; c + 1 < w; ++c) {
      const int a[2] = {r, c}, b[2] = {r, c + 1}, d[2] = {r + 1, c},
                e[2] = {r + 1, c + 1};
      const auto id = [&](const int* p) { return compact_of[p[0] * w + p[1]]; };
      const auto ok = [&](const int* p, const int* q, const int* s) {
        return valid(p[0], p[1]) && valid(q[0], q[1]) && valid(s[0], s[1]) &&
               close(p[0], p[1], q[0], q[1]) && close(q[0], q[1], s[0], s[1]) &&
               close(s[0], s[1], p[0], p[1]);
      };
      if (ok(a, b, d))
        triangles.push_back({id(a), id(d), id(b)});
      if (ok(b, e, d))
        triangles.push_back({id(b), id(d), id(e)});
    }
  std::size_t n = 0;
  for (const int i : compact_of)
    n = std::max<std::size_t>(n, i + 1);
  // Border half-edges, traced into loops; a grid mesh can touch itself at a corner,
  // so a vertex may start several.
  const pcl::cocone::EdgeIncidences inc(triangles);
  std::vector<std::vector<int>> out(n);
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (inc.count(e) == 1) {
      const bool fwd = inc.forward[inc.first[e]];
      out[fwd ? inc.edges[e][0] : inc.edges[e][1]].push_back(fwd ? inc.edges[e][1]
                                                                 : inc.edges[e][0]);
    }
  for (std::size_t s = 0; s < n; ++s)
    while (!out[s].empty()) {
      std::vector<int> loop;
      int v = static_cast<int>(s);
      while (!out[v].empty()) {
        loop.push_back(v);
        const int w = out[v].back();
        out[v].pop_back();
        v = w;
      }
      // Holes of a few missing pixels are below the sampling resolution: a surface
      // reconstruction is right to close them.
      if (loop.size() > MIN_LOOP) {
        ++truth.loops;
        truth.border.insert(truth.border.end(), loop.begin(), loop.end());
      }
    }
  std::sort(truth.border.begin(), truth.border.end());
  truth.border.erase(std::unique(truth.border.begin(), truth.border.end()),
                     truth.border.end());
  return truth;
}

struct Score {
  double precision = 0.0, recall = 0.0, f1 = 0.0;
};

Score
score(const Cloud& cloud, const std::vector<int>& reported, const Truth& truth)
{
  const auto nearest = [&](const std::vector<int>& set) {
    Cloud::Ptr sub(new Cloud);
    for (const int i : set)
      sub->push_back(cloud[i]);
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    if (!sub->empty())
      tree.setInputCloud(sub);
    return std::make_pair(sub, tree);
  };
  const double r = 2.0 * truth.spacing;
  const auto count_close = [&](const std::vector<int>& from,
                               const std::vector<int>& to) {
    if (from.empty() || to.empty())
      return std::size_t(0);
    auto [sub, tree] = nearest(to);
    std::size_t n = 0;
    pcl::Indices k(1);
    std::vector<float> d(1);
    for (const int i : from)
      if (tree.nearestKSearch(cloud[i], 1, k, d) > 0 && d[0] <= r * r)
        ++n;
    return n;
  };
  Score s;
  s.precision = reported.empty() ? 0.0
                                 : double(count_close(reported, truth.border)) /
                                       double(reported.size());
  s.recall = double(count_close(truth.border, reported)) / double(truth.border.size());
  s.f1 = s.precision + s.recall > 0.0
             ? 2.0 * s.precision * s.recall / (s.precision + s.recall)
             : 0.0;
  return s;
}

double
since(std::chrono::steady_clock::time_point t)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void
report(const char* method,
       const Score& s,
       std::size_t loops,
       std::size_t points,
       double sec)
{
  std::printf("  %-28s border F1 %.2f (precision %.2f recall %.2f)  loops %5zu  "
              "points %6zu  %.2f s\n",
              method,
              s.f1,
              s.precision,
              s.recall,
              loops,
              points,
              sec);
}

void
runCocone(const Cloud::Ptr& cloud,
          const Truth& truth,
          const char* name,
          double ratio,
          double spacing_factor,
          double gap_angle)
{
  const auto t = std::chrono::steady_clock::now();
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  cocone.setRatio(ratio);
  cocone.setSpacingFactor(spacing_factor);
  cocone.setGapAngle(gap_angle);
  pcl::PolygonMesh mesh;
  cocone.reconstruct(mesh);
  const double sec = since(t);
  std::vector<pcl::Vertices> loops;
  cocone.getBoundaryLoops(loops);
  std::vector<int> border;
  for (const auto& l : loops)
    border.insert(border.end(), l.vertices.begin(), l.vertices.end());
  std::sort(border.begin(), border.end());
  border.erase(std::unique(border.begin(), border.end()), border.end());
  pcl::PointIndices undersampled;
  cocone.getBoundaryPointIndices(undersampled);
  char label[64];
  std::snprintf(
      label, sizeof(label), "%s (rho %.2f) borders", name, cocone.getUsedRatio());
  report(label, score(*cloud, border, truth), loops.size(), border.size(), sec);
  std::snprintf(label, sizeof(label), "%s undersampled", name);
  report(label,
         score(*cloud, undersampled.indices, truth),
         0,
         undersampled.indices.size(),
         sec);
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCAN.ply [SCAN.ply ...]\n", argv[0]);
    return 1;
  }
  for (int a = 1; a < argc; ++a) {
    Cloud organized;
    if (pcl::io::loadPLYFile(argv[a], organized) < 0 || !organized.isOrganized()) {
      std::fprintf(stderr, "%s: not a range grid\n", argv[a]);
      continue;
    }
    Cloud::Ptr cloud(new Cloud);
    std::vector<int> compact_of(organized.size(), -1);
    for (std::size_t i = 0; i < organized.size(); ++i)
      if (pcl::isFinite(organized[i])) {
        compact_of[i] = static_cast<int>(cloud->size());
        cloud->push_back(organized[i]);
      }
    const Truth truth = gridTruth(organized, compact_of);
    std::printf(
        "%s: %zu points, truth: %zu border points on %zu loops (spacing %.5f)\n",
        argv[a],
        cloud->size(),
        truth.border.size(),
        truth.loops,
        truth.spacing);

    const pcl::cocone::Parameters defaults;
    runCocone(cloud, truth, "cocone default", 0.0, 3.0, defaults.gap_angle);
    runCocone(cloud, truth, "cocone paper", 1.5, 0.0, 0.0);
    runCocone(cloud, truth, "cocone paper", 2.5, 0.0, 0.0);

    // pcl::BoundaryEstimation with estimated normals.
    auto t = std::chrono::steady_clock::now();
    pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(
        new pcl::search::KdTree<pcl::PointXYZ>);
    pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
    ne.setInputCloud(cloud);
    ne.setSearchMethod(tree);
    ne.setKSearch(20);
    ne.compute(*normals);
    pcl::BoundaryEstimation<pcl::PointXYZ, pcl::Normal, pcl::Boundary> be;
    be.setInputCloud(cloud);
    be.setInputNormals(normals);
    be.setSearchMethod(tree);
    be.setKSearch(20);
    pcl::PointCloud<pcl::Boundary> flags;
    be.compute(flags);
    std::vector<int> be_points;
    for (std::size_t i = 0; i < flags.size(); ++i)
      if (flags[i].boundary_point)
        be_points.push_back(static_cast<int>(i));
    report("BoundaryEstimation points",
           score(*cloud, be_points, truth),
           0,
           be_points.size(),
           since(t));

    // Greedy projection: the borders of its mesh.
    t = std::chrono::steady_clock::now();
    pcl::PointCloud<pcl::PointNormal>::Ptr with_normals(
        new pcl::PointCloud<pcl::PointNormal>);
    pcl::concatenateFields(*cloud, *normals, *with_normals);
    pcl::search::KdTree<pcl::PointNormal>::Ptr tree2(
        new pcl::search::KdTree<pcl::PointNormal>);
    pcl::GreedyProjectionTriangulation<pcl::PointNormal> gp3;
    gp3.setSearchRadius(6.0 * truth.spacing);
    gp3.setMu(2.5);
    gp3.setMaximumNearestNeighbors(100);
    gp3.setInputCloud(with_normals);
    gp3.setSearchMethod(tree2);
    pcl::PolygonMesh gp3_mesh;
    gp3.reconstruct(gp3_mesh);
    std::vector<pcl::cocone::Triangle> tris;
    for (const auto& p : gp3_mesh.polygons)
      tris.push_back({p.vertices[0], p.vertices[1], p.vertices[2]});
    const auto gp3_loops = pcl::cocone::boundaryLoops(tris, cloud->size());
    std::vector<int> gp3_border;
    for (const auto& l : gp3_loops)
      gp3_border.insert(gp3_border.end(), l.begin(), l.end());
    std::sort(gp3_border.begin(), gp3_border.end());
    gp3_border.erase(std::unique(gp3_border.begin(), gp3_border.end()),
                     gp3_border.end());
    report("GP3 (k=20 normals) borders",
           score(*cloud, gp3_border, truth),
           gp3_loops.size(),
           gp3_border.size(),
           since(t));
  }
  return 0;
}
