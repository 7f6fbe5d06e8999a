/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Seeded point samples of surfaces with a known ground truth, for the tests.
 *
 * The samples are the same bit for bit on every platform and compiler: the only
 * random source is the raw output of std::mt19937_64 (fully specified by the
 * standard), turned into numbers with +, -, *, / and sqrt only, in a fixed order: no
 * <random> distributions, no libm, no Eigen reductions and no FMA contraction in the
 * samplers. (Checked: GCC 12 and Clang 14, -O0 to -O3, with and without
 * -march=native (FMA, AVX-512) and EIGEN_DONT_VECTORIZE.)
 */

#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace cocone_test {

/** Options common to all generators. */
struct SampleOptions {
  /** Target number of points; the actual count is within +-3 % (exact when random). */
  std::size_t n = 10000;
  std::uint64_t seed = 1;
  /** true: evenly spaced (Poisson-disk); false: area-uniform random. */
  bool even = true;
  /** Gaussian noise along the true normal; sigma as a FRACTION of the spacing. */
  double noise = 0.0;
  /** > 1: the density grows linearly 1 : density_ratio along x over each component. */
  double density_ratio = 1.0;
};

/** A sampled surface with its ground truth. */
struct Sample {
  std::string name;
  std::vector<Eigen::Vector3d> points;
  /** True unit normals at the noise-free sites; outward for closed surfaces. */
  std::vector<Eigen::Vector3d> normals;
  /** Mean distance to the nearest other sample, measured on the noise-free points
   *  (scanLineSheet: the in-row step). */
  double spacing = 0.0;
  /** Dense samples (step <= spacing / 4) of the true boundary curves, loop after
   *  loop; empty for closed surfaces. */
  std::vector<Eigen::Vector3d> boundary_curve;
  /** Number of boundary curves of the true surface. */
  int boundary_loops = 0;
  int components = 1;
  /** Euler characteristic V - E + F of the true surface. */
  int euler = 2;
  bool closed = true;
  /** Unused; 0. */
  double volume_sign = 0;
  /** Unsigned distance to the true surface (exact up to rounding near it, see
   *  below). */
  std::function<double(const Eigen::Vector3d&)> distance;
  /** Per point: the noise-free site is within `spacing` (Euclidean) of the true
   *  boundary. */
  std::vector<bool> near_boundary;

  // Additions to the agreed interface.

  /** Per boundary_curve sample: the index of its loop, 0 .. boundary_loops - 1. */
  std::vector<int> boundary_curve_loop;
  /** Per point: the index of its component, 0 .. components - 1. */
  std::vector<int> component;
  /** Area of the true surface. */
  double area = 0.0;
};

/* For the closed surfaces and the hemisphere, sphere with holes and cylinder the
 * distance is in closed form (the ellipsoid's by a 1D root search); for the height
 * fields it is a box-constrained Newton projection, so it is exact at the rim too.
 * All generators throw std::invalid_argument for n < 4, noise < 0, density_ratio < 1
 * or a non-positive size. */

Sample
sphere(const SampleOptions& o, double radius = 1.0);
Sample
ellipsoid(const SampleOptions& o, double a = 1.5, double b = 1.0, double c = 0.7);
Sample
torus(const SampleOptions& o, double R = 1.0, double r = 0.4);
/** The z >= 0 half: open, one boundary circle (the equator). */
Sample
hemisphere(const SampleOptions& o, double radius = 1.0);
/** z = x^3 - 3 x y^2 over [-1,1]^2 (the paper's MONKEY); one boundary loop. */
Sample
monkeySaddle(const SampleOptions& o);
/** Axis z, |z| <= height/2, no caps: two boundary circles, euler 0. */
Sample
openCylinder(const SampleOptions& o, double radius = 0.5, double height = 2.0);
/** z = 0.15 (x^2 - 0.5 y^2) over [-1,1] x [-0.7,0.7]; one boundary loop. */
Sample
curvedSheet(const SampleOptions& o);
/** The curved sheet in scan lines: rows at constant y, the first and last on the
 *  rim, points s apart (arc length) within a row, rows 3 s apart, each point
 *  jittered tangentially by up to 0.05 s (keeps the Delaunay triangulation
 *  non-degenerate). o.even is ignored. spacing = s, the in-row step, NOT the
 *  measured nearest-neighbour distance (which is about 0.97 s). With
 *  density_ratio > 1 the density grows along y instead of x: both the row
 *  distance and the in-row step scale with 1/sqrt(density), and spacing is the
 *  in-row step averaged over the points. */
Sample
scanLineSheet(const SampleOptions& o);
/** A hemisphere, a curved sheet and an open cylinder side by side along x, with
 *  gaps of max(1, 30 sqrt(area / n)) between their bounding boxes (about 36
 *  spacings when even, 60 when random):
 *  boundary loops 4, components 3, euler 2, closed false. Each component gets the
 *  full 1:density_ratio gradient over its own x extent. */
Sample
threeComponents(const SampleOptions& o);
/** The unit sphere minus `holes` caps of angular radius hole_angle centred on +x,
 *  +y, +z, -x, -y, -z (in that order; more than 6 holes: a Fibonacci lattice).
 *  Throws std::invalid_argument if the caps would touch. euler 2 - holes. */
Sample
sphereWithHoles(const SampleOptions& o, int holes = 3, double hole_angle = 0.5);

} // namespace cocone_test
