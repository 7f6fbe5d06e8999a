/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * cocone_mesh_eval: the topology of the reconstruction of closed reference shapes,
 * next to CGAL's advancing front, as a Markdown table.
 *
 *   cocone_mesh_eval [--threads T] [--no-peer] [--noise S [--seed N]] [--write DIR]
 *                    FILE[:EULER] ...
 *
 * e.g. cocone_mesh_eval ../shared/data/closed_meshes/bunny.obj
 *        ../shared/data/powercrust_samples/knot.pts:0
 *
 * A Wavefront .obj or an .off (CGAL's example meshes) with faces is a mesh: its
 * vertices (all of them, referenced or not) are the cloud, and its faces the truth:
 * the Euler characteristic V - E + F over the referenced vertices, the components
 * (through shared edges), the boundary edges (none: a closed shape) and the genus
 * (2 components - Euler) / 2. Any other cloud (.pts, .xyz, .ply, .pcd, an .obj or
 * .off without faces) has only the Euler
 * characteristic given after the name (FILE:EULER; "?" or none: unknown).
 *
 * Each cloud goes to this library with the default parameters (threads from
 * --threads, 1 if not given) and to CGAL::advancing_front_surface_reconstruction with
 * its defaults (not with --no-peer). Per method the table gives the mesh's vertices,
 * triangles, components, Euler characteristic, genus ((2 components - loops -
 * Euler) / 2, "?" where not a manifold), whether it is an oriented 2-manifold
 * and closed, its wrong loops (as many as it has more or fewer than the truth: all
 * of them where the truth is closed; a count, not a match of loop to loop) with the
 * edge counts of the 5 largest and the median, the outliers the library set aside, and
 * the seconds. The peer's loops are the cycles of its boundary edges. The last column
 * says whether this library has at most as many wrong loops as the peer.
 *
 * --noise S: a noisy scan of each shape, both methods on the same cloud: every
 * point moved by Gaussian noise of S local spacings (the mean distance to its 6
 * nearest other points) per coordinate, from seed N (default 1).
 *
 * --write DIR: each cloud as evaluated (with its noise) is written to DIR/NAME.pcd,
 * so that pcl_cocone_reconstruction can be run on it (its report, its screenshot).
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>
#include <pcl/conversions.h>

#include "benchmark_advancing_front.h"
#include "cloud_io.h"
#include "peer_methods.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace {

using pcl::cocone::MeshTopology;
using pcl::cocone::Triangle;

double
since(std::chrono::steady_clock::time_point t)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/** Every point moved by Gaussian noise of \a sigma local spacings (the mean distance
 * to its 6 nearest other points) per coordinate, drawn from \a seed. */
void
addNoise(std::vector<Eigen::Vector3d>& points, double sigma, unsigned int seed)
{
  constexpr int K = 6;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const Eigen::Vector3d& p : points)
    cloud->push_back(pcl::PointXYZ(static_cast<float>(p.x()),
                                   static_cast<float>(p.y()),
                                   static_cast<float>(p.z())));
  cocone_app::Tree tree;
  tree.setInputCloud(cloud);
  std::vector<double> spacing(points.size(), 0.0);
  pcl::Indices near;
  std::vector<float> d2;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int found = tree.nearestKSearch((*cloud)[i], K + 1, near, d2);
    double sum = 0.0;
    for (int j = 1; j < found; ++j) // the first is the point itself
      sum += std::sqrt(static_cast<double>(d2[j]));
    spacing[i] = found > 1 ? sum / (found - 1) : 0.0;
  }
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int c = 0; c < 3; ++c)
      points[i][c] += sigma * spacing[i] * normal(random);
}

/** What is known of the true surface of a cloud. */
struct Truth {
  bool mesh = false;            ///< from the faces of an .obj or .off
  bool euler_known = false;     ///< the Euler characteristic is known
  long euler = 0;               ///< V - E + F
  MeshTopology topology;        ///< of the faces (mesh only)
  std::size_t unreferenced = 0; ///< vertices in no face (mesh only)
  std::size_t loops = 0;        ///< border loops of the faces (mesh only)
};

