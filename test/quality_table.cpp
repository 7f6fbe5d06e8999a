/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/search/kdtree.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "benchmark_advancing_front.h"
#include "peer_methods.h"
#include <support/cases.h>
#include <support/metrics.h>
#include <support/surfaces.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

// Prints the README's tables (build/test/cocone_quality_table): fixed rho 1.5, fixed
// rho 2.5 and the default mode on the clean synthetic test surfaces; then the default
// mode next to pcl::BoundaryEstimation and CGAL's advancing front on the noisy,
// multi-view and outlier clouds of test_noise, each method on the same cloud.
using namespace cocone_test;

namespace {

struct Case {
  std::string name;
  std::function<Sample()> make;
};

/** Border loops and Euler characteristic; the components too where they are not the
 * truth's (outliers meshed apart, a surface torn). */
std::string
meshCell(std::size_t loops, const pcl::cocone::MeshTopology& m, const Sample& s)
{
  char buf[128];
  std::snprintf(buf, sizeof(buf), "%zu loops, χ %ld", loops, m.euler);
  std::string cell = buf;
  if (s.components >= 0 && m.components != std::size_t(s.components))
    cell += ", " + std::to_string(m.components) + " components";
  if (!m.manifold())
    cell += ", non-manifold";
  return cell;
}

/** Recall and precision against the true border, or the share flagged on a closed
 * surface (every flagged point is false there). */
std::string
borderCell(const Sample& s, const std::vector<int>& reported)
{
  if (s.boundary_loops < 0)
    return "no truth";
  const BoundaryScore b = scoreBoundary(s, reported);
  char buf[64];
  if (s.boundary_loops == 0)
    std::snprintf(buf, sizeof(buf), "%.1f %% flagged", 100 * b.reported_share);
  else
    std::snprintf(buf, sizeof(buf), "R %.2f P %.2f", b.recall, b.precision);
  return buf;
}

/** The outliers set aside (as test_noise counts them: every flying pixel, the
 * scattered outliers more than a spacing off the surface, as those nearer are samples
 * of it by chance), and the samples set aside as outliers. */
std::string
outlierCell(const Sample& s, const pcl::cocone::Result& r)
{
  std::vector<bool> set_aside(s.points.size(), false);
  for (const int i : r.outlier_indices)
    set_aside[std::size_t(i)] = true;
  std::size_t off = 0, found = 0, false_outliers = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    // Flying pixels keep their normals; scattered outliers have none.
    const bool scattered = s.normals[i].squaredNorm() == 0.0;
    if (s.outlier[i] && (!scattered || s.distance(s.points[i]) > s.spacing)) {
      ++off;
      found += set_aside[i];
    }
    false_outliers += set_aside[i] && !s.outlier[i];
  }
  char buf[96];
  std::snprintf(
      buf, sizeof(buf), "; outliers %zu of %zu, %zu false", found, off, false_outliers);
  return buf;
}

std::string
ours(const Sample& s)
{
  const auto r = pcl::cocone::run(
      s.points, pcl::cocone::Parameters(), pcl::cocone::Stages::RECONSTRUCTION);
  if (!r.error.empty())
    return "error: " + r.error;
  const MeshScore m = scoreMesh(s, r);
  // The undersampled points (the paper's output), then the vertices of the mesh's
  // border loops.
  std::vector<int> on_border;
  for (const auto& loop : r.border_loops)
    on_border.insert(on_border.end(), loop.begin(), loop.end());
  std::string cell = meshCell(m.loops, m.topology, s) + ", " +
                     borderCell(s, r.boundary_indices) + "; mesh border " +
                     borderCell(s, on_border);
  bool outliers = false;
  for (const bool o : s.outlier)
    outliers = outliers || o;
  return outliers ? cell + outlierCell(s, r) : cell;
}

/** pcl::BoundaryEstimation as the benchmark runs it (normals and flags from the 20
 * nearest points). */
