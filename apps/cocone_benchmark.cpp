/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * cocone_benchmark: wall time per stage, peak memory and output quality of this
 * library next to CGAL's Delaunay triangulation alone (the floor: no Delaunay-based
 * method can be faster) and to other reconstruction and border detection methods.
 *
 *   cocone_benchmark generate torus|saddle random|even N OUT.ply [SEED [NOISE]]
 *   cocone_benchmark generate terrain|torus stream N OUT.ply [SEED]
 *   cocone_benchmark convert CLOUD OUT.ply
 *   cocone_benchmark METHOD CLOUD [--truth auto|closed|saddle|none] [--threads T]
 *   cocone_benchmark tiled CLOUD --tile_points N [--halo S] [--in_flight K]
 *                    [--threads T]
 *
 * generate writes seeded samples (area-uniform random or evenly spaced) of the torus
 * R = 1, r = 0.4 or of the monkey saddle over [-1,1]^2, with Gaussian noise of NOISE
 * sample spacings along the normal; stream writes area-uniform random samples of the
 * torus or of a terrain with walls and holes (Terrain: 7 border loops, Euler
 * characteristic -5) as they are drawn, for clouds larger than the memory; convert
 * writes the finite
 * points of any readable cloud; both as binary PLY of float x, y, z (what the Open3D
 * script reads). METHOD is one of
 *   delaunay             CGAL::Delaunay_triangulation_3 of the points
 *   detect               this library up to the boundary detection (stages 1-3)
 *   cocone               this library, the whole reconstruction
 *   gp3                  pcl::GreedyProjectionTriangulation on k = 20 normals
 *   boundary_estimation  pcl::BoundaryEstimation on k = 20 normals
 *   advancing_front      CGAL::advancing_front_surface_reconstruction
 * (tiled: this library in tiles of at most N points against one piece, see below)
 * and prints one line of key=value fields: seconds, peak_mb (peak resident memory of
 * the process) and base_mb (after reading the cloud), per stage seconds, and the
 * output's triangles, boundary_edges (edges in one triangle) and euler (V - E + F over
 * the vertices used), border_points, recall and precision when the truth is known.
 * Each measurement runs in its own process so that its peak memory belongs to it;
 * scripts/benchmark.sh runs the grid and prints the table.
 *
 * Border points: detect and boundary_estimation report points; of a mesh the border
 * points are the vertices of its boundary edges. The truth (--truth):
 *   closed  the surface has no border: every reported point is false
 *   saddle  the monkey saddle over [-1,1]^2: points within 1.5 local spacings (mean
 *           nearest-neighbour distance of the 10 nearest points) of the square's edge
 *   auto    an organized PLY (a range scan): the borders of its grid, as in
 *           cocone_scan_eval; otherwise none
 * A reported point is correct if a true border point lies within 2 spacings, a true
 * border point is found if a reported one lies that close (scoreBorder()).
 *
 * tiled runs the whole reconstruction twice on the cloud, in one piece and with
 * pcl::cocone::runTiled() (halo S local spacings, K tiles at a time), each in a child
 * process forked before either starts (so both start from the same memory), one
 * after the other, and prints for both seconds, peak_mb, triangles, euler, loops
 * (border loops), manifold (an oriented 2-manifold), components and boundary points,
 * and between them: differing (triangles, as vertex sets, in one and not the other,
 * both ways), differing_share (of the one-piece triangles, in percent),
 * turned (common triangles oriented the other way) and labels_differing (points
 * undersampled in one run only), with the tiling's tiles, halo_points,
 * patches_flipped, the stitch's repairs, and the seconds of the tiles and of the
 * cut and the stitch.
 */

#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/io/ply_io.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/search/kdtree.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/tiling.h>
#include <pcl/point_types.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "benchmark_advancing_front.h"
#include "border_truth.h"
#include "cloud_io.h"
#include "peer_methods.h"
#include <support/surfaces.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using pcl::cocone::Triangle;

double
peakMegabytes()
{
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0; // kilobytes on Linux
}

class Stopwatch {
public:
  double
  seconds() const
  {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_)
        .count();
  }

  /** Seconds since the previous lap (or the start). */
  double
  lap()
  {
    const double now = seconds(), since = now - last_;
    last_ = now;
    return since;
  }

