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
  /** Per point: true for an outlier (withOutliers, withScatteredOutliers), which is
   *  no sample of the surface: its near_boundary is false and its component -1. All
   *  false from the generators. */
  std::vector<bool> outlier;
  /** Per point: the range view it came from (rangeViews; -1 for the points added
   *  afterwards by withScatteredOutliers); empty from the generators. */
  std::vector<int> view;
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

/** A flat double torus: the points at distance 0.3 from a planar stadium (the
 *  segment x in [-1, 1], y = z = 0 widened by 1) with two round holes of radius 0.5
 *  about (+-1, 0, 0). Two flat faces at z = +-0.3 joined by half tubes (tangent
 *  continuous, curvature 0 to 1 / 0.3 across the seam); the narrowest passage is
 *  the holes' 0.4 diameter. closed, euler -2, area about 25.6; distance exact. */
Sample
genus2(const SampleOptions& o);
/** A thin rounded slab: the points at distance thickness / 2 from the rectangle
 *  [-1, 1] x [-0.7, 0.7] (corners rounded with radius 0.2) in z = 0; closed,
 *  euler 2, distance exact. The two sheets are closer than the spacing while
 *  thickness < spacing: with the default thickness for n up to about 10000 even,
 *  3500 random.
 *  The Poisson-disk elimination (even) only lets samples with normals less than
 *  90 degrees apart exclude each other, so that each sheet is evenly sampled
 *  on its own; spacing is measured within each half (normal z > 0, < 0), as the
 *  nearest sample overall is usually on the other sheet. */
Sample
thinPlate(const SampleOptions& o, double thickness = 0.02);
/** The surface of the cube [-side/2, side/2]^3: sharp edges and corners, face
 *  normals (a site on an edge gets the normal of the face it was drawn on); closed,
 *  euler 2, distance exact. */
Sample
cube(const SampleOptions& o, double side = 2.0);
/** A tube of the given radius (< 0.5) around the trefoil knot
 *  (sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t), of length 28.83: closed, euler 0,
 *  distance exact up to rounding (a Newton projection onto the curve). The default
 *  radius makes the tube coarse: 2 pi radius / spacing is about 8 for n = 10000
 *  (even; 13 random), and grows like sqrt (n radius). */
Sample
tube(const SampleOptions& o, double radius = 0.02);
/** Two spheres of the given radius on the x axis, gap * spacing apart (centres at
 *  +-(radius + gap spacing / 2)): components 2, each closed, euler 4. Each sphere
 *  is sampled on its own (the Poisson-disk elimination ignores the other one) and
 *  spacing is measured within each sphere; the closest samples of the two spheres
 *  are then 0.5 to 0.6 spacings apart (gap 0.5). */
Sample
twoTouchingSpheres(const SampleOptions& o, double radius = 1.0, double gap = 0.5);

/** Registered range scans of a dense, noise-free sample of a surface (best an even
 *  one, a few times denser than the scans are meant to be; its outliers are left
 *  out). Camera v of `views` looks at the bounding box centre from 4 half-diagonals
 *  away, from direction v of a Fibonacci lattice on the sphere (z = 1 - (2 v + 1) /
 *  views, longitude v times the golden angle). A view sees the sites facing it
 *  (normal . (camera - site) > 0; either side for an open surface) that no other
 *  part hides: a z-buffer of cells of 0.7 dense spacings in which every site is a
 *  disc of radius 2 dense spacings in its tangent plane; a site more than 1.5 dense
 *  spacings behind the nearest disc in its cell is hidden. Each view keeps each site
 *  it sees that no earlier view kept with probability keep (so the views are
 *  disjoint and denser where they overlap), adds its own Gaussian noise along the
 *  true normal (sigma = noise spacings) and is then moved by its own random rigid
 *  motion: a rotation about the centre and a translation, each moving no point by
 *  more than registration_error / 2 spacings. spacing is that of the result,
 *  measured on the kept sites before noise and motion; normals are the true ones at
 *  those sites and distance is that of the true (unmoved) surface, so a
 *  noise-free point lies up to registration_error spacings off it.
 *
 *  Truth: the views cover the surface when every site of `surface` is within 2
 *  dense spacings of one that some view saw; then the truth is that of `surface`
 *  (closed, loops, euler, components; near_boundary of the kept sites). Random
 *  holes that keep < 1 leaves between the kept sites do not count. A closed surface
 *  needs views all around it; with 12000-site surfaces these counts and all larger
 *  ones up to 16 cover: 2 the thin plate, 3 the cube, 4 the sphere and the tube, 5
 *  the torus, 8 genus2 (the insides of its holes; 5 happens to, 6 and 7 do not), 11
 *  the two touching spheres (7 to 9 happen to; their facing caps are never seen
 *  but are small). Use a few more views, or check the result.
 *  Otherwise the truth is unknown: closed false, boundary_loops -1, components -1,
 *  euler 0, no boundary curve, and near_boundary marks the kept sites within 3
 *  spacings of an unseen site: treat the sample as a partial scan and compare no
 *  topology. Throws std::invalid_argument for views < 1, registration_error < 0,
 *  noise < 0, keep not in (0, 1], a surface without points or normals, or if no view
 *  sees anything. */
Sample
rangeViews(const Sample& surface,
           int views,
           double registration_error,
           std::uint64_t seed,
           double noise = 0.0,
           double keep = 0.5);

/** Replaces round(fraction * n) random points by flying pixels: each moved along its
 *  true normal, to either side, by a uniform offset in [1, max_offset_spacings]
 *  spacings; they become outliers (near_boundary false, component -1) and keep
 *  their normals. All else (spacing, truth) is unchanged. Throws
 *  std::invalid_argument for fraction outside [0, 1] or max_offset_spacings < 1. */
Sample
withOutliers(Sample s, double fraction, double max_offset_spacings, std::uint64_t seed);
/** Appends round(fraction * n) outliers uniform in the points' bounding box widened
 *  on every side by 5 % of its largest extent (some fall near the surface by
 *  chance: s.distance tells); their normals are zero, near_boundary false, component
 *  -1, view -1 (when s.view is not empty). Throws std::invalid_argument for
 *  fraction < 0. */
Sample
withScatteredOutliers(Sample s, double fraction, std::uint64_t seed);

} // namespace cocone_test