/** The border loops of a triangle mesh of any kind: the cycles of its directed
 * boundary half-edges (edges in one triangle, as that triangle traverses them).
 * Where several loops pass through a vertex they are split there; a chain that
 * cannot close (the triangles around it disagree in orientation) counts as a loop
 * too. Each loop is its vertices, as many as its edges. */
std::vector<std::vector<int>>
borderCycles(const std::vector<Triangle>& triangles, std::size_t num_vertices)
{
  const pcl::cocone::EdgeIncidences inc(triangles);
  // Outgoing border half-edges per vertex, in CSR form.
  std::vector<std::array<int, 2>> half;
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (inc.count(e) == 1) {
      const std::size_t i = inc.first[e];
      const bool forward = inc.forward[i] != 0;
      half.push_back({inc.edges[e][forward ? 0 : 1], inc.edges[e][forward ? 1 : 0]});
    }
  std::sort(half.begin(), half.end());
  std::vector<std::size_t> first(num_vertices + 1, 0);
  for (const auto& h : half)
    ++first[h[0] + 1];
  for (std::size_t v = 0; v < num_vertices; ++v)
    first[v + 1] += first[v];
  std::vector<std::size_t> next_unused(first.begin(), first.end() - 1);
  std::vector<std::vector<int>> loops;
  for (std::size_t s = 0; s < half.size(); ++s) {
    const int start = half[s][0];
    if (next_unused[start] == first[start + 1])
      continue; // every half-edge out of start is on a loop
    std::vector<int> loop;
    int v = start;
    do {
      loop.push_back(v);
      const int w = half[next_unused[v]++][1];
      v = w;
    }
    while (v != start && next_unused[v] < first[v + 1]);
    loops.push_back(std::move(loop));
  }
  return loops;
}

/** One row of the table. */
struct Row {
  std::string error;
  std::size_t mesh_vertices = 0;
  MeshTopology topology;
  std::vector<std::size_t> loop_sizes; ///< edges per loop
  long outliers = -1;                  ///< -1: not reported
  double seconds = 0.0;
};

template <class Loops>
std::vector<std::size_t>
sizes(const Loops& loops)
{
  std::vector<std::size_t> s;
  for (const auto& l : loops)
    s.push_back(l.size());
  return s;
}

Row
runCocone(const std::vector<Eigen::Vector3d>& points, unsigned int threads)
{
  Row row;
  pcl::cocone::Parameters parameters;
  parameters.threads = threads;
  const auto t = std::chrono::steady_clock::now();
  const pcl::cocone::Result r =
      pcl::cocone::run(points, parameters, pcl::cocone::Stages::RECONSTRUCTION);
  row.seconds = since(t);
  if (!r.error.empty()) {
    row.error = r.error;
    return row;
  }
  row.topology = pcl::cocone::analyzeMesh(r.triangles, r.vertices);
  row.loop_sizes = sizes(r.border_loops);
  row.outliers = static_cast<long>(r.outlier_indices.size());
  return row;
}

Row
runPeer(const std::vector<Eigen::Vector3d>& points)
{
  Row row;
  const auto t = std::chrono::steady_clock::now();
  const std::vector<Triangle> triangles = cocone_app::advancingFront(points);
  row.seconds = since(t);
  row.topology = pcl::cocone::analyzeMesh(triangles, points.size());
  row.loop_sizes = sizes(borderCycles(triangles, points.size()));
  return row;
}

std::string
yesNo(bool b)
{
  return b ? "yes" : "no";
}

/** The edge counts of the 5 largest loops, and the median one. */
void
loopSummary(std::vector<std::size_t> s, std::string& largest, std::string& median)
{
  if (s.empty()) {
    largest = median = "-";
    return;
  }
  std::sort(s.begin(), s.end(), std::greater<std::size_t>());
  largest.clear();
  for (std::size_t i = 0; i < s.size() && i < 5; ++i)
    largest += (i ? ", " : "") + std::to_string(s[i]);
  const std::size_t n = s.size();
  char buffer[32];
  if (n % 2)
    std::snprintf(buffer, sizeof(buffer), "%zu", s[n / 2]);
  else
    std::snprintf(buffer, sizeof(buffer), "%g", 0.5 * double(s[n / 2 - 1] + s[n / 2]));
  median = buffer;
}