private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double last_ = 0.0;
};

bool
writePly(const std::string& path, const std::vector<Eigen::Vector3d>& points)
{
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f)
    return false;
  const std::uint16_t probe = 1;
  const bool little = *reinterpret_cast<const std::uint8_t*>(&probe) == 1;
  std::fprintf(f,
               "ply\nformat %s 1.0\nelement vertex %zu\nproperty float x\n"
               "property float y\nproperty float z\nend_header\n",
               little ? "binary_little_endian" : "binary_big_endian",
               points.size());
  std::vector<float> xyz;
  xyz.reserve(3 * points.size());
  for (const auto& p : points)
    xyz.insert(xyz.end(), {float(p.x()), float(p.y()), float(p.z())});
  const bool ok = std::fwrite(xyz.data(), sizeof(float), xyz.size(), f) == xyz.size();
  return std::fclose(f) == 0 && ok;
}

Cloud::Ptr
toCloud(const std::vector<Eigen::Vector3d>& points)
{
  Cloud::Ptr cloud(new Cloud);
  cloud->reserve(points.size());
  for (const auto& p : points)
    cloud->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  return cloud;
}

/** Read the finite points of a cloud; with \a grid, the border truth of a range grid
 * (spacing 0 if the file is not one). */
bool
readPoints(const std::string& path,
           std::vector<Eigen::Vector3d>& points,
           cocone_app::BorderTruth* grid)
{
  if (grid && cocone_app::extension(path) == "ply") {
    Cloud organized;
    if (pcl::io::loadPLYFile(path, organized) >= 0 && organized.isOrganized()) {
      std::vector<int> compact_of(organized.size(), -1);
      for (std::size_t i = 0; i < organized.size(); ++i)
        if (pcl::isFinite(organized[i])) {
          compact_of[i] = static_cast<int>(points.size());
          points.emplace_back(organized[i].getVector3fMap().cast<double>());
        }
      *grid = cocone_app::gridBorderTruth(organized, compact_of);
      return true;
    }
  }
  pcl::PCLPointCloud2 blob;
  std::string error;
  std::vector<Eigen::Vector3d> all;
  if (!cocone_app::readCloud(path, blob, error) ||
      !cocone_app::extractXYZ(blob, all, error)) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), error.c_str());
    return false;
  }
  for (const auto& p : all)
    if (p.allFinite())
      points.push_back(p);
  return true;
}

/** Per point, the distance to its nearest other point. */
std::vector<double>
nearestDistances(const Cloud::Ptr& cloud, pcl::search::Search<pcl::PointXYZ>& tree)
{
  std::vector<double> d(cloud->size(), 0.0);
  pcl::Indices k(2);
  std::vector<float> d2(2);
  for (std::size_t i = 0; i < cloud->size(); ++i)
    if (tree.nearestKSearch((*cloud)[i], 2, k, d2) == 2)
      d[i] = std::sqrt(d2[1]);
  return d;
}

double
mean(const std::vector<double>& v)
{
  double sum = 0.0;
  for (const double x : v)
    sum += x;
  return v.empty() ? 0.0 : sum / double(v.size());
}

/** The monkey saddle's border: points within 1.5 local spacings of the square's
 * edge, the local spacing being the mean nearest-neighbour distance over the 10
 * nearest points (random samples are denser in some places than in others). */