std::string
boundaryEstimation(const Sample& s)
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& p : s.points)
    cloud->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  cocone_app::Tree::Ptr tree(new cocone_app::Tree);
  const auto normals = cocone_app::estimateNormals(cloud, tree);
  return borderCell(s, cocone_app::boundaryEstimation(cloud, normals, tree));
}

/** CGAL's advancing front with its defaults; its loops are those of its mesh. */
std::string
advancingFront(const Sample& s)
{
  const auto start = std::chrono::steady_clock::now();
  const auto triangles = cocone_app::advancingFront(s.points);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr, "%s: advancing front %.1f s\n", s.name.c_str(), seconds);
  const auto m = pcl::cocone::analyzeMesh(triangles, s.points.size());
  return meshCell(pcl::cocone::boundaryLoops(triangles, s.points.size()).size(), m, s);
}

void
cleanTable()
{
  std::vector<Case> cases = {
      {"sphere", [] { return sphere(options(10000)); }},
      {"ellipsoid", [] { return ellipsoid(options(10000)); }},
      {"torus", [] { return torus(options(10000)); }},
      {"hemisphere", [] { return hemisphere(options(10000)); }},
      {"monkey saddle", [] { return monkeySaddle(options(10000)); }},
      {"open cylinder", [] { return openCylinder(options(10000)); }},
      {"curved sheet", [] { return curvedSheet(options(10000)); }},
      {"scan-line sheet", [] { return scanLineSheet(options(10000)); }},
      {"three components", [] { return threeComponents(options(10000)); }},
      {"sphere, 3 holes 30 deg",
       [] { return sphereWithHoles(options(10000), 3, 30 * M_PI / 180); }},
      {"sphere, 3 holes 15 deg",
       [] { return sphereWithHoles(options(10000), 3, 15 * M_PI / 180); }},
      {"hemisphere, noise 5 %", [] { return hemisphere(options(10000, 0.05)); }},
      {"torus, noise 15 %", [] { return torus(options(10000, 0.15)); }},
      {"hemisphere, density 1:4", [] { return hemisphere(options(10000, 0, 4)); }},
  };
  printf("| surface (truth: loops, Euler) | rho 1.5 | rho 2.5 | default "
         "|\n|---|---|---|---|\n");
  for (auto& c : cases) {
    Sample s = c.make();
    printf("| %s (%d, %d) |", c.name.c_str(), s.boundary_loops, s.euler);
    for (int mode = 0; mode < 3; ++mode) {
      pcl::cocone::Parameters p = mode == 0   ? paper(1.5)
                                  : mode == 1 ? paper(2.5)
                                              : pcl::cocone::Parameters();
      auto r = pcl::cocone::run(s.points, p, pcl::cocone::Stages::RECONSTRUCTION);
      auto m = scoreMesh(s, r);
      auto b = scoreBoundary(s, r.boundary_indices);
      if (s.boundary_loops == 0)
        printf(" %zu loops, χ %ld, %.1f %% flagged |",
               m.loops,
               m.topology.euler,
               100 * b.reported_share);
      else
        printf(" %zu loops, χ %ld, R %.2f P %.2f |",
               m.loops,
               m.topology.euler,
               b.recall,
               b.precision);
    }
    printf("\n");
    fflush(stdout);
  }
}

/** The clouds of test_noise: 10,000 random samples with Gaussian noise of sigma local
 * spacings along the normal; registered range views (noise 0.3, registration error
 * 0.5 spacings) of a dense even sample (4 views are the fewest that cover the
 * hemisphere); 1 % flying pixels or scattered outliers. */
