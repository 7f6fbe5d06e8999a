/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * cocone_benchmark: wall time per stage and peak memory of the pipeline next to CGAL's
 * Delaunay triangulation alone (the floor: no Delaunay-based method can be faster), on
 * seeded area-uniform random samples of a torus and of the monkey saddle.
 *
 *   cocone_benchmark delaunay|pipeline|detect torus|saddle N [threads]
 *
 * Each run measures one thing in its own process, so that the peak resident memory
 * it prints belongs to that thing; scripts/benchmark.sh runs the grid.
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

/** Area-uniform random samples (rejection on the area element), seeded. */
std::vector<Eigen::Vector3d>
sample(const std::string& surface, std::size_t n, unsigned seed)
{
  std::mt19937_64 rng(seed);
  const auto uniform = [&]() { return (rng() >> 11) * (1.0 / 9007199254740992.0); };
  std::vector<Eigen::Vector3d> points;
  points.reserve(n);
  while (points.size() < n) {
    if (surface == "torus") {
      const double R = 1.0, r = 0.4;
      const double u = 2.0 * M_PI * uniform(), v = 2.0 * M_PI * uniform();
      if (uniform() * (R + r) > R + r * std::cos(v))
        continue;
      points.emplace_back((R + r * std::cos(v)) * std::cos(u),
                          (R + r * std::cos(v)) * std::sin(u),
                          r * std::sin(v));
    }
    else {
      const double x = 2.0 * uniform() - 1.0, y = 2.0 * uniform() - 1.0;
      const double fx = 3.0 * x * x - 3.0 * y * y, fy = -6.0 * x * y;
      if (uniform() * std::sqrt(1.0 + 72.0) > std::sqrt(1.0 + fx * fx + fy * fy))
        continue;
      points.emplace_back(x, y, x * x * x - 3.0 * x * y * y);
    }
  }
  return points;
}

double
peakMegabytes()
{
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 4) {
    std::fprintf(
        stderr, "usage: %s delaunay|pipeline|detect torus|saddle N [seed]\n", argv[0]);
    return 1;
  }
  const std::string what = argv[1], surface = argv[2];
  const std::size_t n = std::strtoul(argv[3], nullptr, 10);
  const unsigned threads = argc > 4 ? std::atoi(argv[4]) : 1;
  const auto points = sample(surface, n, 1);
  const double base_mb = peakMegabytes();
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&]() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
        .count();
  };

  if (what == "delaunay") {
    using K = CGAL::Exact_predicates_inexact_constructions_kernel;
    std::vector<K::Point_3> p;
    p.reserve(points.size());
    for (const auto& q : points)
      p.emplace_back(q.x(), q.y(), q.z());
    CGAL::Delaunay_triangulation_3<K> dt(p.begin(), p.end());
    std::printf(
        "%s %zu delaunay_alone: %.2f s, peak %.0f MB (points %.0f MB), %zu cells\n",
        surface.c_str(),
        n,
        seconds(),
        peakMegabytes(),
        base_mb,
        dt.number_of_finite_cells());
    return 0;
  }

  const auto stages = what == "detect" ? pcl::cocone::Stages::BOUNDARY_DETECTION
                                       : pcl::cocone::Stages::RECONSTRUCTION;
  pcl::cocone::Parameters parameters;
  parameters.threads = threads;
  const pcl::cocone::Result r = pcl::cocone::run(points, parameters, stages);
  const double total = seconds();
  const auto& t = r.timings;
  const auto topology = pcl::cocone::analyzeMesh(r.triangles, r.vertices);
  std::printf(
      "%s %zu %s (%u threads): %.2f s (unique %.2f, delaunay %.2f, voronoi %.2f, "
      "boundary "
      "%.2f, reconstruction %.2f), peak %.0f MB; rho %.2f, %zu boundary points, "
      "%zu triangles, %zu border loops, euler %ld, manifold %d\n",
      surface.c_str(),
      n,
      what.c_str(),
      threads,
      total,
      t.unique / 1e3,
      t.delaunay / 1e3,
      t.voronoi / 1e3,
      t.boundary / 1e3,
      t.reconstruction / 1e3,
      peakMegabytes(),
      r.ratio,
      r.boundary_indices.size(),
      r.triangles.size(),
      r.border_loops.size(),
      topology.euler,
      int(topology.manifold()));
  return 0;
}