cocone_app::BorderTruth
saddleTruth(const Cloud::Ptr& cloud)
{
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  const std::vector<double> nearest = nearestDistances(cloud, tree);
  // The edge as a polyline 1e-4 apart in x or y: at most 6e-4 in space, below the
  // spacing of 3M samples.
  Cloud::Ptr edge(new Cloud);
  const int steps = 20000;
  for (int i = 0; i <= steps; ++i) {
    const double t = -1.0 + 2.0 * i / steps;
    for (const double s : {-1.0, 1.0})
      for (const auto& xy : {Eigen::Vector2d(s, t), Eigen::Vector2d(t, s)})
        edge->push_back(pcl::PointXYZ(
            float(xy.x()),
            float(xy.y()),
            float(xy.x() * xy.x() * xy.x() - 3.0 * xy.x() * xy.y() * xy.y())));
  }
  pcl::KdTreeFLANN<pcl::PointXYZ> edge_tree;
  edge_tree.setInputCloud(edge);
  cocone_app::BorderTruth truth;
  truth.spacing = mean(nearest);
  truth.loops = 1;
  pcl::Indices k;
  std::vector<float> d2;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const int found = tree.nearestKSearch((*cloud)[i], 10, k, d2);
    double local = 0.0;
    for (int j = 0; j < found; ++j)
      local += nearest[k[j]];
    local /= std::max(found, 1);
    pcl::Indices e(1);
    std::vector<float> e2(1);
    if (edge_tree.nearestKSearch((*cloud)[i], 1, e, e2) > 0 &&
        std::sqrt(e2[0]) <= 1.5 * local)
      truth.border.push_back(static_cast<int>(i));
  }
  return truth;
}

/** What a method produced. */
struct Output {
  bool mesh = false;
  std::vector<Triangle> triangles;
  std::size_t vertices = 0; ///< ids of the triangles are below this
  bool has_border = false;
  std::vector<int> border; ///< indices of the points
  std::vector<std::pair<std::string, double>> stages;
  std::string extra; ///< further key=value fields
};

void
delaunayAlone(const std::vector<Eigen::Vector3d>& points, Output& out)
{
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  Stopwatch watch;
  std::vector<K::Point_3> p;
  p.reserve(points.size());
  for (const auto& q : points)
    p.emplace_back(q.x(), q.y(), q.z());
  CGAL::Delaunay_triangulation_3<K> dt(p.begin(), p.end());
  out.stages.emplace_back("delaunay", watch.lap());
  out.extra = "cells=" + std::to_string(dt.number_of_finite_cells());
}

void
cocone(const std::vector<Eigen::Vector3d>& points,
       bool reconstruct,
       unsigned threads,
       Output& out)
{
  pcl::cocone::Parameters parameters;
  parameters.threads = threads;
  const pcl::cocone::Result r =
      pcl::cocone::run(points,
                       parameters,
                       reconstruct ? pcl::cocone::Stages::RECONSTRUCTION
                                   : pcl::cocone::Stages::BOUNDARY_DETECTION);
  const auto& t = r.timings;
  out.stages = {{"unique", t.unique / 1e3},
                {"delaunay", t.delaunay / 1e3},
                {"noise", t.noise / 1e3},
                {"voronoi", t.voronoi / 1e3},
                {"boundary", t.boundary / 1e3}};
  char extra[160];
  std::snprintf(extra,
                sizeof(extra),
                "rho=%.2f noise=%.3f after=%.3f smoothed=%d outliers=%zu threads=%u",
                r.ratio,
                r.noise_level,
                r.noise_after_smoothing,
                int(r.smoothed),
                r.outlier_indices.size(),
                threads);
  out.extra = extra;
  if (!reconstruct) {
    out.has_border = true;
    out.border = r.boundary_indices;
    return;
  }
  out.stages.emplace_back("reconstruction", t.reconstruction / 1e3);
  out.mesh = true; // its border points are its mesh's, as for the other meshes
  out.triangles = r.polygons; // over the indices of the points, like the others'
  out.vertices = points.size();
}

void
greedyProjection(const Cloud::Ptr& cloud, Output& out)
{
  Stopwatch watch;
  cocone_app::Tree::Ptr tree(new cocone_app::Tree);
  const auto normals = cocone_app::estimateNormals(cloud, tree);
  out.stages.emplace_back("normals", watch.lap());
  // The search radius scales with the sampling; the mean spacing sets it.
  const double radius = 6.0 * mean(nearestDistances(cloud, *tree));
  out.stages.emplace_back("spacing", watch.lap());
  out.triangles = cocone_app::greedyProjection(cloud, normals, radius);
  out.stages.emplace_back("triangulation", watch.lap());
  out.mesh = true;
  out.vertices = cloud->size();
  char extra[64];
  std::snprintf(extra, sizeof(extra), "search_radius=%.6g", radius);
  out.extra = extra;
}