std::vector<Case>
noisyCases()
{
  using Generator = std::function<Sample(const SampleOptions&)>;
  const std::vector<std::pair<const char*, Generator>> surfaces = {
      {"hemisphere", [](const SampleOptions& o) { return hemisphere(o); }},
      {"monkey saddle", [](const SampleOptions& o) { return monkeySaddle(o); }},
      {"open cylinder", [](const SampleOptions& o) { return openCylinder(o); }},
      {"sphere, 3 holes 30 deg",
       [](const SampleOptions& o) { return sphereWithHoles(o, 3, M_PI / 6.0); }},
      {"sphere, 3 holes 15 deg",
       [](const SampleOptions& o) { return sphereWithHoles(o, 3, M_PI / 12.0); }},
      {"torus", [](const SampleOptions& o) { return torus(o); }},
      {"genus 2", [](const SampleOptions& o) { return genus2(o); }},
  };
  std::vector<Case> cases;
  for (const auto& surface : surfaces)
    for (const double sigma : {0.3, 0.5, 1.0}) {
      char name[96];
      std::snprintf(name, sizeof(name), "%s, sigma %.1f", surface.first, sigma);
      const Generator make = surface.second;
      cases.push_back(
          {name, [make, sigma] { return make(options(10000, sigma, 1.0, false)); }});
    }
  // A knotted tube 6 to 8 samples round (7,000 random samples): no point passes
  // the flatness test, and the smoothing would pull the tube onto its axis.
  for (const double sigma : {0.3, 0.5}) {
    char name[96];
    std::snprintf(name, sizeof(name), "coarse knotted tube, sigma %.1f", sigma);
    cases.push_back({name, [sigma] { return tube(options(7000, sigma, 1.0, false)); }});
  }
  cases.push_back({"sphere, 6 views",
                   [] { return rangeViews(sphere(options(30000)), 6, 0.5, 7, 0.3); }});
  for (const int views : {4, 6})
    cases.push_back({"hemisphere, " + std::to_string(views) + " views", [views] {
                       return rangeViews(
                           hemisphere(options(30000)), views, 0.5, 7, 0.3);
                     }});
  cases.push_back({"torus, 1 % flying pixels", [] {
                     return withOutliers(
                         torus(options(10000, 0.0, 1.0, false)), 0.01, 3.0, 5);
                   }});
  cases.push_back({"hemisphere, 1 % flying pixels", [] {
                     return withOutliers(
                         hemisphere(options(10000, 0.0, 1.0, false)), 0.01, 3.0, 5);
                   }});
  cases.push_back({"sphere, 1 % scattered outliers", [] {
                     return withScatteredOutliers(
                         sphere(options(10000, 0.0, 1.0, false)), 0.01, 5);
                   }});
  return cases;
}

void
noisyTable()
{
  printf("| cloud (truth: loops, Euler) | this library (default) | "
         "`pcl::BoundaryEstimation` | CGAL advancing front |\n|---|---|---|---|\n");
  // The recall of every sample reported: the most a method that reports samples can
  // reach where random sampling leaves no sample near a stretch of the true border.
  std::string ceilings;
  for (const Case& c : noisyCases()) {
    const Sample s = c.make();
    if (s.boundary_loops > 0) {
      std::vector<int> every(s.points.size());
      for (std::size_t i = 0; i < every.size(); ++i)
        every[i] = static_cast<int>(i);
      char buf[128];
      std::snprintf(buf,
                    sizeof(buf),
                    "%s%s %.2f",
                    ceilings.empty() ? "" : ", ",
                    c.name.c_str(),
                    scoreBoundary(s, every).recall);
      ceilings += buf;
    }
    // A range view sample whose views leave part of the surface unseen has no truth.
    if (s.boundary_loops < 0)
      printf("| %s (unknown) |", c.name.c_str());
    else
      printf("| %s (%d, %d) |", c.name.c_str(), s.boundary_loops, s.euler);
    printf(" %s | %s | %s |\n",
           ours(s).c_str(),
           boundaryEstimation(s).c_str(),
           advancingFront(s).c_str());
    fflush(stdout);
  }
  printf("\nRecall with every sample reported (the most a method that reports samples "
         "can reach): %s.\n",
         ceilings.c_str());
}

} // namespace

int
main()
{
  cleanTable();
  printf("\n");
  noisyTable();
}
