/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Standalone check of the surface generators (not part of the CMake build):
 *   g++ -std=c++17 -O2 -I/usr/include/eigen3 -Itest test/support/surfaces.cpp \
 *       test/support/surfaces_selfcheck.cpp -o /tmp/surfaces_selfcheck
 */

#include <support/surfaces.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

using cocone_test::Sample;
using cocone_test::SampleOptions;

namespace {

int failures = 0;

void
check(bool ok, const std::string& what, const std::string& name)
{
  if (!ok) {
    ++failures;
    std::printf("  FAIL %s: %s\n", name.c_str(), what.c_str());
  }
}

double
msSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                   start)
      .count();
}

struct Generator {
  const char* name;
  std::function<Sample(const SampleOptions&)> make;
  int loops, components, euler;
  int density_axis; // the axis the density gradient runs along
};

/** Checks common to every sample; returns the largest distance of a point. */
double
checkSample(const Sample& s,
            const SampleOptions& o,
            const Generator& g,
            bool exact_count)
{
  const double miss = std::abs(double(s.points.size()) - double(o.n)) / double(o.n);
  check(exact_count ? s.points.size() == o.n : miss <= 0.03, "point count", s.name);
  check(s.normals.size() == s.points.size() &&
            s.near_boundary.size() == s.points.size() &&
            s.component.size() == s.points.size(),
        "per-point sizes",
        s.name);
  for (const auto& n : s.normals)
    if (std::abs(n.norm() - 1.0) > 1e-12) {
      check(false, "unit normals", s.name);
      break;
    }
  check(s.boundary_loops == g.loops && s.components == g.components &&
            s.euler == g.euler,
        "topology",
        s.name);
  check(s.closed == (g.loops == 0) && s.boundary_curve.empty() == s.closed,
        "closed",
        s.name);
  check(s.boundary_curve_loop.size() == s.boundary_curve.size(), "loop ids", s.name);
  // Boundary step <= spacing / 4, closing step of each loop included.
  double worst_step = 0.0;
  for (std::size_t k = 0; k < s.boundary_curve.size(); ++k) {
    std::size_t next = k + 1;
    if (next == s.boundary_curve.size() ||
        s.boundary_curve_loop[next] != s.boundary_curve_loop[k]) {
      next = k;
      while (next > 0 && s.boundary_curve_loop[next - 1] == s.boundary_curve_loop[k])
        --next;
    }
    worst_step =
        std::max(worst_step, (s.boundary_curve[next] - s.boundary_curve[k]).norm());
  }
  check(worst_step <= 0.25 * s.spacing, "boundary step", s.name);
  for (const auto& c : s.boundary_curve)
    if (s.distance(c) > 1e-9) {
      check(false, "boundary curve on the surface", s.name);
      break;
    }
  double worst = 0.0;
  for (const auto& p : s.points)
    worst = std::max(worst, s.distance(p));
  return worst;
}

/** Ratio of the mean nearest-neighbour distance at the sparse and dense ends. */
double
densityContrast(const Sample& s, int axis)
{
  double lo = 1e300, hi = -1e300;
  for (const auto& p : s.points) {
    lo = std::min(lo, p[axis]);
    hi = std::max(hi, p[axis]);
  }
  double sum[2] = {0, 0};
  int count[2] = {0, 0};
  for (std::size_t i = 0; i < s.points.size(); i += 7) {
    const double t = (s.points[i][axis] - lo) / (hi - lo);
    const int bin = t < 0.2 ? 0 : t > 0.8 ? 1 : -1;
    if (bin < 0)
      continue;
    double best = 1e300;
    for (std::size_t j = 0; j < s.points.size(); ++j)
      if (j != i)
        best = std::min(best, (s.points[j] - s.points[i]).norm());
    sum[bin] += best;
    ++count[bin];
  }
  return (sum[0] / count[0]) / (sum[1] / count[1]);
}

/** Brute-force distance to a surface patch X (u, v) over a parameter rectangle:
 *  a coarse-to-fine grid search. */