void
boundaryEstimation(const Cloud::Ptr& cloud, Output& out)
{
  Stopwatch watch;
  cocone_app::Tree::Ptr tree(new cocone_app::Tree);
  const auto normals = cocone_app::estimateNormals(cloud, tree);
  out.stages.emplace_back("normals", watch.lap());
  out.border = cocone_app::boundaryEstimation(cloud, normals, tree);
  out.stages.emplace_back("boundary", watch.lap());
  out.has_border = true;
}

/** What a child process of the tiled comparison reports: its figures... */
struct PieceFigures {
  bool ok = false;
  double seconds = 0.0, peak_mb = 0.0;
  std::size_t loops = 0, tiles = 0, halo_points = 0, patches_flipped = 0;
  std::size_t stitch_dropped = 0, seam_filled = 0;
  double tiles_seconds = 0.0, stitch_seconds = 0.0;
};

/** ... and its output. */
struct Piece : PieceFigures {
  std::vector<Triangle> polygons;
  std::vector<int> boundary;
};

template <typename T>
void
writeVector(FILE* f, const std::vector<T>& v)
{
  const std::size_t n = v.size();
  std::fwrite(&n, sizeof(n), 1, f);
  std::fwrite(v.data(), sizeof(T), n, f);
}

template <typename T>
bool
readVector(FILE* f, std::vector<T>& v)
{
  std::size_t n = 0;
  if (std::fread(&n, sizeof(n), 1, f) != 1)
    return false;
  v.resize(n);
  return std::fread(v.data(), sizeof(T), n, f) == n;
}

/** In a child: the reconstruction, in one piece or tiled, written to \a f. */
void
reconstructPiece(std::vector<Eigen::Vector3d> points,
                 const pcl::cocone::Parameters& parameters,
                 const pcl::cocone::TilingOptions* tiling,
                 FILE* f)
{
  Stopwatch watch;
  pcl::cocone::TilingReport report;
  const pcl::cocone::Result r =
      tiling
          ? pcl::cocone::runTiled(std::move(points), parameters, *tiling, {}, &report)
          : pcl::cocone::run(
                std::move(points), parameters, pcl::cocone::Stages::RECONSTRUCTION);
  Piece piece;
  piece.seconds = watch.seconds();
  piece.peak_mb = peakMegabytes();
  piece.ok = r.error.empty();
  if (!piece.ok)
    std::fprintf(stderr, "%s\n", r.error.c_str());
  piece.loops = r.border_loops.size();
  piece.tiles = report.tiles;
  piece.halo_points = report.halo_points;
  piece.patches_flipped = report.patches_flipped;
  piece.stitch_dropped = report.stitch.dropped();
  piece.seam_filled = report.seam_filled;
  piece.tiles_seconds = report.tiles_ms / 1e3;
  piece.stitch_seconds = (report.cut_ms + report.stitch_ms) / 1e3;
  std::fwrite(static_cast<PieceFigures*>(&piece), sizeof(PieceFigures), 1, f);
  writeVector(f, r.polygons);
  writeVector(f, r.boundary_indices);
  std::fflush(f);
}