/** The genus of a surface with \a loops borders: 2 components - loops - Euler is
 * twice it; "?" where that is odd. */
std::string
genusText(std::size_t components, std::size_t loops, long euler)
{
  const long twice =
      2 * static_cast<long>(components) - static_cast<long>(loops) - euler;
  return twice % 2 ? "?" : std::to_string(twice / 2);
}

std::string
truthText(const Truth& t)
{
  if (!t.mesh)
    return t.euler_known ? "Euler " + std::to_string(t.euler) + " (given)" : "Euler ?";
  const MeshTopology& m = t.topology;
  std::string s = "Euler " + std::to_string(m.euler) + ", " +
                  std::to_string(m.components) + " comp.";
  if (m.boundary_edges == 0)
    s += ", genus " + genusText(m.components, 0, m.euler);
  else
    s += ", " + std::to_string(m.boundary_edges) + " boundary edges in " +
         std::to_string(t.loops) + " loops (not closed)";
  if (!m.manifold())
    s += ", not manifold";
  if (t.unreferenced)
    s += ", " + std::to_string(t.unreferenced) + " unreferenced vertices";
  return s;
}

/** The loops a row has more or fewer than the truth's. */
std::size_t
wrongLoops(const Row& row, const Truth& truth)
{
  const std::size_t loops = row.loop_sizes.size();
  return loops > truth.loops ? loops - truth.loops : truth.loops - loops;
}

void
printRow(const std::string& cloud,
         const Truth& truth,
         const char* method,
         std::size_t points,
         const Row& row,
         const std::string& verdict)
{
  if (!row.error.empty()) {
    std::printf("| %s | %s | %s | %zu | error: %s | | | | | | | | | | | %.2f | %s |\n",
                cloud.c_str(),
                truthText(truth).c_str(),
                method,
                points,
                row.error.c_str(),
                row.seconds,
                verdict.c_str());
    return;
  }
  const MeshTopology& m = row.topology;
  std::string largest, median;
  loopSummary(row.loop_sizes, largest, median);
  const std::string genus =
      m.manifold() ? genusText(m.components, row.loop_sizes.size(), m.euler) : "?";
  std::printf(
      "| %s | %s | %s | %zu | %zu | %zu | %zu | %ld | %s | %s | %s | %zu | %s | %s | "
      "%s | %.2f | %s |\n",
      cloud.c_str(),
      truthText(truth).c_str(),
      method,
      points,
      m.vertices,
      m.triangles,
      m.components,
      m.euler,
      genus.c_str(),
      yesNo(m.manifold()).c_str(),
      yesNo(m.triangles > 0 && m.boundary_edges == 0).c_str(),
      wrongLoops(row, truth),
      largest.c_str(),
      median.c_str(),
      row.outliers < 0 ? "-" : std::to_string(row.outliers).c_str(),
      row.seconds,
      verdict.c_str());
}

/** Split FILE:EULER; the suffix counts only if it is an integer or "?". */
void
splitArgument(const std::string& arg, std::string& path, Truth& truth)
{
  path = arg;
  const auto colon = arg.find_last_of(':');
  if (colon == std::string::npos)
    return;
  const std::string suffix = arg.substr(colon + 1);
  if (suffix == "?") {
    path = arg.substr(0, colon);
    return;
  }
  char* end = nullptr;
  const long e = std::strtol(suffix.c_str(), &end, 10);
  if (suffix.empty() || *end != '\0')
    return;
  path = arg.substr(0, colon);
  truth.euler_known = true;
  truth.euler = e;
}

std::string
baseName(const std::string& path)
{
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

} // namespace

