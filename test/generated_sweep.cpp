/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>

#include <support/cases.h>
#include <support/metrics.h>
#include <support/surfaces.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

// Sweeps the generated surfaces of the tests over sizes, samplings and seeds and
// compares each default reconstruction's topology with the truth
// (build/test/cocone_generated_sweep [--noise S] [--views V] [--sizes N,N,...]
// [--seeds K] [--threads T] [--failures] [--write DIR]): per case the components,
// border loops and Euler characteristic found and true, and the samples set aside as
// outliers (on a clean cloud every one is false); then per surface and in all the cases
// whose topology is wrong (--write: the clouds of those cases as DIR/NAME.xyz, to look
// into). Where the tests check chosen cases, this shows how often a surface of each
// kind comes out right. --views V: each case is V registered range views of the surface
// (rangeViews(): a registration error of half a spacing, the noise S in each view); a
// case whose views leave part of the surface unseen has no known topology and is
// counted apart.
using namespace cocone_test;

namespace {

struct Surface {
  std::string name;
  std::function<Sample(const SampleOptions&)> make;
};

/** The samplings swept: even (Poisson-disk), area-uniform random, and even with the
 * density growing 1:8 along x. */
struct Sampling {
  std::string name;
  bool even;
  double density_ratio;
};

struct Tally {
  std::size_t cases = 0, wrong = 0, extra_loops = 0, false_outliers = 0, unseen = 0;

  Tally&
  operator+=(const Tally& t)
  {
    cases += t.cases;
    wrong += t.wrong;
    extra_loops += t.extra_loops;
    false_outliers += t.false_outliers;
    unseen += t.unseen;
    return *this;
  }
};

std::vector<std::size_t>
parseSizes(const std::string& list)
{
  std::vector<std::size_t> sizes;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const unsigned long n = std::strtoul(item.c_str(), &end, 10);
    if (end == item.c_str() || *end != '\0' || n < 100)
      return {};
    sizes.push_back(n);
  }
  return sizes;
}

/** \a text read whole as a number, NaN if it is not one ("0.5x" is none). */
double
parseNumber(const char* text)
{
  char* end = nullptr;
  const double x = std::strtod(text, &end);
  return end == text || *end != '\0' ? std::numeric_limits<double>::quiet_NaN() : x;
}

/** \a text read whole as a whole number, -1 if it is not one. */
long
parseWhole(const char* text)
{
  char* end = nullptr;
  const long n = std::strtol(text, &end, 10);
  return end == text || *end != '\0' ? -1 : n;
}

/** Write \a points to DIR/NAME.xyz, NAME's spaces and colons as underscores. */
void
writeCloud(const std::string& dir,
           std::string name,
           const std::vector<Eigen::Vector3d>& points)
{
  for (char& c : name)
    if (c == ' ' || c == ':')
      c = '_';
  const std::string path = dir + "/" + name + ".xyz";
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    return;
  }
  for (const auto& p : points)
    std::fprintf(out, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
  std::fclose(out);
}

} // namespace