int
compareTiled(std::vector<Eigen::Vector3d> points,
             const pcl::cocone::Parameters& parameters,
             const pcl::cocone::TilingOptions& tiling)
{
  const double base_mb = peakMegabytes();
  FILE* files[2] = {std::tmpfile(), std::tmpfile()};
  int go[2];
  if (!files[0] || !files[1] || pipe(go) != 0) {
    std::fprintf(stderr, "cannot make the children's files\n");
    return 1;
  }
  // Both children forked now, the second waiting for the first to end: the same
  // memory at their start, one measurement at a time.
  pid_t child[2];
  for (int c = 1; c >= 0; --c) {
    child[c] = fork();
    if (child[c] < 0) {
      std::perror("fork");
      return 1;
    }
    if (child[c] == 0) {
      char byte;
      if (c == 1 && read(go[0], &byte, 1) != 1)
        _exit(1);
      reconstructPiece(std::move(points), parameters, c ? &tiling : nullptr, files[c]);
      _exit(0);
    }
  }
  std::vector<Eigen::Vector3d>().swap(points);
  Piece piece[2];
  for (int c = 0; c < 2; ++c) {
    int status = 0;
    waitpid(child[c], &status, 0);
    if (c == 0 && write(go[1], "g", 1) != 1)
      return 1;
    std::rewind(files[c]);
    Piece& p = piece[c];
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
        std::fread(static_cast<PieceFigures*>(&p), sizeof(PieceFigures), 1, files[c]) !=
            1 ||
        !readVector(files[c], p.polygons) || !readVector(files[c], p.boundary) ||
        !p.ok) {
      std::fprintf(stderr, "the %s run failed\n", c ? "tiled" : "one-piece");
      return 1;
    }
  }
  std::size_t vertices = 0;
  for (const auto& p : piece)
    for (const auto& t : p.polygons)
      vertices =
          std::max<std::size_t>(vertices, *std::max_element(t.begin(), t.end()) + 1);
  // Triangles as vertex sets; oriented ones to compare the common ones' turn.
  std::vector<std::pair<Triangle, Triangle>> sets[2];
  for (int c = 0; c < 2; ++c) {
    for (const auto& t : piece[c].polygons) {
      Triangle key = t;
      std::sort(key.begin(), key.end());
      Triangle oriented = t;
      std::rotate(oriented.begin(),
                  std::min_element(oriented.begin(), oriented.end()),
                  oriented.end());
      sets[c].emplace_back(key, oriented);
    }
    std::sort(sets[c].begin(), sets[c].end());
  }
  std::size_t differing = 0, turned = 0;
  for (std::size_t i = 0, j = 0; i < sets[0].size() || j < sets[1].size();) {
    if (j == sets[1].size() ||
        (i < sets[0].size() && sets[0][i].first < sets[1][j].first)) {
      ++differing;
      ++i;
    }
    else if (i == sets[0].size() || sets[1][j].first < sets[0][i].first) {
      ++differing;
      ++j;
    }
    else {
      turned += sets[0][i].second != sets[1][j].second;
      ++i;
      ++j;
    }
  }
  std::vector<int> labels;
  std::set_symmetric_difference(piece[0].boundary.begin(),
                                piece[0].boundary.end(),
                                piece[1].boundary.begin(),
                                piece[1].boundary.end(),
                                std::back_inserter(labels));
  std::printf(
      "method=tiled points=%zu tile_points=%zu halo=%g tiles=%zu halo_points=%zu "
      "base_mb=%.0f",
      vertices,
      tiling.tile_points,
      tiling.halo_spacings,
      piece[1].tiles,
      piece[1].halo_points,
      base_mb);
  const char* name[2] = {"one", "tiled"};
  for (int c = 0; c < 2; ++c) {
    const auto topology = pcl::cocone::analyzeMesh(piece[c].polygons, vertices);
    std::printf(" %s_seconds=%.3f %s_peak_mb=%.0f %s_triangles=%zu %s_euler=%ld "
                "%s_loops=%zu %s_manifold=%d %s_components=%zu %s_boundary=%zu",
                name[c],
                piece[c].seconds,
                name[c],
                piece[c].peak_mb,
                name[c],
                piece[c].polygons.size(),
                name[c],
                topology.euler,
                name[c],
                piece[c].loops,
                name[c],
                int(topology.manifold()),
                name[c],
                topology.components,
                name[c],
                piece[c].boundary.size());
  }
  std::printf(" differing=%zu differing_share=%.4f%% turned=%zu labels_differing=%zu "
              "patches_flipped=%zu stitch_dropped=%zu seam_filled=%zu "
              "tiles_seconds=%.3f cut_and_stitch_seconds=%.3f\n",
              differing,
              100.0 * double(differing) /
                  double(std::max<std::size_t>(1, sets[0].size())),
              turned,
              labels.size(),
              piece[1].patches_flipped,
              piece[1].stitch_dropped,
              piece[1].seam_filled,
              piece[1].tiles_seconds,
              piece[1].stitch_seconds);
  return 0;
}

