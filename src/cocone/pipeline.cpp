/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/boundary.h>
#include <pcl/surface/cocone/candidates.h>
#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/hole_refinement.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/noise.h>
#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/pruning.h>
#include <pcl/surface/cocone/repair.h>
#include <pcl/surface/cocone/triangulation.h>
#include <pcl/surface/cocone/umbrella.h>
#include <pcl/surface/cocone/voronoi_cell.h>
#include <pcl/surface/cocone/walk.h>

#include <Eigen/Geometry>

#include "caller_ids.h"
#include "disjoint_sets.h"
#include "edge_sort.h"
#include "parallel.h"
#include "points.h"
#include "stages.h"
#include "stopwatch.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <system_error>
#include <utility>

namespace pcl {
namespace cocone {
namespace detail {

WalkedMesh
walkCandidates(const std::vector<Eigen::Vector3d>& points,
               const std::vector<Triangle>& candidates,
               const std::vector<std::uint8_t>& labels,
               int threads,
               ReconstructionCounts& counts)
{
  WalkedMesh mesh;
  const TriangleComplex complex(points, candidates, threads);
  std::vector<std::uint8_t> umbrella_triangles;
  mesh.umbrella_failed =
      umbrellaFailures(complex, labels, &umbrella_triangles, threads);
  std::vector<std::uint8_t> boundary = labels;
  for (std::size_t v = 0; v < boundary.size(); ++v)
    if (mesh.umbrella_failed[v]) {
      boundary[v] = 1;
      ++counts.umbrella_failures;
    }
  const std::vector<std::uint8_t> present =
      prune(complex, boundary, &counts.pruned, umbrella_triangles);
  WalkResult walked = walk(complex, present, boundary, threads);
  counts.walk_components = walked.components;
  counts.walked = walked.triangles.size();
  counts.walk_conflicts = walked.conflicts;
  counts.walk_reseeds = walked.reseeds;
  // Read off the complex, then kept by the repair, the edge incidences serve the
  // steps after it.
  mesh.incidences = walkedIncidences(complex, walked, threads);
  mesh.triangles = std::move(walked.triangles);
  repairManifold(points, mesh.triangles, counts.repair, threads, &mesh.incidences);
  return mesh;
}

std::vector<Triangle>
plainCoconeMesh(const std::vector<Eigen::Vector3d>& points,
                const VoronoiCells& cells,
                const std::vector<std::uint8_t>& region,
                int threads)
{
  const std::vector<std::uint8_t> none(points.size(), 0);
  std::vector<Triangle> candidates = selectCandidates(cells, none);
  candidates.erase(std::remove_if(candidates.begin(),
                                  candidates.end(),
                                  [&](const Triangle& t) {
                                    return !region[t[0]] || !region[t[1]] ||
                                           !region[t[2]];
                                  }),
                   candidates.end());
  ReconstructionCounts scratch;
  return walkCandidates(points, candidates, none, threads, scratch).triangles;
}

} // namespace detail

namespace {

/** The fewest points of a part the walk left unmeshed that the original Co-cone's
 * mesh stands in for (unmeshedParts()): above the specks' and the outlier clusters'
 * sizes (MIN_PIECE_VERTICES); the smallest true piece in the tests and the shared
 * clouds has hundreds. */
constexpr std::size_t MIN_UNMESHED_PART = 64;

/** A part of the surface whose largest piece of the walk's mesh holds less than
 * this share of its points is one the walk broke up (unmeshedParts()). Measured
 * before the hole filling on the generated surfaces (3,000 and 8,000 samples, even
 * and random, density 1:1 and 1:8, clean and with noise of half a spacing): on the
 * knotted tube 6 to 9 samples round the largest piece holds at most 39 % of the tube
 * (16 to 52 pieces); on every other surface 49 % (two touching spheres, one piece
 * each) to 100 %; on the range scans 97 % and more. A part of up to three closed
 * objects touching within the reach keeps the walk's pieces. */
constexpr double BROKEN_PART_SHARE = 1.0 / 3.0;

/** A part of the surface whose points the walk's mesh uses fewer than this share of
 * is one the walk failed on (unmeshedParts()). Measured before the hole filling: no
 * part of the range scans, the merged Stanford scans, the closed meshes' vertex sets
 * (clean, noise 0.3 and 1.0) or the generated surfaces other than the coarse tube
 * uses fewer (the least, 93 %: a noisy thin plate); the knotted tube 6 to 9 samples
 * round 0 to 93 %, 66 and 88 % where a stretch of it was left out and the tube came
 * out pinched. */
constexpr double MESHED_PART_SHARE = 0.9;

/** The points of the parts of the surface the walk left partly unmeshed or broke
 * up: the pieces co-cone triangles of the local spacing join the points into, of at
 * least MIN_UNMESHED_PART points, fewer than MESHED_PART_SHARE of which the walk's
 * mesh uses or whose largest piece of the walk's mesh holds less than
 * BROKEN_PART_SHARE of them.
 * The flatness test found such a part undersampled over much of it or across it all
 * round (a knot's tube a few samples round: the walk leaves specks, short stretches
 * of tube that the hole filling caps, or one long stretch capped at both ends); what
 * the original Co-cone makes of it is the best guess there is, and its holes are then
 * closed like the walk's. Empty if there is none. */
std::vector<std::uint8_t>
unmeshedParts(std::size_t n,
              const std::vector<CoconeTriangle>& cocone_triangles,
              detail::CoconeTrianglesWithinReach& within_reach,
              const std::vector<Triangle>& triangles)
{
  const std::vector<std::uint8_t> meshed = usedVertices(triangles, n);
  // The mesh's pieces first; the parts join them with the co-cone triangles. Each
  // of the mesh's triangles is then in one part, and taking out a part's leaves the
  // others' fans whole.
  detail::DisjointSets parts(n);
  const auto join = [&](const auto& corners) {
    parts.unite(corners[0], corners[1]);
    parts.unite(corners[0], corners[2]);
  };
  for (const auto& t : triangles)
    join(t);
  // Each piece's size is kept at its root, the only vertex with a nonzero count.
  // 32 bits hold any count: the triangulation indexes the points with int.
  std::vector<std::uint32_t> piece(n, 0);
  std::size_t unmeshed = 0, pieces = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const int root = parts.find(static_cast<int>(v));
    pieces += meshed[v] && piece[root] == 0;
    piece[root] += meshed[v];
    unmeshed += !meshed[v];
  }
  // No part can be selected without the co-cone triangles' pass (the clean cloud's
  // case): one of MIN_UNMESHED_PART points that the mesh uses fewer than
  // MESHED_PART_SHARE of holds that many unmeshed points, and with at most two
  // pieces the larger holds half of a part's meshed points, more than
  // BROKEN_PART_SHARE of it.
  if (static_cast<double>(unmeshed) < (1.0 - MESHED_PART_SHARE) * MIN_UNMESHED_PART &&
      pieces <= 2)
    return std::vector<std::uint8_t>();
  const std::vector<std::uint8_t>& reach = within_reach.mask();
  for (std::size_t i = 0; i < cocone_triangles.size(); ++i)
    if (reach[i])
      join(cocone_triangles[i].v);
  // Per part (its root): its points, those the mesh uses and its largest piece.
  std::vector<std::uint32_t> size(n, 0), used(n, 0), largest(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    const int root = parts.find(static_cast<int>(v));
    ++size[root];
    used[root] += meshed[v];
    largest[root] = std::max(largest[root], piece[v]);
  }
  std::vector<std::uint8_t> region(n, 0);
  bool any = false;
  for (std::size_t v = 0; v < n; ++v) {
    const int root = parts.find(static_cast<int>(v));
    if (size[root] >= MIN_UNMESHED_PART &&
        (static_cast<double>(used[root]) < MESHED_PART_SHARE * size[root] ||
         static_cast<double>(largest[root]) < BROKEN_PART_SHARE * size[root])) {
      region[v] = 1;
      any = true;
    }
  }
  return any ? region : std::vector<std::uint8_t>();
}

/** The longest edge, in local spacings, of a bridge between two parts of the walk's
 * mesh that is kept (dropBridges()): CGAL's knot2, two linked tori 5 spacings
 * apart, had one of 6; the strips one triangle wide within a part on CGAL's
 * example meshes have edges of 0.3 to 1.8 (median edge lengths round them). */
constexpr double BRIDGE_SPACINGS = 3.0;

/** Stages 4-7 and the repair, up to the undersampled holes: the oriented manifold
 * mesh over vertex ids and its border loops; returns its edge incidences. */
EdgeIncidences
walkSurface(Triangulation& dt,
            const VoronoiCells& cells,
            const Parameters& parameters,
            const std::vector<double>& rim_reach,
            const std::vector<double>& spacing,
            detail::CoconeTrianglesWithinReach& within_reach,
            Result& result)
{
  auto& counts = result.counts;
  const std::vector<Triangle> candidates = selectCandidates(
      cells, result.boundary, parameters.candidate_rule, &dt, rim_reach);
  counts.candidates = candidates.size();
  dt.release(); // the cells are no longer needed: make room for stages 5-7
  const int threads = resolveThreads(parameters.threads);
  detail::WalkedMesh mesh =
      detail::walkCandidates(dt.points, candidates, result.boundary, threads, counts);
  result.umbrella_failed = std::move(mesh.umbrella_failed);
  EdgeIncidences& incidences = mesh.incidences;
  result.triangles = std::move(mesh.triangles);
  if (parameters.fill_hole_edges >= 3) {
    // A hole is closed with triangles whose dual Voronoi edge meets a co-cone.
    const auto cocone_triangle = [&](const Triangle& t) {
      const auto it = std::lower_bound(
          cells.triangles.begin(),
          cells.triangles.end(),
          t,
          [](const CoconeTriangle& a, const Triangle& b) { return a.v < b; });
      return it != cells.triangles.end() && it->v == t;
    };
    // No second repair: a hole is a simple loop of border edges (every vertex of
    // the repaired mesh has one fan), its triangles add no edge the mesh has and run
    // against the loop, so the mesh stays an oriented manifold (checked on the
    // tests, the synthetic table and the range scans: a repair after filling never
    // changed a triangle).
    counts.repair.filled = fillHoles(dt.points,
                                     result.triangles,
                                     cocone_triangle,
                                     parameters.fill_hole_edges,
                                     &incidences);
  }
  counts.repair.ribbon = dropRibbons(result.triangles, dt.points.size(), &incidences);
  counts.repair.ribbon +=
      dropBridges(dt.points, spacing, BRIDGE_SPACINGS, result.triangles, &incidences);
  if (parameters.fill_undersampled_holes && !spacing.empty()) {
    const std::vector<std::uint8_t> unmeshed = unmeshedParts(
        dt.points.size(), cells.triangles, within_reach, result.triangles);
    if (!unmeshed.empty()) {
      // The walk's triangles there (all their corners in the part) make way for
      // the Co-cone's over the whole part: the mesh stays an oriented manifold.
      std::vector<std::uint8_t> replaced(result.triangles.size(), 0);
      for (std::size_t t = 0; t < result.triangles.size(); ++t)
        replaced[t] = unmeshed[result.triangles[t][0]];
      removeTriangles(result.triangles, replaced, &incidences);
      const std::size_t kept = result.triangles.size();
      const std::vector<Triangle> parts =
          detail::plainCoconeMesh(dt.points, cells, unmeshed, threads);
      result.triangles.insert(result.triangles.end(), parts.begin(), parts.end());
      incidences.add(result.triangles, kept);
      counts.unmeshed_parts = parts.size();
    }
  }
  // The borders, in vertex ids (neither the order of the triangles nor the corner
  // each starts at, both set below, matters to them).
  result.border_loops = boundaryLoops(incidences, dt.points.size());
  return std::move(incidences);
}

/** The mesh in a canonical order, and its normals. */
void
finishMesh(const Triangulation& dt,
           const VoronoiCells& cells,
           int threads,
           Result& result)
{
  std::vector<std::uint8_t> boundary = result.boundary;
  for (std::size_t v = 0; v < boundary.size(); ++v)
    boundary[v] |= result.umbrella_failed[v];
  // A canonical order: the same input gives the same mesh, whatever the walk order.
  for (auto& t : result.triangles)
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  detail::sortByVertexIds(
      result.triangles, dt.points.size(), [](const Triangle& t) { return t; }, threads);

  // Normals: the pole line, turned to the side the mesh faces. At an undersampled
  // point the pole says little (at a border it leans towards the convex hull): there
  // the area-weighted normal of the point's triangles stands in.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Eigen::Vector3d> facing(dt.points.size(), Eigen::Vector3d::Zero());
  for (const auto& t : result.triangles) {
    const auto& P = dt.points;
    const Eigen::Vector3d n = (P[t[1]] - P[t[0]]).cross(P[t[2]] - P[t[0]]);
    for (const int v : t)
      facing[v] += n;
  }
  result.normals.assign(dt.points.size(), Eigen::Vector3d::Constant(nan));
  for (std::size_t v = 0; v < dt.points.size(); ++v) {
    if (facing[v].squaredNorm() == 0.0)
      continue; // not in the mesh
    if (boundary[v])
      result.normals[v] = facing[v].normalized();
    else {
      const Eigen::Vector3d& pole = cells.pole[v];
      result.normals[v] = pole.dot(facing[v]) < 0.0 ? Eigen::Vector3d(-pole) : pole;
    }
  }
}

/** Per vertex: whether it counts in the cloud's statistics (one of the first
 * Parameters::statistics_points points is at it); empty: all do. */
std::vector<std::uint8_t>
countedVertices(const Parameters& parameters,
                const std::vector<int>& vertex_of_input,
                std::size_t vertices)
{
  const std::size_t n = parameters.statistics_points;
  std::vector<std::uint8_t> counted;
  if (n == 0 || n >= vertex_of_input.size())
    return counted;
  counted.assign(vertices, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (vertex_of_input[i] >= 0)
      counted[vertex_of_input[i]] = 1;
  return counted;
}

/** Stage 3's findings: the undersampled vertices, and what the reconstruction reads
 * of the tests. */
struct Undersampling {
  /** Per vertex: undersampled (the flatness test failed or a rim of the half-disk
   * test). */
  std::vector<std::uint8_t> boundary;
  /** Per vertex, the local spacing; empty when no test needs it. */
  std::vector<double> spacing;
  /** Per vertex: for a rim vertex the longest edge at it of a triangle it may
   * choose (its local spacing), infinite for the others; empty without the
   * half-disk test. */
  std::vector<double> rim_reach;
  /** The ratio rho used. */
  double ratio = 0.0;
};

/** Stage 3 on a triangulation and its first Voronoi pass: the local spacing (from
 * \a mean_spacing where the noise handling has it, meanSpacing()) and the
 * half-disk test, which read the nearest neighbours, then the second Voronoi pass
 * (the co-cones, into \a cells), whose peak memory then does not hold the neighbour
 * lists, then the flatness test. Its time goes to \a timings. */
Undersampling
detectUndersampling(Triangulation& dt,
                    VoronoiCells& cells,
                    const Parameters& parameters,
                    Stages stages,
                    const std::vector<std::uint8_t>& counted,
                    int threads,
                    std::vector<double> mean_spacing,
                    Timings& timings)
{
  detail::Stopwatch clock;
  Undersampling out;
  const bool detect = parameters.boundary_detection;
  const bool half_disk = detect && parameters.gap_angle > 0.0;
  if (detect && (parameters.spacing_factor > 0.0 || half_disk))
    out.spacing = mean_spacing.size() == dt.points.size()
                      ? localSpacing(cells, mean_spacing, threads)
                      : localSpacing(dt.points, cells, threads);
  std::vector<double>().swap(mean_spacing); // before the second pass's peak
  HalfDisk test;
  if (half_disk)
    test = halfDiskTest(dt.points,
                        cells,
                        out.spacing,
                        parameters.gap_reach,
                        parameters.gap_angle,
                        threads,
                        counted);
  std::vector<std::array<int, VoronoiCells::NEAREST>>().swap(cells.nearest);
  timings.boundary += clock.lap();

  computeCocones(dt, parameters.cocone_angle, parameters.threads, cells);
  // Only the paper's literal candidate rule reads the cells again.
  if (stages != Stages::RECONSTRUCTION ||
      parameters.candidate_rule != CandidateRule::LITERAL)
    dt.release();
  timings.voronoi += clock.lap();

  const std::size_t n = dt.points.size();
  out.boundary.assign(n, 0);
  if (detect) {
    const double ratio =
        parameters.ratio > 0.0 ? parameters.ratio : automaticRatio(cells, counted);
    const BoundaryLabels labels =
        detectBoundary(cells,
                       {ratio, parameters.normal_angle, parameters.spacing_factor},
                       out.spacing,
                       threads);
    out.ratio = labels.ratio;
    for (std::size_t v = 0; v < n; ++v)
      out.boundary[v] = !labels.interior[v];
    if (half_disk) {
      out.rim_reach.assign(n, std::numeric_limits<double>::infinity());
      for (std::size_t v = 0; v < n; ++v)
        if (!out.boundary[v] && test.rim[v]) {
          out.boundary[v] = 1;
          out.rim_reach[v] = out.spacing[v];
        }
    }
  }
  timings.boundary += clock.lap();
  return out;
}

/** Smoothing moved the points as noise would if the kurtosis of their displacements
 * is at least this (displacementKurtosis(): Gaussian noise 3, points pulled onto a
 * sheet they do not sample, 1 to 2.5). */
constexpr double NOISE_KURTOSIS = 2.5;
/** Smoothing took the noise out if it left at most this share of the noise level. */
constexpr double SMOOTHED_NOISE_SHARE = 0.5;
/** Below this kurtosis of the displacements the smoothing moved the points alike,
 * as it does a shape it flattens (a thin plate's sheets onto one, 1.05 and 1.39;
 * a coarse tube onto its axis, 1.33 and 1.52): that of a uniform distribution.
 * Between it and NOISE_KURTOSIS they do not tell (noise on a coarse or creased
 * shape: see runStages()). */
constexpr double ALIKE_KURTOSIS = 1.8;
/** Above this kurtosis, twice the Gaussian's, the displacements are heavy-tailed: a
 * minority of the points moved far more than the rest, as where the smoothing
 * flattens a shape's creases and thin parts, noisy or not; the scales are then told
 * apart as between ALIKE_KURTOSIS and NOISE_KURTOSIS. Measured: clouds with Gaussian
 * noise of 0.3 to 1 spacing (the closed meshes' vertex sets, the synthetic surfaces,
 * registered views of them) 2.0 to 4.6, where the shape has sharp features 5.9 to
 * 44 (originalHead: the meshes keep the smoothed run); without noise the bunny's
 * vertex set 7.9, which the smoothing flattens in places (4 loops smoothed, 1 as
 * given); the Stanford range scans 18 to 186 (the given points mesh better) and 16
 * merged (the smoothed ones, the same mesh). The cost: both scales' stages 3 to 8,
 * about twice the time of one. */
constexpr double HEAVY_KURTOSIS = 6.0;
/** Where the displacements do not tell, the smoothed points' run is kept if its
 * mesh leaves out or has on its border at most this share of the points the given
 * points' mesh does (see runStages()). */
constexpr double UNRESOLVED_SHARE = 0.8;
/** Smoothing took noise out, not just flattened a clean sample, if it lengthened the
 * median pole height (medianPoleHeight()) at least this many times: with noise of
 * 0.2 to 1 spacing on the closed meshes' vertex sets 1.8 to 5.4 times, on clean
 * vertex sets of meshes 1.0 to 1.4 (one 1.9), whose uneven sampling reads as a noise
 * level of 0.4 to 0.8 and whose displacements can be distributed as noise's (cow,
 * elephant, femur in CGAL's data: kurtosis 3.8 to 4.8). Below it the scales are told
 * apart by their meshes, as between ALIKE_KURTOSIS and NOISE_KURTOSIS. */
constexpr double NOISE_POLE_GAIN = 1.6;

/** A triangulation with its first Voronoi pass, and the map from the caller's
 * points to its vertices. */
struct Sample {
  Triangulation dt;
  VoronoiCells cells;
  std::vector<int> vertex_of_input;
  std::size_t vertices = 0;
};

/** The sample of \a positions (a triangulation's vertices, recentred by \a offset),
 * the outliers left out and the vertices renumbered by makeUniquePoints()
 * (smoothing may bring two points together); \a vertex_of_input maps the caller's
 * points to the given vertices. Sets \a error if too few points are left. */
Sample
retriangulate(std::vector<Eigen::Vector3d> positions,
              const Eigen::Vector3d& offset,
              const std::vector<std::uint8_t>& outlier,
              std::vector<int> vertex_of_input,
              const Parameters& parameters,
              int threads,
              std::string& error)
{
  Sample sample;
  std::vector<int> kept_index(positions.size(), -2);
  std::size_t k = 0;
  for (std::size_t v = 0; v < positions.size(); ++v)
    if (!outlier[v]) {
      kept_index[v] = static_cast<int>(k);
      positions[k++] = positions[v] + offset;
    }
  positions.resize(k);
  UniquePoints unique = makeUniquePoints(positions, threads);
  std::vector<Eigen::Vector3d>().swap(positions);
  for (int& v : vertex_of_input)
    if (v >= 0)
      v = kept_index[v] < 0 ? -2 : unique.vertex_of_input[kept_index[v]];
  sample.vertex_of_input = std::move(vertex_of_input);
  sample.vertices = unique.points.size();
  if (unique.points.size() < 4) {
    error = "fewer than 4 distinct finite points that are not outliers (" +
            std::to_string(unique.points.size()) + ")";
    return sample;
  }
  sample.dt = triangulate(std::move(unique.points), threads);
  if (sample.dt.dimension < 2) {
    error = "the points that are not outliers are collinear";
    return sample;
  }
  sample.cells = computePoles(sample.dt, parameters.cocone_angle, parameters.threads);
  return sample;
}

/** Noise handling between the first pass over the cells and the rest: the noise
 * levels, and where there are outliers or noise, the triangulation and the first pass
 * again, of the smoothed points without the outliers.
 *
 * The displacements tell whether the smoothing took noise out or flattened a shape
 * too coarse or creased for the jets when they are distributed as noise is. When
 * they are not (a coarse surface with noise reads like one without: see
 * runStages()) and the stages include the reconstruction, \a dt and \a cells are
 * those of the given points and the smoothed points' sample is returned beside
 * them; null otherwise (without the reconstruction the given points stay). Sets
 * result.error if too few points are left. \a mean_spacing gets the vertices' mean
 * spacings (meanSpacing()), which stage 3 reads too, while \a dt stays. */
std::unique_ptr<Sample>
handleNoise(Triangulation& dt,
            VoronoiCells& cells,
            const Parameters& parameters,
            Stages stages,
            Result& result,
            int threads,
            std::vector<double>& mean_spacing)
{
  if (cells.nearest.size() != dt.points.size())
    return nullptr; // no neighbour lists (coplanar points): nothing to read
  const std::vector<std::uint8_t> counted =
      countedVertices(parameters, result.vertex_of_input, result.vertices);
  mean_spacing = meanSpacing(dt.points, cells, threads);
  NoiseAnalysis noise =
      analyzeNoise(dt.points, cells.nearest, threads, counted, false, mean_spacing);
  result.noise_level = noise.cloud_level;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  result.point_noise.assign(result.vertex_of_input.size(), nan);
  for (std::size_t i = 0; i < result.vertex_of_input.size(); ++i)
    if (result.vertex_of_input[i] >= 0)
      result.point_noise[i] = noise.level[result.vertex_of_input[i]];
  std::vector<Eigen::Vector3d> smoothed;
  bool undecided = false;
  const bool two_scales =
      parameters.boundary_detection && stages == Stages::RECONSTRUCTION;
  double given_height = 0.0; // medianPoleHeight() of the given points
  if (noise.cloud_level > parameters.noise_threshold) {
    if (two_scales) // read only where both scales may run
      given_height = medianPoleHeight(cells, mean_spacing, noise.outlier, counted);
    // Not held through the smoothing's peak (the stages after read them again if
    // the given points' triangulation stands).
    std::vector<double>().swap(mean_spacing);
    smoothed = smoothPoints(dt.points,
                            cells.nearest,
                            noise.outlier,
                            std::max(parameters.smoothing_iterations, 1),
                            threads);
    // Smoothing takes noise out, moving each point by its own noise; a surface too
    // coarse or creased for the jets (a tube a few samples round, two sheets closer
    // than the spacing) it would flatten, moving the points alike or leaving the
    // level high: then the points stay as they are. The level alone does not tell:
    // noise of a spacing reads 0.9 on random samples and 1.25 on even ones, tubes
    // and thin plates 0.9 to 1.5.
    result.noise_after_smoothing =
        cloudNoiseLevel(smoothed, cells.nearest, noise.outlier, threads, counted);
    const bool reduced =
        result.noise_after_smoothing < SMOOTHED_NOISE_SHARE * noise.cloud_level;
    const double kurtosis = displacementKurtosis(dt.points, smoothed, noise.outlier);
    // Only meshes tell the scales apart (see runStages()): where the displacements
    // mix the two, or are heavy-tailed, a minority of the points moved far more than
    // the rest (the shape's creases and thin parts flattened, noise or not).
    result.smoothed = reduced && kurtosis >= NOISE_KURTOSIS &&
                      !(two_scales && kurtosis > HEAVY_KURTOSIS);
    undecided = reduced && !result.smoothed && kurtosis >= ALIKE_KURTOSIS && two_scales;
  }
  // The level read as noise, but the smoothing would not take it out: not noise but
  // a shape too coarse or creased for the jets, such as two sheets closer than the
  // spacing mixing in every neighbourhood (a thin plate reads 0.8 to 1.3). There,
  // as in a clean cloud, an outlier found with samples of a sheet of its own round it
  // is a sample (analyzeNoise()): clean thin plates of 10,000 random samples, seeds 1
  // and 2, had 3 and 7 of their samples set aside, now 1 each. Rare: the analysis
  // runs again rather than keep its state for this.
  if (noise.cloud_level > parameters.noise_threshold && !result.smoothed &&
      !undecided && noise.outliers > 0)
    noise = analyzeNoise(dt.points, cells.nearest, threads, counted, true);
  if (!result.smoothed && !undecided && noise.outliers == 0)
    return nullptr; // a clean cloud: the triangulation stands
  // The given points' triangulation goes below, unless it stands beside the
  // smoothed points' sample: its spacings go before the new one's peak.
  if (!undecided || noise.outliers > 0)
    std::vector<double>().swap(mean_spacing);

  const Eigen::Vector3d offset = dt.offset;
  const auto resample = [&](std::vector<Eigen::Vector3d>&& positions,
                            std::vector<int> vertex_of_input,
                            std::string& error) {
    return retriangulate(std::move(positions),
                         offset,
                         noise.outlier,
                         std::move(vertex_of_input),
                         parameters,
                         threads,
                         error);
  };
  const auto keep = [&](Sample&& sample) {
    dt = std::move(sample.dt);
    cells = std::move(sample.cells);
    result.vertex_of_input = std::move(sample.vertex_of_input);
    result.vertices = sample.vertices;
    result.offset = dt.offset;
  };
  std::unique_ptr<Sample> alternative;
  std::vector<Eigen::Vector3d> kept;
  if (undecided) {
    // Smoothed points too few or collinear to triangulate leave the given ones.
    std::string error;
    alternative = std::make_unique<Sample>(
        resample(std::move(smoothed), result.vertex_of_input, error));
    if (!error.empty())
      alternative.reset();
    if (noise.outliers == 0)
      return alternative; // the triangulation stands for the given points
    kept = std::move(dt.points);
  }
  else if (result.smoothed && two_scales) {
    // The smoothed points' sample stands alone only if their poles moved out
    // (NOISE_POLE_GAIN); else both scales run. The given points stay (released
    // cells keep their points) and are triangulated again if needed.
    cells = VoronoiCells();
    dt.release();
    Sample sample = resample(std::move(smoothed), result.vertex_of_input, result.error);
    if (!result.error.empty())
      return nullptr;
    std::vector<double> spacing = meanSpacing(sample.dt.points, sample.cells, threads);
    const double height = medianPoleHeight(
        sample.cells,
        spacing,
        {},
        countedVertices(parameters, sample.vertex_of_input, sample.vertices));
    if (height >= NOISE_POLE_GAIN * given_height) {
      keep(std::move(sample));
      mean_spacing = std::move(spacing);
      return nullptr;
    }
    result.smoothed = false;
    alternative = std::make_unique<Sample>(std::move(sample));
    kept = std::move(dt.points);
  }
  else
    kept = result.smoothed ? std::move(smoothed) : std::move(dt.points);
  cells = VoronoiCells();
  dt.release();
  keep(resample(std::move(kept), std::move(result.vertex_of_input), result.error));
  return alternative;
}

/** Stage 3 and the reconstruction on a triangulation and its first Voronoi pass,
 * and the findings back in the caller's ids. */
void
completeStages(Triangulation& dt,
               VoronoiCells& cells,
               const Parameters& parameters,
               Stages stages,
               const std::vector<int>& ids,
               int threads,
               std::vector<double> mean_spacing,
               Result& result)
{
  detail::Stopwatch clock;
  const auto id = [&](std::size_t i) {
    return ids.empty() ? static_cast<int>(i) : ids[i];
  };
  Undersampling undersampling = detectUndersampling(
      dt,
      cells,
      parameters,
      stages,
      countedVertices(parameters, result.vertex_of_input, result.vertices),
      threads,
      std::move(mean_spacing),
      result.timings);
  clock.lap();
  result.boundary = std::move(undersampling.boundary);
  result.ratio = undersampling.ratio;

  result.umbrella_failed.assign(result.vertices, 0);
  if (stages == Stages::RECONSTRUCTION) {
    detail::CoconeTrianglesWithinReach within_reach(
        dt.points, undersampling.spacing, cells.triangles);
    EdgeIncidences incidences = walkSurface(dt,
                                            cells,
                                            parameters,
                                            undersampling.rim_reach,
                                            undersampling.spacing,
                                            within_reach,
                                            result);
    detail::closeUndersampledHoles(dt.points,
                                   cells,
                                   parameters,
                                   undersampling.spacing,
                                   within_reach,
                                   incidences,
                                   result);
    finishMesh(dt, cells, threads, result);
    result.timings.reconstruction = clock.lap();
  }

  // Back to the caller's ids.
  result.representative.assign(result.vertices, std::numeric_limits<int>::max());
  for (std::size_t i = 0; i < result.vertex_of_input.size(); ++i) {
    const int v = result.vertex_of_input[i];
    if (v == -2)
      result.outlier_indices.push_back(id(i));
    if (v < 0)
      continue;
    result.representative[v] = std::min(result.representative[v], id(i));
    if (result.boundary[v] || result.umbrella_failed[v])
      result.boundary_indices.push_back(id(i));
  }
  std::sort(result.boundary_indices.begin(), result.boundary_indices.end());
  std::sort(result.outlier_indices.begin(), result.outlier_indices.end());
  detail::meshToCallerIds(result);
  result.positions = std::move(dt.points); // the triangulation's last use
  const int first_added = detail::firstAddedId(ids, result.vertex_of_input.size());
  if (parameters.refine_filled_holes && first_added >= 0) {
    refineFilledHoles(result, first_added);
    result.timings.reconstruction += clock.lap();
  }
}

/** The counted vertices (countedVertices()) that a run's mesh leaves out or has on
 * its border. */
std::size_t
unresolvedVertices(const Parameters& parameters, const Result& result)
{
  const std::vector<std::uint8_t> counted =
      countedVertices(parameters, result.vertex_of_input, result.vertices);
  // The mesh also holds the vertices the refinement of the filled holes added
  // (Result::positions beyond the sample's), which no input point is.
  std::vector<std::uint8_t> resolved = usedVertices(
      result.triangles, std::max(result.vertices, result.positions.size()));
  for (const int v : borderVertices(result.triangles))
    resolved[v] = 0;
  std::size_t count = 0;
  for (std::size_t v = 0; v < result.vertices; ++v)
    count += !resolved[v] && (counted.empty() || counted[v]);
  return count;
}

Result
runStages(std::vector<Eigen::Vector3d>&& points,
          const Parameters& parameters,
          Stages stages,
          const std::vector<int>& ids)
{
  Result result;
  const int threads = resolveThreads(parameters.threads);
  detail::Stopwatch clock;
  UniquePoints unique = makeUniquePoints(points, threads);
  std::vector<Eigen::Vector3d>().swap(points); // the unique points stand in for them
  result.vertex_of_input = std::move(unique.vertex_of_input);
  result.vertices = unique.points.size();
  result.timings.unique = clock.lap();
  if (unique.points.size() < 4) {
    result.error = "fewer than 4 distinct finite points (" +
                   std::to_string(unique.points.size()) + ")";
    return result;
  }

  Triangulation dt = triangulate(std::move(unique.points), threads);
  result.timings.delaunay = clock.lap();
  if (dt.dimension < 2) {
    result.error = "the points are collinear";
    return result;
  }
  result.offset = dt.offset;

  VoronoiCells cells = computePoles(dt, parameters.cocone_angle, parameters.threads);
  result.timings.voronoi = clock.lap();
  std::unique_ptr<Sample> smoothed;
  std::vector<double> mean_spacing; // the noise handling's, for stage 3
  if (parameters.noise_handling) {
    smoothed =
        handleNoise(dt, cells, parameters, stages, result, threads, mean_spacing);
    if (!result.error.empty())
      return result;
  }
  result.timings.noise = clock.lap();
  if (!smoothed) {
    completeStages(
        dt, cells, parameters, stages, ids, threads, std::move(mean_spacing), result);
    return result;
  }

  // Undecided whether the smoothing took noise out or flattened the shape (noise on
  // a shape too coarse or creased for the jets, whose displacements mix the two),
  // the pipeline runs at both scales and keeps the smoothed points' run where its
  // mesh leaves out or has on its border at most UNRESOLVED_SHARE of the points the
  // given points' mesh does: the scale at which the reconstruction resolves more of
  // the surface. This assumes that a shape the smoothing distorts comes out worse
  // meshed, not better. Measured on the vertex sets of closed meshes of this kind
  // (a CAD part, a coarse knotted tube): with noise of 0.3 and 0.5 spacings the
  // smoothed run leaves 0.35 to 0.66 of the given run's, without noise 4 times as
  // many or more. The undersampled points of stage 3 alone do not tell: the jets
  // round a CAD part's creases, which flattens their cells (0.60 of them without
  // noise, 0.49 with).
  Result alternative = result;
  alternative.vertex_of_input = std::move(smoothed->vertex_of_input);
  alternative.vertices = smoothed->vertices;
  alternative.offset = smoothed->dt.offset;
  alternative.smoothed = true;
  // The two scales are independent: given two threads or more they run at once,
  // half the threads each (the output is the same whatever the thread count).
  const int share = threads >= 2 ? threads / 2 : threads;
  Parameters shared = parameters;
  shared.threads = static_cast<unsigned int>(share);
  double given_ms = 0.0, smoothed_ms = 0.0;
  const auto given_scale = [&] {
    detail::Stopwatch watch;
    completeStages(
        dt, cells, shared, stages, ids, share, std::move(mean_spacing), result);
    given_ms = watch.lap();
  };
  const auto smoothed_scale = [&] {
    detail::Stopwatch watch;
    completeStages(
        smoothed->dt, smoothed->cells, shared, stages, ids, share, {}, alternative);
    smoothed_ms = watch.lap();
  };
  detail::forEachTask(2, threads >= 2 ? 2 : 1, [&](std::size_t scale) {
    scale == 0 ? given_scale() : smoothed_scale();
  });
  const bool smoothing_wins =
      static_cast<double>(unresolvedVertices(parameters, alternative)) <=
      UNRESOLVED_SHARE * static_cast<double>(unresolvedVertices(parameters, result));
  Result& kept = smoothing_wins ? alternative : result;
  kept.timings.noise += smoothing_wins ? given_ms : smoothed_ms; // the other scale's
  return std::move(kept);
}

} // namespace

Result
run(std::vector<Eigen::Vector3d> points,
    const Parameters& parameters,
    Stages stages,
    const std::vector<int>& ids)
{
  // Running out of memory is an outcome to report, not a reason to terminate the
  // caller's process (a scanning pipeline keeps running with an empty result).
  const std::size_t count = points.size();
  try {
    return runStages(std::move(points), parameters, stages, ids);
  }
  catch (const std::bad_alloc&) {
    Result failed;
    failed.error = "out of memory for " + std::to_string(count) + " points";
    return failed;
  }
  catch (const std::system_error& e) { // no thread could be started
    Result failed;
    failed.error = std::string("system error: ") + e.what();
    return failed;
  }
}

} // namespace cocone
} // namespace pcl