int
main(int argc, char** argv)
{
  double noise = 0.0;
  long views = 0, seeds = 2, threads = 1;
  std::vector<std::size_t> sizes{3000, 10000};
  bool failures_only = false;
  std::string write_dir;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--noise" && a + 1 < argc)
      noise = parseNumber(argv[++a]);
    else if (arg == "--views" && a + 1 < argc)
      views = parseWhole(argv[++a]);
    else if (arg == "--sizes" && a + 1 < argc)
      sizes = parseSizes(argv[++a]);
    else if (arg == "--seeds" && a + 1 < argc)
      seeds = parseWhole(argv[++a]);
    else if (arg == "--threads" && a + 1 < argc)
      threads = parseWhole(argv[++a]);
    else if (arg == "--failures")
      failures_only = true;
    else if (arg == "--write" && a + 1 < argc)
      write_dir = argv[++a];
    else
      sizes.clear();
  }
  if (sizes.empty() || seeds < 1 || !(noise >= 0.0 && std::isfinite(noise)) ||
      threads < 0 || views < 0) {
    std::fprintf(stderr,
                 "usage: %s [--noise S] [--views V] [--sizes N,N,...] [--seeds K] "
                 "[--threads T] [--failures] [--write DIR]\n  S: noise sigma in "
                 "spacings (default 0); V: registered range views of each surface "
                 "(default 0: the surface's samples); N: at least "
                 "100 points (default 3000,10000); K: seeds 1 to K (default 2)\n",
                 argv[0]);
    return 2;
  }

  const std::vector<Surface> surfaces{
      {"sphere", [](const SampleOptions& o) { return sphere(o); }},
      {"ellipsoid", [](const SampleOptions& o) { return ellipsoid(o); }},
      {"torus", [](const SampleOptions& o) { return torus(o); }},
      {"genus 2", [](const SampleOptions& o) { return genus2(o); }},
      {"cube", [](const SampleOptions& o) { return cube(o); }},
      {"thin plate", [](const SampleOptions& o) { return thinPlate(o); }},
      {"knotted tube", [](const SampleOptions& o) { return tube(o); }},
      {"touching spheres",
       [](const SampleOptions& o) { return twoTouchingSpheres(o); }},
      {"hemisphere", [](const SampleOptions& o) { return hemisphere(o); }},
      {"monkey saddle", [](const SampleOptions& o) { return monkeySaddle(o); }},
      {"open cylinder", [](const SampleOptions& o) { return openCylinder(o); }},
      {"sphere, 3 holes", [](const SampleOptions& o) { return sphereWithHoles(o); }},
      {"three components", [](const SampleOptions& o) { return threeComponents(o); }},
  };
  const std::vector<Sampling> samplings{
      {"even", true, 1.0}, {"random", false, 1.0}, {"even 1:8", true, 8.0}};

  pcl::cocone::Parameters parameters;
  parameters.threads = static_cast<unsigned int>(threads);
  if (views > 0)
    std::printf("%ld range views registered within half a spacing, noise sigma %.2f "
                "spacings in each, default parameters\n\n",
                views,
                noise);
  else
    std::printf("noise sigma %.2f spacings, default parameters\n\n", noise);
  std::printf("| surface | points | sampling | seed | truth (components, loops, χ) | "
              "found | outliers | |\n|---|--:|---|--:|---|---|--:|---|\n");
  std::vector<Tally> tally(surfaces.size());
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    for (const std::size_t n : sizes)
      for (const Sampling& sampling : samplings)
        for (unsigned long seed = 1; seed <= static_cast<unsigned long>(seeds);
             ++seed) {
          SampleOptions o = options(
              n, views > 0 ? 0.0 : noise, sampling.density_ratio, sampling.even);
          o.seed = seed;
          const Sample s =
              views > 0
                  ? rangeViews(
                        surfaces[k].make(o), static_cast<int>(views), 0.5, seed, noise)
                  : surfaces[k].make(o);
          if (s.boundary_loops < 0) { // the views leave part of it unseen
            ++tally[k].unseen;
            continue;
          }
          const pcl::cocone::Result r = pcl::cocone::run(
              s.points, parameters, pcl::cocone::Stages::RECONSTRUCTION);
          const MeshScore m = scoreMesh(s, r);
          const bool right = r.error.empty() && m.topology.manifold() &&
                             m.topology.components == std::size_t(s.components) &&
                             m.loops == std::size_t(s.boundary_loops) &&
                             m.topology.euler == s.euler;
          Tally& t = tally[k];
          ++t.cases;
          t.wrong += !right;
          if (m.loops > std::size_t(s.boundary_loops))
            t.extra_loops += m.loops - std::size_t(s.boundary_loops);
          // The generated clouds have no outliers: a sample set aside is lost surface.
          t.false_outliers += r.outlier_indices.size();
          if (failures_only && right)
            continue;
          if (!right && !write_dir.empty())
            writeCloud(write_dir,
                       surfaces[k].name + " " + std::to_string(n) + " " +
                           sampling.name + " " + std::to_string(seed) +
                           (views > 0 ? " views " + std::to_string(views) : ""),
                       s.points);
          std::printf(
              "| %s | %zu | %s | %lu | %d, %d, %d | %zu, %zu, %ld%s | %zu | %s |\n",
              surfaces[k].name.c_str(),
              s.points.size(),
              sampling.name.c_str(),
              seed,
              s.components,
              s.boundary_loops,
              s.euler,
              m.topology.components,
              m.loops,
              m.topology.euler,
              m.topology.manifold() ? "" : ", non-manifold",
              r.outlier_indices.size(),
              right ? "" : (r.error.empty() ? "wrong" : r.error.c_str()));
          std::fflush(stdout);
        }

  // With views, the cases whose views left part of the surface unseen too.
  std::printf("\n| surface | cases | topology wrong | extra loops | outliers |%s\n"
              "|---|--:|--:|--:|--:|%s\n",
              views > 0 ? " unseen |" : "",
              views > 0 ? "--:|" : "");
  const auto row = [&](const std::string& name, const Tally& t) {
    std::printf("| %s | %zu | %zu | %zu | %zu |",
                name.c_str(),
                t.cases,
                t.wrong,
                t.extra_loops,
                t.false_outliers);
    if (views > 0)
      std::printf(" %zu |", t.unseen);
    std::printf("\n");
  };
  Tally all;
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    row(surfaces[k].name, tally[k]);
    all += tally[k];
  }
  row("all", all);
  return 0;
}