int
usage(const char* program)
{
  std::fprintf(stderr,
               "usage: %s generate torus|saddle random|even N OUT.ply [SEED [NOISE]]\n"
               "       %s generate terrain|torus stream N OUT.ply [SEED]\n"
               "       %s convert CLOUD OUT.ply\n"
               "       %s delaunay|detect|cocone|gp3|boundary_estimation|"
               "advancing_front CLOUD\n"
               "          [--truth auto|closed|saddle|none] [--threads T]\n"
               "       %s tiled CLOUD --tile_points N [--halo S] [--in_flight K] "
               "[--threads T]\n",
               program,
               program,
               program,
               program,
               program);
  return 1;
}

/** The terrain of `generate terrain`: over [-1, 1]^2, rolling ground with five mesas
 * whose walls rise at up to 84 degrees (logistic steps 0.08 high, 0.002 wide) and
 * six round holes, one on a mesa: a disk with six holes (7 border loops, Euler
 * characteristic -5). The same surface at every N, so that runs of different sizes
 * compare per point. */
struct Terrain {
  struct Circle {
    double x, y, r;
  };
  static constexpr double HEIGHT = 0.08, WIDTH = 0.002;
  std::vector<Circle> mesas{{-0.5, -0.5, 0.25},
                            {0.5, 0.4, 0.3},
                            {-0.4, 0.55, 0.15},
                            {0.45, -0.5, 0.2},
                            {0.0, 0.0, 0.12}};
  std::vector<Circle> holes{{-0.75, 0.1, 0.06},
                            {0.1, -0.75, 0.05},
                            {0.8, -0.1, 0.07},
                            {-0.1, 0.85, 0.05},
                            {0.1, 0.3, 0.04},
                            {0.55, 0.45, 0.08}};

  /** Height and gradient at (x, y). */
  double
  height(double x, double y, Eigen::Vector2d& gradient) const
  {
    double z = 0.05 * std::sin(2.1 * x + 0.3) * std::cos(1.7 * y);
    gradient = {0.105 * std::cos(2.1 * x + 0.3) * std::cos(1.7 * y),
                -0.085 * std::sin(2.1 * x + 0.3) * std::sin(1.7 * y)};
    for (const Circle& m : mesas) {
      const Eigen::Vector2d d(x - m.x, y - m.y);
      const double r = std::max(d.norm(), 1e-12);
      const double step = 1.0 / (1.0 + std::exp(-(m.r - r) / WIDTH));
      z += HEIGHT * step;
      gradient -= HEIGHT * step * (1.0 - step) / WIDTH * d / r;
    }
    return z;
  }

  bool
  inHole(double x, double y) const
  {
    for (const Circle& h : holes)
      if (std::hypot(x - h.x, y - h.y) < h.r)
        return true;
    return false;
  }

  /** sqrt(1 + |gradient|^2): the area element. */
  double
  areaFactor(double x, double y) const
  {
    Eigen::Vector2d g;
    height(x, y, g);
    return std::sqrt(1.0 + g.squaredNorm());
  }
};

/** Draws one area-uniform random point of a surface from uniform numbers. */
using Sampler = std::function<Eigen::Vector3d(const std::function<double()>&)>;

/** The Terrain's sampler: rejection from cells drawn in proportion to a bound of the
 * area element over them (its largest value on a 5 x 5 grid of the cell, with a
 * margin): the walls are 50 times steeper than the ground, a single bound would
 * reject 49 of 50. */
Sampler
terrainSampler()
{
  constexpr int CELLS = 512;
  const double size = 2.0 / CELLS;
  const auto terrain = std::make_shared<Terrain>();
  auto bound = std::make_shared<std::vector<double>>(CELLS * CELLS);
  auto cumulative = std::make_shared<std::vector<double>>(CELLS * CELLS);
  double total = 0.0;
  for (int i = 0; i < CELLS; ++i)
    for (int j = 0; j < CELLS; ++j) {
      double b = 0.0;
      for (int a = 0; a <= 4; ++a)
        for (int c = 0; c <= 4; ++c)
          b = std::max(b,
                       terrain->areaFactor(-1.0 + (i + a / 4.0) * size,
                                           -1.0 + (j + c / 4.0) * size));
      (*bound)[i * CELLS + j] = 1.5 * b;
      (*cumulative)[i * CELLS + j] = total += 1.5 * b;
    }
  return [=](const std::function<double()>& uniform) {
    for (;;) {
      const auto& cum = *cumulative;
      const std::size_t c = std::min<std::size_t>(
          static_cast<std::size_t>(
              std::upper_bound(cum.begin(), cum.end(), uniform() * total) -
              cum.begin()),
          cum.size() - 1);
      const double x = -1.0 + (static_cast<double>(c / CELLS) + uniform()) * size;
      const double y = -1.0 + (static_cast<double>(c % CELLS) + uniform()) * size;
      const double accept = uniform() * (*bound)[c];
      if (terrain->inHole(x, y))
        continue;
      Eigen::Vector2d g;
      const double z = terrain->height(x, y, g);
      if (accept < std::sqrt(1.0 + g.squaredNorm()))
        return Eigen::Vector3d(x, y, z);
    }
  };
}