double
bruteDistance(const std::function<Eigen::Vector3d(double, double)>& X,
              double u0,
              double u1,
              double v0,
              double v1,
              const Eigen::Vector3d& q)
{
  double cu = 0.5 * (u0 + u1), cv = 0.5 * (v0 + v1), hu = 0.5 * (u1 - u0),
         hv = 0.5 * (v1 - v0);
  double best = 1e300;
  for (int level = 0; level < 7; ++level) {
    const int k = 100;
    double bu = cu, bv = cv;
    for (int i = -k; i <= k; ++i)
      for (int j = -k; j <= k; ++j) {
        const double u = std::max(u0, std::min(u1, cu + hu * i / k));
        const double v = std::max(v0, std::min(v1, cv + hv * j / k));
        const double d = (X(u, v) - q).norm();
        if (d < best) {
          best = d;
          bu = u;
          bv = v;
        }
      }
    cu = bu;
    cv = bv;
    hu *= 0.05;
    hv *= 0.05;
  }
  return best;
}

} // namespace

int
main()
{
  const std::vector<Generator> generators = {
      {"sphere",
       [](const SampleOptions& o) { return cocone_test::sphere(o); },
       0,
       1,
       2,
       0},
      {"ellipsoid",
       [](const SampleOptions& o) { return cocone_test::ellipsoid(o); },
       0,
       1,
       2,
       0},
      {"torus",
       [](const SampleOptions& o) { return cocone_test::torus(o); },
       0,
       1,
       0,
       0},
      {"hemisphere",
       [](const SampleOptions& o) { return cocone_test::hemisphere(o); },
       1,
       1,
       1,
       0},
      {"monkey_saddle",
       [](const SampleOptions& o) { return cocone_test::monkeySaddle(o); },
       1,
       1,
       1,
       0},
      {"open_cylinder",
       [](const SampleOptions& o) { return cocone_test::openCylinder(o); },
       2,
       1,
       0,
       0},
      {"curved_sheet",
       [](const SampleOptions& o) { return cocone_test::curvedSheet(o); },
       1,
       1,
       1,
       0},
      {"scan_line_sheet",
       [](const SampleOptions& o) { return cocone_test::scanLineSheet(o); },
       1,
       1,
       1,
       1},
      {"three_components",
       [](const SampleOptions& o) { return cocone_test::threeComponents(o); },
       4,
       3,
       2,
       -1},
      {"sphere_with_holes",
       [](const SampleOptions& o) { return cocone_test::sphereWithHoles(o); },
       3,
       1,
       -1,
       0},
  };

  std::printf("%-18s %-10s %6s %9s %6s %6s %10s %8s %8s\n",
              "surface",
              "variant",
              "n",
              "spacing",
              "curve",
              "near%",
              "max dist",
              "gen ms",
              "dist us");
  for (const auto& g : generators) {
    const bool scan = std::string(g.name) == "scan_line_sheet";
    SampleOptions base;
    base.n = 10000;

    // Even, noise-free.
    auto start = std::chrono::steady_clock::now();
    const Sample s = g.make(base);
    const double gen_ms = msSince(start);
    const double worst = checkSample(s, base, g, false);
    check(worst < 1e-9, "noise-free points on the surface", s.name);
    check(gen_ms < 500.0, "generation time", s.name);
    // 50k distance calls: points pushed off along the normal, as mesh centroids are.
    start = std::chrono::steady_clock::now();
    double sink = 0.0;
    for (int rep = 0; rep < 5; ++rep)
      for (std::size_t i = 0; i < s.points.size(); ++i)
        sink += s.distance(s.points[i] + (0.1 * rep - 0.2) * s.spacing * s.normals[i]);
    const double dist_us = msSince(start) * 1000.0 / (5.0 * s.points.size());
    std::size_t near = std::count(s.near_boundary.begin(), s.near_boundary.end(), true);
    std::printf("%-18s %-10s %6zu %9.5f %6zu %6.2f %10.2e %8.1f %8.2f%s\n",
                g.name,
                "even",
                s.points.size(),
                s.spacing,
                s.boundary_curve.size(),
                100.0 * near / s.points.size(),
                worst,
                gen_ms,
                dist_us,
                sink < 0 ? "!" : "");

    // Determinism: the same seed gives the same sample, another seed another one.
    const Sample again = g.make(base);
    check(again.points == s.points, "same seed, same sample", s.name);
    SampleOptions other = base;
    other.seed = 2;
    check(g.make(other).points != s.points, "other seed, other sample", s.name);

    // Random (area-uniform).
    SampleOptions random = base;
    random.even = false;
    start = std::chrono::steady_clock::now();
    const Sample r = g.make(random);
    const double r_ms = msSince(start);
    const double r_worst = checkSample(r, random, g, !scan);
    check(r_worst < 1e-9, "noise-free random points on the surface", r.name);
    std::printf("%-18s %-10s %6zu %9.5f %6zu %6s %10.2e %8.1f\n",
                g.name,
                "random",
                r.points.size(),
                r.spacing,
                r.boundary_curve.size(),
                "",
                r_worst,
                r_ms);

    // Noise 0.05: same sites, displaced along the normal only.
    SampleOptions noisy = base;
    noisy.noise = 0.05;
    start = std::chrono::steady_clock::now();
    const Sample z = g.make(noisy);
    const double z_ms = msSince(start);
    checkSample(z, noisy, g, false);
    check(z.points.size() == s.points.size() && z.spacing == s.spacing,
          "noise keeps sites",
          z.name);
    double sum2 = 0.0, tangential = 0.0, mismatch = 0.0;
    for (std::size_t i = 0; i < z.points.size() && z.points.size() == s.points.size();
         ++i) {
      const Eigen::Vector3d d = z.points[i] - s.points[i];
      const double along = d.dot(z.normals[i]);
      sum2 += along * along;
      tangential = std::max(tangential, (d - along * z.normals[i]).norm());
      if (!z.near_boundary[i])
        mismatch =
            std::max(mismatch, std::abs(z.distance(z.points[i]) - std::abs(along)));
    }
    const double sigma = std::sqrt(sum2 / z.points.size()) / z.spacing;
    check(std::abs(sigma - 0.05) < 0.005, "noise sigma", z.name);
    check(tangential < 1e-12, "noise along the normal", z.name);
    check(mismatch < 1e-9, "distance of noisy points", z.name);
    std::printf("%-18s %-10s %6zu %9.5f %6s %6s %10s %8.1f   sigma/spacing %.4f, "
                "|dist - |noise|| <= %.1e\n",
                g.name,
                "noise0.05",
                z.points.size(),
                z.spacing,
                "",
                "",
                "",
                z_ms,
                sigma,
                mismatch);

    // Density ratio 4, even and random.
    for (const bool even : {true, false}) {
      SampleOptions dense = base;
      dense.density_ratio = 4.0;
      dense.even = even;
      start = std::chrono::steady_clock::now();
      const Sample d = g.make(dense);
      const double d_ms = msSince(start);
      const double d_worst = checkSample(d, dense, g, !even && !scan);
      check(d_worst < 1e-9, "noise-free density points on the surface", d.name);
      std::printf("%-18s %-10s %6zu %9.5f %6zu %6s %10.2e %8.1f",
                  g.name,
                  even ? "ratio4" : "ratio4rnd",
                  d.points.size(),
                  d.spacing,
                  d.boundary_curve.size(),
                  "",
                  d_worst,
                  d_ms);
      if (g.density_axis >= 0) {
        const double contrast = densityContrast(d, g.density_axis);
        // Ends at densities ~1.3 and ~3.7: spacing ratio ~ sqrt (3.7 / 1.3) = 1.7.
        check(contrast > 1.4 && contrast < 2.1, "density contrast", d.name);
        std::printf("   sparse/dense NN %.2f", contrast);
      }
      std::printf("\n");
    }
  }

  // Components are far apart: gap over spacing.
  {
    SampleOptions o;
    const Sample s = cocone_test::threeComponents(o);
    double gap = 1e300;
    for (std::size_t i = 0; i < s.points.size(); i += 3)
      for (std::size_t j = 0; j < s.points.size(); j += 3)
        if (s.component[i] != s.component[j])
          gap = std::min(gap, (s.points[i] - s.points[j]).norm());
    std::printf(
        "three_components: smallest gap %.3f = %.1f spacings\n", gap, gap / s.spacing);
    check(gap > 20.0 * s.spacing, "component gap", s.name);
  }

  // Distances against a brute-force search, near and far, rims included.
  {
    std::mt19937_64 engine(7);
    const auto u01 = [&] { return (engine() >> 11) * (1.0 / 9007199254740992.0); };
    struct Patch {
      Sample s;
      std::function<Eigen::Vector3d(double, double)> X;
      double u0, u1, v0, v1;
      // Optional second chart over [0, pi]^2: the grid search is poor near a pole.
      std::function<Eigen::Vector3d(double, double)> Y = nullptr;
    };
    SampleOptions o;
    o.n = 3000;
    const double pi = 3.14159265358979323846;
    const Patch patches[] = {
        {cocone_test::monkeySaddle(o),
         [](double x, double y) {
           return Eigen::Vector3d(x, y, x * x * x - 3 * x * y * y);
         },
         -1,
         1,
         -1,
         1},
        {cocone_test::curvedSheet(o),
         [](double x, double y) {
           return Eigen::Vector3d(x, y, 0.15 * (x * x - 0.5 * y * y));
         },
         -1,
         1,
         -0.7,
         0.7},
        {cocone_test::ellipsoid(o),
         [](double t, double p) {
           return Eigen::Vector3d(1.5 * std::sin(t) * std::cos(p),
                                  std::sin(t) * std::sin(p),
                                  0.7 * std::cos(t));
         },
         0,
         pi,
         -pi,
         pi},
        {cocone_test::hemisphere(o),
         [](double t, double p) {
           return Eigen::Vector3d(
               std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
         },
         0,
         pi / 2,
         -pi,
         pi,
         [](double t, double p) {
           return Eigen::Vector3d(
               std::cos(t), std::sin(t) * std::cos(p), std::sin(t) * std::sin(p));
         }},
        {cocone_test::openCylinder(o),
         [](double p, double z) {
           return Eigen::Vector3d(0.5 * std::cos(p), 0.5 * std::sin(p), z);
         },
         -pi,
         pi,
         -1,
         1},
    };
    for (const auto& patch : patches) {
      double worst_near = 0.0, worst_far = 0.0;
      for (int k = 0; k < 300; ++k) {
        const bool far = k % 3 == 0;
        const auto& p = patch.s.points[engine() % patch.s.points.size()];
        const Eigen::Vector3d dir =
            Eigen::Vector3d(u01() - 0.5, u01() - 0.5, u01() - 0.5).normalized();
        const Eigen::Vector3d q =
            p + (far ? 0.6 * u01() : 3.0 * patch.s.spacing * u01()) * dir;
        double brute =
            bruteDistance(patch.X, patch.u0, patch.u1, patch.v0, patch.v1, q);
        if (patch.Y)
          brute = std::min(brute, bruteDistance(patch.Y, 0, pi, 0, pi, q));
        const double err = std::abs(patch.s.distance(q) - brute);
        double& worst = far ? worst_far : worst_near;
        worst = std::max(worst, err);
      }
      std::printf("%s distance vs brute force: near %.1e, far (<= 0.6) %.1e\n",
                  patch.s.name.c_str(),
                  worst_near,
                  worst_far);
      check(worst_near < 1e-7, "distance near the surface", patch.s.name);
      check(worst_far < 0.01 * patch.s.spacing,
            "distance away from the surface",
            patch.s.name);
    }
  }

  // Other sizes keep the count within 3 %.
  for (const std::size_t n : {200, 1500, 3000, 40000}) {
    SampleOptions o;
    o.n = n;
    for (const auto& g : generators) {
      const auto start = std::chrono::steady_clock::now();
      const Sample s = g.make(o);
      const double ms = msSince(start);
      const double miss = std::abs(double(s.points.size()) - double(n)) / double(n);
      check(miss <= 0.03, "count at n = " + std::to_string(n), s.name);
      if (n == 40000)
        std::printf(
            "n=%zu %-18s %6zu points %7.1f ms\n", n, g.name, s.points.size(), ms);
    }
  }

  std::printf(failures ? "%d FAILURES\n" : "all checks passed\n", failures);
  return failures ? 1 : 0;
}