int
main(int argc, char** argv)
{
  unsigned int threads = 1, seed = 1;
  bool peer = true;
  double noise = 0.0;
  std::string write_dir;
  std::vector<std::string> files;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--threads" && a + 1 < argc)
      threads = static_cast<unsigned int>(std::strtoul(argv[++a], nullptr, 10));
    else if (arg == "--no-peer")
      peer = false;
    else if (arg == "--noise" && a + 1 < argc)
      noise = std::strtod(argv[++a], nullptr);
    else if (arg == "--seed" && a + 1 < argc)
      seed = static_cast<unsigned int>(std::strtoul(argv[++a], nullptr, 10));
    else if (arg == "--write" && a + 1 < argc)
      write_dir = argv[++a];
    else if (arg.size() > 1 && arg[0] == '-') {
      std::fprintf(stderr, "unknown option '%s'\n", arg.c_str());
      return 1;
    }
    else
      files.push_back(arg);
  }
  if (!(noise >= 0.0) || !std::isfinite(noise)) {
    std::fprintf(stderr, "--noise takes a number of local spacings, 0 or more\n");
    return 1;
  }
  if (files.empty()) {
    std::fprintf(
        stderr,
        "usage: %s [--threads T] [--no-peer] [--noise S [--seed N]] [--write DIR] "
        "FILE[:EULER] ...\n",
        argv[0]);
    return 1;
  }
  std::printf("| cloud | truth | method | points | mesh vertices | triangles | "
              "components | Euler | genus | manifold | closed | wrong loops | largest "
              "loops (edges) | median loop | outliers | s | ours <= peer |\n");
  std::printf("|---|---|---|---:|---:|---:|---:|---:|---:|---|---|---:|---|---:|---:|"
              "---:|---|\n");
  int status = 0;
  for (const std::string& arg : files) {
    std::string path;
    Truth truth;
    splitArgument(arg, path, truth);
    pcl::PCLPointCloud2 blob;
    std::string error;
    std::vector<Eigen::Vector3d> points;
    if (!cocone_app::readCloud(path, blob, error) ||
        !cocone_app::extractXYZ(blob, points, error)) {
      std::fprintf(stderr, "%s\n", error.c_str());
      status = 1;
      continue;
    }
    const std::string ext = cocone_app::extension(path);
    if (ext == "obj" || ext == "off") {
      std::vector<Triangle> faces;
      if (!cocone_app::readFaces(path, faces, error)) {
        std::fprintf(stderr, "%s: %s\n", path.c_str(), error.c_str());
        status = 1;
        continue;
      }
      if (!faces.empty()) {
        if (truth.euler_known)
          std::fprintf(stderr,
                       "%s: a mesh; its faces' Euler characteristic is the truth\n",
                       path.c_str());
        truth.mesh = true;
        truth.topology = pcl::cocone::analyzeMesh(faces, points.size());
        truth.euler_known = true;
        truth.euler = truth.topology.euler;
        truth.unreferenced = points.size() - truth.topology.vertices;
        truth.loops = borderCycles(faces, points.size()).size();
      }
    }
    if (noise > 0.0)
      addNoise(points, noise, seed);
    const std::string name = baseName(path);
    if (!write_dir.empty()) {
      pcl::PointCloud<pcl::PointXYZ> cloud;
      for (const Eigen::Vector3d& p : points)
        cloud.push_back(pcl::PointXYZ(static_cast<float>(p.x()),
                                      static_cast<float>(p.y()),
                                      static_cast<float>(p.z())));
      pcl::PCLPointCloud2 written;
      pcl::toPCLPointCloud2(cloud, written);
      const std::string out =
          write_dir + "/" + name.substr(0, name.rfind('.')) + ".pcd";
      if (!cocone_app::writeCloud(out, written, error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        status = 1;
      }
    }
    std::fprintf(stderr, "%s: %zu points\n", path.c_str(), points.size());
    const Row ours = runCocone(points, threads);
    if (!peer) {
      printRow(name, truth, "cocone", points.size(), ours, "-");
      continue;
    }
    const Row theirs = runPeer(points);
    const bool both = ours.error.empty() && theirs.error.empty();
    printRow(name,
             truth,
             "cocone",
             points.size(),
             ours,
             both ? yesNo(wrongLoops(ours, truth) <= wrongLoops(theirs, truth)) : "-");
    printRow(name, truth, "advancing front", points.size(), theirs, "");
  }
  return status;
}