/** The torus R = 1, r = 0.4 of `generate torus`: the angle round the tube by
 * rejection on the area element R + r cos(phi). */
Sampler
torusSampler()
{
  return [](const std::function<double()>& uniform) {
    constexpr double R = 1.0, r = 0.4, TWO_PI = 6.283185307179586;
    for (;;) {
      const double theta = TWO_PI * uniform(), phi = TWO_PI * uniform();
      if (uniform() * (R + r) >= R + r * std::cos(phi))
        continue;
      const double ring = R + r * std::cos(phi);
      return Eigen::Vector3d(
          ring * std::cos(theta), ring * std::sin(theta), r * std::sin(phi));
    }
  };
}

/** \a n area-uniform random samples of a surface streamed to a binary PLY of float
 * x, y, z: clouds larger than the memory, without the test samples' truth. */
int
generateStreamed(const Sampler& sample,
                 std::size_t n,
                 std::uint64_t seed,
                 const std::string& path)
{
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    return 1;
  }
  std::fprintf(f,
               "ply\nformat binary_little_endian 1.0\nelement vertex %zu\n"
               "property float x\nproperty float y\nproperty float z\nend_header\n",
               n);
  std::uint64_t state = seed * 0x9E3779B97F4A7C15ull + 1;
  const std::function<double()> uniform = [&state] { // splitmix64
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  std::vector<float> block;
  bool ok = true;
  for (std::size_t i = 0; i < n && ok; ++i) {
    const Eigen::Vector3d p = sample(uniform);
    block.insert(block.end(), {float(p.x()), float(p.y()), float(p.z())});
    if (block.size() >= 3 * 65536 || i + 1 == n) {
      ok = std::fwrite(block.data(), sizeof(float), block.size(), f) == block.size();
      block.clear();
    }
  }
  if (std::fclose(f) != 0 || !ok) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    return 1;
  }
  return 0;
}

