/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>

#include <support/cases.h>
#include <support/metrics.h>

#include <cstdio>

// Prints the README's table: fixed rho 1.5, fixed rho 2.5 and the default mode on
// the synthetic test surfaces (build/test/cocone_quality_table).
#include <functional>
using namespace cocone_test;

int
main()
{
  struct C {
    const char* name;
    std::function<Sample()> make;
  };
  std::vector<C> cases = {
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
    printf("| %s (%d, %d) |", c.name, s.boundary_loops, s.euler);
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