int
generate(int argc, char** argv)
{
  if (argc < 6)
    return usage(argv[0]);
  const std::string surface = argv[2], sampling = argv[3];
  cocone_test::SampleOptions o;
  o.n = std::strtoul(argv[4], nullptr, 10);
  o.seed = argc > 6 ? std::strtoull(argv[6], nullptr, 10) : 1;
  o.noise = argc > 7 ? std::strtod(argv[7], nullptr) : 0.0;
  o.even = sampling == "even";
  if (sampling == "stream" && (surface == "terrain" || surface == "torus"))
    return generateStreamed(
        surface == "terrain" ? terrainSampler() : torusSampler(), o.n, o.seed, argv[5]);
  if ((surface != "torus" && surface != "saddle") ||
      (sampling != "even" && sampling != "random"))
    return usage(argv[0]);
  const cocone_test::Sample s =
      surface == "torus" ? cocone_test::torus(o) : cocone_test::monkeySaddle(o);
  if (!writePly(argv[5], s.points)) {
    std::fprintf(stderr, "cannot write %s\n", argv[5]);
    return 1;
  }
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 3)
    return usage(argv[0]);
  const std::string method = argv[1], path = argv[2];
  if (method == "generate")
    return generate(argc, argv);
  std::string truth_kind = "auto";
  unsigned threads = 1;
  pcl::cocone::TilingOptions tiling;
  if (method != "convert" && argc % 2 == 0)
    return usage(argv[0]); // an option without its value
  for (int a = 3; a + 1 < argc; a += 2) {
    if (std::strcmp(argv[a], "--truth") == 0)
      truth_kind = argv[a + 1];
    else if (std::strcmp(argv[a], "--threads") == 0)
      threads = std::strtoul(argv[a + 1], nullptr, 10);
    else if (method == "tiled" && std::strcmp(argv[a], "--tile_points") == 0)
      tiling.tile_points = std::strtoul(argv[a + 1], nullptr, 10);
    else if (method == "tiled" && std::strcmp(argv[a], "--halo") == 0)
      tiling.halo_spacings = std::strtod(argv[a + 1], nullptr);
    else if (method == "tiled" && std::strcmp(argv[a], "--in_flight") == 0)
      tiling.tiles_in_flight = std::strtoul(argv[a + 1], nullptr, 10);
    else
      return usage(argv[0]);
  }

  cocone_app::BorderTruth grid;
  std::vector<Eigen::Vector3d> points;
  if (!readPoints(path, points, truth_kind == "auto" ? &grid : nullptr))
    return 1;
  if (method == "convert") {
    if (argc < 4 || !writePly(argv[3], points)) {
      std::fprintf(stderr, "cannot write the cloud\n");
      return 1;
    }
    return 0;
  }
  if (method == "tiled") {
    if (tiling.tile_points == 0)
      return usage(argv[0]);
    pcl::cocone::Parameters parameters;
    parameters.threads = threads;
    return compareTiled(std::move(points), parameters, tiling);
  }
  // The PCL methods take a PCL cloud; the others do not pay for one.
  const bool pcl_input = method == "gp3" || method == "boundary_estimation";
  Cloud::Ptr cloud = pcl_input ? toCloud(points) : Cloud::Ptr();
  const double base_mb = peakMegabytes();

  Output out;
  Stopwatch watch;
  if (method == "delaunay")
    delaunayAlone(points, out);
  else if (method == "detect" || method == "cocone")
    cocone(points, method == "cocone", threads, out);
  else if (method == "gp3")
    greedyProjection(cloud, out);
  else if (method == "boundary_estimation")
    boundaryEstimation(cloud, out);
  else if (method == "advancing_front") {
    out.triangles = cocone_app::advancingFront(points);
    out.stages.emplace_back("reconstruction", watch.seconds());
    out.mesh = true;
    out.vertices = points.size();
  }
  else
    return usage(argv[0]);
  const double seconds = watch.seconds();
  const double peak_mb = peakMegabytes(); // before the evaluation adds its own

  std::printf("method=%s points=%zu seconds=%.3f base_mb=%.0f peak_mb=%.0f",
              method.c_str(),
              points.size(),
              seconds,
              base_mb,
              peak_mb);
  std::printf(" stages=");
  for (std::size_t i = 0; i < out.stages.size(); ++i)
    std::printf(
        "%s%s:%.3f", i ? "," : "", out.stages[i].first.c_str(), out.stages[i].second);
  if (out.mesh) {
    const auto topology = pcl::cocone::analyzeMesh(out.triangles, out.vertices);
    std::printf(" triangles=%zu boundary_edges=%zu euler=%ld manifold=%d",
                out.triangles.size(),
                topology.boundary_edges,
                topology.euler,
                int(topology.manifold()));
    out.has_border = true;
    out.border = pcl::cocone::borderVertices(out.triangles);
  }
  if (out.has_border) {
    std::printf(" border_points=%zu", out.border.size());
    cocone_app::BorderTruth truth;
    bool known = true;
    if (truth_kind == "saddle")
      truth = saddleTruth(toCloud(points));
    else if (truth_kind == "auto" && grid.spacing > 0.0)
      truth = grid;
    else
      known = truth_kind == "closed";
    if (known) {
      if (!cloud)
        cloud = toCloud(points);
      const auto s = cocone_app::scoreBorder(*cloud, out.border, truth);
      if (!truth.border.empty())
        std::printf(" recall=%.3f", s.recall);
      if (!out.border.empty())
        std::printf(" precision=%.3f", s.precision);
    }
  }
  if (!out.extra.empty())
    std::printf(" %s", out.extra.c_str());
  std::printf("\n");
  return 0;
}
