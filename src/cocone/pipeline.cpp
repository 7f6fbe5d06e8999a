/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/border_classification.h>
#include <pcl/surface/cocone/boundary.h>
#include <pcl/surface/cocone/candidates.h>
#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/handle_removal.h>
#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/hole_refinement.h>
#include <pcl/surface/cocone/hole_reopening.h>
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
#include "cocone_neighbours.h"
#include "disjoint_sets.h"
#include "edge_sort.h"
#include "points.h"
#include "stopwatch.h"

#include <algorithm>
#include <iterator>
#include <limits>
#include <memory>
#include <new>
#include <set>
#include <string>
#include <system_error>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

/** Stages 5-7 and the repair over stage 4's candidates: the oriented manifold
 * mesh, its edge incidences, and per vertex whether it failed the umbrella check. */
struct WalkedMesh {
  std::vector<Triangle> triangles;
  EdgeIncidences incidences;
  std::vector<std::uint8_t> umbrella_failed;
};

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

/** The original Co-cone's mesh (every vertex chooses) over the vertices of the
 * \a region and the co-cone triangles among them. */
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
unmeshedParts(const std::vector<Eigen::Vector3d>& points,
              const std::vector<double>& spacing,
              const std::vector<CoconeTriangle>& cocone_triangles,
              const std::vector<Triangle>& triangles)
{
  const std::size_t n = points.size();
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
  for (const auto& t : cocone_triangles)
    if (detail::triangleWithinReach(points, spacing, detail::FAR_NEIGHBOUR, t.v))
      join(t.v);
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

/** The last Delaunay patches' longest edge, in hole widths (Parameters::hole_width,
 * in rim triangle diameters). Measured on the closed meshes' vertex sets, clean and
 * with noise 0.2 to 1 spacing: the patches this lets close have edges of 3.5 to 4.7
 * rim triangles (12 loops fewer over the 42 clouds, none more); on the range scans
 * the occlusion holes it would close need 6 to 8 (at 2.4 the scans' border F1 drops
 * by 0.01 on one, at 2.0 and below none changes). */
constexpr double RIM_REACH_PER_WIDTH = 2.0;

/** Rings of co-cone and mesh triangles around the open parts that the original
 * Co-cone's mesh is made over. */
constexpr int PLAIN_COCONE_RINGS = 2;
/** The same for the advancing front: it grows from the most plausible triangle
 * inwards, and at the region's edge it has too little around to judge (on the
 * shared closed meshes 3 rings closed one loop fewer than 6, 10 none more). */
constexpr int ADVANCING_FRONT_RINGS = 6;
/** The band of the mesh's triangles a patch from the advancing front may replace
 * around a hole, per loop edge (on the shared closed meshes 6 and 12 closed no
 * loop more than 3). */
constexpr std::size_t BAND_PER_LOOP_EDGE = 3;

/** Rings of triangles a loop left open is reopened by at most (see reopen_loops in
 * reconstruct()). */
constexpr int REOPENED_RINGS = 3;
/** Loops reopened at most (those the patches could close; where more are left
 * open, the shortest): each attempt costs a pass over the mesh. Measured: the noisy
 * closed meshes leave 2 to 20 with noise up to a spacing, FinalBaseMesh 48 with
 * 1.5 (all tried: 22 loops left, 24 shortest: 28, none: 49); the merged Stanford
 * scans' run on the other scale leaves 84 (all tried: +8 s, 24: +2.7 s). */
constexpr std::size_t REOPENED_LOOPS = 24;
/** A vertex a reopened and closed hole leaves out is inserted into the new surface
 * if it lies within this many local spacings of it (else the attempt is undone): a
 * sample of that surface, off it within the noise band where two sheets meet.
 * Measured on the closed meshes with noise 0.3: a reach of 1, 1.5, 2 and 4 leaves
 * FinalBaseMesh 10, 10, 7 and 7 handles, the casting 17, 14, 14 and 14; 1 spacing
 * without the insertion (the vertices further out left out) 14 and 17. */
constexpr double REOPENED_REACH = 2.0;
/** ... or this many sigmas of the cloud's noise (Result::noise_level, read in
 * spacings before any smoothing) where that is wider: the band two noisy sheets
 * meet in grows with the noise. Measured on the closed meshes, knot, hot dogs and
 * kitten with noise 0.3, 0.5 and 1.0, seeds 2 and 3: wrong loops 133 and handles
 * 160 with the reach of 2 alone, 125 and 155 with 3 sigmas (a fixed reach of 4: 123
 * and 152, but it also closes a dropout on two of the Stanford range scans, whose
 * noise reads 0.15). */
constexpr double REOPENED_SIGMAS = 3.0;

/** The fewest vertices of a piece of the mesh (see dropSpecks()): the shards
 * between spheres two spacings apart have 4 to 7, the tetrahedra of outlier clusters
 * off the merged Stanford scans 4; the smallest true piece in the tests and the
 * shared clouds has hundreds. */
constexpr std::size_t MIN_PIECE_VERTICES = 8;

/** Stages 4-7 and the repair: the oriented manifold mesh over vertex ids. */
void
reconstruct(Triangulation& dt,
            const VoronoiCells& cells,
            const Parameters& parameters,
            const std::vector<double>& rim_reach,
            const std::vector<double>& spacing,
            Result& result)
{
  auto& counts = result.counts;
  const std::vector<Triangle> candidates = selectCandidates(
      cells, result.boundary, parameters.candidate_rule, &dt, rim_reach);
  counts.candidates = candidates.size();
  dt.release(); // the cells are no longer needed: make room for stages 5-7
  const int threads = resolveThreads(parameters.threads);
  WalkedMesh mesh =
      walkCandidates(dt.points, candidates, result.boundary, threads, counts);
  result.umbrella_failed = std::move(mesh.umbrella_failed);
  std::vector<std::uint8_t> boundary = result.boundary;
  for (std::size_t v = 0; v < boundary.size(); ++v)
    boundary[v] |= result.umbrella_failed[v];
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
  if (parameters.fill_undersampled_holes && !spacing.empty()) {
    const std::vector<std::uint8_t> unmeshed =
        unmeshedParts(dt.points, spacing, cells.triangles, result.triangles);
    if (!unmeshed.empty()) {
      // The walk's triangles there (all their corners in the part) make way for
      // the Co-cone's over the whole part: the mesh stays an oriented manifold.
      std::vector<std::uint8_t> replaced(result.triangles.size(), 0);
      for (std::size_t t = 0; t < result.triangles.size(); ++t)
        replaced[t] = unmeshed[result.triangles[t][0]];
      removeTriangles(result.triangles, replaced, &incidences);
      const std::size_t kept = result.triangles.size();
      const std::vector<Triangle> parts =
          plainCoconeMesh(dt.points, cells, unmeshed, threads);
      result.triangles.insert(result.triangles.end(), parts.begin(), parts.end());
      incidences.add(result.triangles, kept);
      counts.unmeshed_parts = parts.size();
    }
  }
  // The borders, in vertex ids (neither the order of the triangles nor the corner
  // each starts at, both set below, matters to them).
  result.border_loops = boundaryLoops(incidences, dt.points.size());
  if (parameters.fill_undersampled_holes && !spacing.empty()) {
    // Each loop classified once, on the mesh as the walk left it: what the sampling
    // says there, before any patch changes the triangles round it.
    const std::vector<std::uint8_t> loop_is_border =
        classifyBorderLoops(dt.points,
                            result.triangles,
                            result.border_loops,
                            cells.triangles,
                            parameters.hole_width,
                            parameters.max_hole_edges);
    counts.true_borders = static_cast<std::size_t>(
        std::count(loop_is_border.begin(), loop_is_border.end(), 1));
    std::vector<std::uint8_t> true_border;
    if (counts.true_borders > 0) {
      true_border.assign(dt.points.size(), 0);
      for (std::size_t l = 0; l < loop_is_border.size(); ++l)
        if (loop_is_border[l])
          for (const int v : result.border_loops[l])
            true_border[v] = 1;
    }
    // A vertex is on one loop at most (one fan each), and a true border's loop is
    // never changed: its first vertex tells.
    const auto fillable = [&](const std::vector<int>& loop) {
      return loop.size() <= parameters.max_hole_edges &&
             (true_border.empty() || !true_border[loop[0]]);
    };
    // Each step's holes counted and listed.
    const auto record = [&](const HoleFilling& closed) {
      counts.holes_filled += closed.holes;
      counts.hole_triangles += closed.triangles;
      result.filled_holes.insert(
          result.filled_holes.end(), closed.rims.begin(), closed.rims.end());
    };
    // The loops closed with triangles of their own vertices, weighed by weight.
    const auto patch_loops = [&](HoleWeight weight, double rim_reach) {
      record(fillUndersampledHoles(dt.points,
                                   spacing,
                                   result.triangles,
                                   incidences,
                                   result.border_loops,
                                   parameters.hole_reach,
                                   parameters.max_hole_edges,
                                   true_border,
                                   weight,
                                   rim_reach));
    };
    // What the Delaunay patches leave (loops, points in no triangle) the original
    // Co-cone's triangles may close (fillHolesFromMesh()): a part sampled too
    // coarsely for the flatness test. What those leave, the advancing front's may:
    // the vertex density changing faster than the co-cones follow. Only there, and
    // a few rings around, does either mesh need making.
    // The rings grow through co-cone triangles of the surface round the holes, not
    // through those along the convex hull or across a wide void (an edge of more
    // than FAR_NEIGHBOUR spacings): at a tile's cut those reached over most of the
    // tile (75,000 of 128,000 points for a 1M saddle's tile of 125,000, the
    // advancing front then taking 44 % of its time).
    const auto grow = [&](std::vector<std::uint8_t> region, int rings) {
      for (int ring = 0; ring < rings; ++ring) {
        std::vector<std::uint8_t> grown = region;
        for (const auto& t : cells.triangles)
          if ((region[t.v[0]] || region[t.v[1]] || region[t.v[2]]) &&
              detail::triangleWithinReach(
                  dt.points, spacing, detail::FAR_NEIGHBOUR, t.v))
            grown[t.v[0]] = grown[t.v[1]] = grown[t.v[2]] = 1;
        for (const auto& t : result.triangles)
          if (region[t[0]] || region[t[1]] || region[t[2]])
            grown[t[0]] = grown[t[1]] = grown[t[2]] = 1;
        region = std::move(grown);
      }
      return region;
    };
    // The region's islands for the advancing front (advancingFrontMesh()): its
    // points joined by the triangles grow() follows, numbered in the order of their
    // lowest vertex (the root: the sets keep the lowest).
    const auto islands = [&](const std::vector<std::uint8_t>& region) {
      detail::DisjointSets sets(region.size());
      const auto join = [&](const auto& corners) {
        for (int i = 0; i < 3; ++i)
          if (region[corners[i]] && region[corners[(i + 1) % 3]])
            sets.unite(corners[i], corners[(i + 1) % 3]);
      };
      for (const auto& t : cells.triangles)
        if (detail::triangleWithinReach(dt.points, spacing, detail::FAR_NEIGHBOUR, t.v))
          join(t.v);
      for (const auto& t : result.triangles)
        join(t);
      std::vector<int> island(region.size(), -1);
      int count = 0;
      for (std::size_t v = 0; v < region.size(); ++v)
        if (region[v]) {
          const int root = sets.find(static_cast<int>(v));
          island[v] = root == static_cast<int>(v) ? count++ : island[root];
        }
      return island;
    };
    const auto open_region = [&](int rings, bool free_points, bool with_loops = true) {
      std::vector<std::uint8_t> region(dt.points.size(), free_points ? 1 : 0);
      for (const auto& t : result.triangles)
        for (const int v : t)
          region[v] = 0;
      for (const auto& loop : result.border_loops)
        if (with_loops && fillable(loop))
          for (const int v : loop)
            region[v] = 1;
      if (std::find(region.begin(), region.end(), 1) == region.end())
        return std::vector<std::uint8_t>();
      return grow(std::move(region), rings);
    };
    // The same round the given loops and those samples in no triangle that co-cone
    // triangles join to them, within the rings or through one another (the samples
    // in and round their holes), rather than every such sample of the cloud: on the
    // merged Stanford scans, whose free samples are spread over the whole cloud,
    // the advancing front for the one loop the hole filling leaves took 0.63 s over
    // all of them, 0.13 s over those joined to it.
    const auto loops_region = [&](const std::vector<std::vector<int>>& loops,
                                  int rings) {
      std::vector<std::uint8_t> start(dt.points.size(), 0);
      for (const auto& loop : loops)
        for (const int v : loop)
          start[v] = 1;
      const std::vector<std::uint8_t> near = grow(start, rings);
      const std::vector<std::uint8_t> used =
          usedVertices(result.triangles, dt.points.size());
      const detail::CoconeNeighbours free_around = detail::coconeNeighbours(
          cells.triangles, dt.points.size(), [&](int b) { return !used[b]; });
      std::vector<int> queue;
      for (std::size_t v = 0; v < near.size(); ++v)
        if (near[v] && !used[v]) {
          start[v] = 1;
          queue.push_back(static_cast<int>(v));
        }
      for (std::size_t q = 0; q < queue.size(); ++q)
        for (std::size_t a = free_around.first[queue[q]];
             a < free_around.first[queue[q] + 1];
             ++a)
          if (!start[free_around.neighbour[a]]) {
            start[free_around.neighbour[a]] = 1;
            queue.push_back(free_around.neighbour[a]);
          }
      return grow(std::move(start), rings);
    };
    const auto fill_from = [&](const std::vector<Triangle>& other,
                               std::size_t band_per_edge,
                               bool join_loops) {
      record(fillHolesFromMesh(dt.points,
                               spacing,
                               other,
                               result.triangles,
                               incidences,
                               result.border_loops,
                               parameters.hole_reach,
                               parameters.max_hole_edges,
                               band_per_edge,
                               true_border,
                               join_loops));
    };
    // Holes round samples in no triangle, closed through them (see below).
    const auto fill_through_inner_samples = [&]() {
      record(fillHolesWithInnerSamples(dt.points,
                                       spacing,
                                       cells.triangles,
                                       result.triangles,
                                       incidences,
                                       result.border_loops,
                                       parameters.hole_reach,
                                       parameters.max_hole_edges,
                                       true_border));
    };
    // What is left where the sampling is coarser across the rim than along it
    // (fillUndersampledHoles()): a hole no wider than hole_width rim triangles,
    // patched with edges up to twice that; then long narrow holes, closed by the
    // strip across them. Last, so that a hole with samples in it closes through
    // them rather than over them.
    const auto last_patches = [&]() {
      patch_loops(HoleWeight::DIHEDRAL_ANGLES,
                  RIM_REACH_PER_WIDTH * parameters.hole_width);
      patch_loops(HoleWeight::LEAST_PERIMETER, 0.0);
    };
    // A loop the passes leave open where two sheets meet within the noise runs
    // through a crumpled cluster (trianglesRoundLoop()). Reopened by one to
    // REOPENED_RINGS rings of triangles, the wider hole goes through the passes again
    // (the advancing front through the samples it frees, the inner-samples and the
    // Delaunay patches). The vertices it leaves out go into its nearest triangles
    // (insertLeftOut()), and the result is kept only if each was within
    // REOPENED_REACH local spacings of them (REOPENED_SIGMAS of the noise where wider),
    // and the loop closed without a handle or a piece more, the mesh an oriented
    // manifold.
    const auto reopen_loops = [&]() {
      const std::size_t n = dt.points.size();
      const auto twice_genus = [&](const MeshTopology& mesh, std::size_t loops) {
        return 2 * static_cast<long>(mesh.components) - static_cast<long>(loops) -
               mesh.euler;
      };
      // The loops tried: every one left open; where more are, the REOPENED_LOOPS
      // shortest (a crumpled cluster's loop is short: on FinalBaseMesh with noise
      // 1.5, 48 loops, none of more than 77 edges closed).
      std::vector<std::vector<int>> chosen;
      std::copy_if(result.border_loops.begin(),
                   result.border_loops.end(),
                   std::back_inserter(chosen),
                   fillable);
      if (chosen.empty())
        return false;
      const bool all = chosen.size() <= REOPENED_LOOPS;
      if (!all) {
        std::stable_sort(chosen.begin(),
                         chosen.end(),
                         [](const std::vector<int>& a, const std::vector<int>& b) {
                           return a.size() < b.size();
                         });
        chosen.resize(REOPENED_LOOPS);
      }
      const std::set<std::vector<int>> shortest(chosen.begin(), chosen.end());
      const double reach =
          std::max(REOPENED_REACH, REOPENED_SIGMAS * result.noise_level);
      // One advancing front for every attempt, over the samples in no triangle and
      // the loops' surroundings as far as they are reopened: remade for each, it
      // took 90 % of the time (twenty loops on a noisy FinalBaseMesh: 16 s).
      const std::vector<std::uint8_t> front_region =
          loops_region(chosen, ADVANCING_FRONT_RINGS + REOPENED_RINGS);
      const std::vector<Triangle> front =
          advancingFrontMesh(dt.points, islands(front_region), threads);
      // Its triangles within FRONT_RINGS of a reopened region: the patches' and
      // the bands' (the whole front, matched against every loop, took 60 % of the
      // time).
      const auto front_near = [&](std::vector<std::uint8_t> near) {
        constexpr int FRONT_RINGS = 2;
        for (int ring = 0; ring < FRONT_RINGS; ++ring) {
          std::vector<std::uint8_t> grown = near;
          for (const Triangle& t : front)
            if (near[t[0]] || near[t[1]] || near[t[2]])
              grown[t[0]] = grown[t[1]] = grown[t[2]] = 1;
          near = std::move(grown);
        }
        std::vector<Triangle> local;
        for (const Triangle& t : front)
          if (near[t[0]] || near[t[1]] || near[t[2]])
            local.push_back(t);
        return local;
      };
      std::set<std::vector<int>> tried;
      bool any = false;
      for (bool changed = true; changed; any = any || changed) {
        changed = false;
        const std::vector<std::vector<int>> loops = result.border_loops;
        const MeshTopology before = analyzeMesh(result.triangles, n, incidences);
        const long genus_before = twice_genus(before, loops.size());
        for (std::size_t l = 0; l < loops.size() && !changed; ++l) {
          if (!fillable(loops[l]) || (!all && shortest.count(loops[l]) == 0) ||
              !tried.insert(loops[l]).second)
            continue;
          for (int rings = 1; rings <= REOPENED_RINGS && !changed; ++rings) {
            std::vector<std::uint8_t> region;
            const std::vector<std::uint8_t> drop =
                trianglesRoundLoop(result.triangles, loops[l], rings, n, &region);
            // A true border's loop is never changed (see fillable), nor reopened
            // into another.
            bool reaches_border = false;
            for (std::size_t v = 0; v < true_border.size() && !reaches_border; ++v)
              reaches_border = region[v] && true_border[v];
            if (reaches_border)
              break;
            std::vector<Triangle> kept = result.triangles;
            EdgeIncidences kept_incidences = incidences;
            const ReconstructionCounts kept_counts = counts;
            const std::size_t kept_holes = result.filled_holes.size();
            // What the rings leave is an oriented manifold (trianglesRoundLoop()
            // takes the stars they would pinch), and its incidences those of the
            // mesh less the triangles dropped: neither is made again over the whole
            // mesh per attempt.
            removeTriangles(result.triangles, drop, &incidences);
            // Only the reopened hole goes through the passes again: the other
            // loops went through them as they are (on the range scans, patching
            // them all again for each attempt took a fifth of the time).
            const auto reopened_loops = [&]() {
              auto loops_now = boundaryLoops(incidences, n);
              loops_now.erase(std::remove_if(loops_now.begin(),
                                             loops_now.end(),
                                             [&](const std::vector<int>& loop) {
                                               return !region[loop[0]];
                                             }),
                              loops_now.end());
              return loops_now;
            };
            result.border_loops = reopened_loops();
            fill_from(front_near(region), BAND_PER_LOOP_EDGE, false);
            result.border_loops = reopened_loops();
            fill_through_inner_samples();
            last_patches();
            // The loop must have closed: else the attempt is undone without the
            // insertion and the checks (an inserted vertex changes no border).
            result.border_loops = boundaryLoops(incidences, n);
            if (result.border_loops.size() < loops.size()) {
              const std::size_t patched = result.triangles.size();
              const bool inserted = insertLeftOut(
                  dt.points, spacing, kept, result.triangles, region, reach);
              if (result.triangles.size() != patched) {
                incidences = EdgeIncidences(result.triangles);
                result.border_loops = boundaryLoops(incidences, n);
              }
              const MeshTopology after = analyzeMesh(result.triangles, n, incidences);
              changed = inserted && after.manifold() &&
                        after.components == before.components &&
                        twice_genus(after, result.border_loops.size()) <= genus_before;
            }
            if (!changed) {
              result.triangles = std::move(kept);
              counts = kept_counts;
              result.filled_holes.resize(kept_holes);
              incidences = std::move(kept_incidences);
              result.border_loops = loops;
            }
          }
        }
      }
      return any;
    };
    // First, where samples no triangle uses lie between loops (a tunnel's wall the
    // walk left out, its two rims open), the advancing front's surface through them
    // closes the loops together, before the patches below cap each on its own.
    std::vector<std::uint8_t> region = open_region(ADVANCING_FRONT_RINGS, true, false);
    if (!region.empty())
      fill_from(advancingFrontMesh(dt.points, islands(region), threads),
                BAND_PER_LOOP_EDGE,
                true);
    patch_loops(HoleWeight::DIHEDRAL_ANGLES, 0.0);
    region = open_region(PLAIN_COCONE_RINGS, true);
    if (!region.empty())
      fill_from(plainCoconeMesh(dt.points, cells, region, threads), 0, false);
    region = open_region(ADVANCING_FRONT_RINGS, false);
    if (!region.empty())
      fill_from(advancingFrontMesh(dt.points, islands(region), threads),
                BAND_PER_LOOP_EDGE,
                false);
    // What the walk left between sheets a couple of spacings apart, closed by the
    // patches or not, is no surface: the specks go, with their loops and holes.
    counts.repair.speck =
        dropSpecks(result.triangles, dt.points.size(), MIN_PIECE_VERTICES, &incidences);
    if (counts.repair.speck > 0) {
      result.border_loops = boundaryLoops(incidences, dt.points.size());
      const std::vector<std::uint8_t> used =
          usedVertices(result.triangles, dt.points.size());
      const auto gone =
          std::remove_if(result.filled_holes.begin(),
                         result.filled_holes.end(),
                         [&](const std::vector<int>& rim) { return !used[rim[0]]; });
      counts.holes_filled -= static_cast<std::size_t>(result.filled_holes.end() - gone);
      result.filled_holes.erase(gone, result.filled_holes.end());
    }
    // Holes round samples no mesh made a surface of, closed through them.
    fill_through_inner_samples();
    // Pieces whose holes no patch closes, closed whole by the advancing front.
    record(closePiecesWithAdvancingFront(dt.points,
                                         spacing,
                                         cells.triangles,
                                         result.triangles,
                                         incidences,
                                         result.border_loops,
                                         parameters.hole_reach,
                                         parameters.max_hole_edges,
                                         true_border,
                                         threads));
    last_patches();
    // Tunnels too narrow for any sample round them: the walk's, between sheets
    // within the noise or a couple of spacings apart.
    counts.handles_cut = cutShortHandles(
        dt.points, result.triangles, incidences, MIN_TUNNEL_SAMPLES, threads);
    // Loops left in a crumpled cluster, reopened wider and closed again; the
    // handles their new patches leave, cut as before.
    if (reopen_loops())
      counts.handles_cut += cutShortHandles(
          dt.points, result.triangles, incidences, MIN_TUNNEL_SAMPLES, threads);
    // The borders left through the samples on them.
    counts.repair.peeled =
        peelBorderSlivers(dt.points, result.triangles, incidences, result.border_loops);
  }
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

/** Stage 3 on a triangulation and its first Voronoi pass: the local spacing and the
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
                    Timings& timings)
{
  detail::Stopwatch clock;
  Undersampling out;
  const bool detect = parameters.boundary_detection;
  const bool half_disk = detect && parameters.gap_angle > 0.0;
  if (detect && (parameters.spacing_factor > 0.0 || half_disk))
    out.spacing = localSpacing(dt.points, cells, threads);
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
 * result.error if too few points are left. */
std::unique_ptr<Sample>
handleNoise(Triangulation& dt,
            VoronoiCells& cells,
            const Parameters& parameters,
            Stages stages,
            Result& result,
            int threads)
{
  if (cells.nearest.size() != dt.points.size())
    return nullptr; // no neighbour lists (coplanar points): nothing to read
  const std::vector<std::uint8_t> counted =
      countedVertices(parameters, result.vertex_of_input, result.vertices);
  const NoiseAnalysis noise = analyzeNoise(dt.points, cells.nearest, threads, counted);
  result.noise_level = noise.cloud_level;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  result.point_noise.assign(result.vertex_of_input.size(), nan);
  for (std::size_t i = 0; i < result.vertex_of_input.size(); ++i)
    if (result.vertex_of_input[i] >= 0)
      result.point_noise[i] = noise.level[result.vertex_of_input[i]];
  std::vector<Eigen::Vector3d> smoothed;
  bool undecided = false;
  if (noise.cloud_level > parameters.noise_threshold) {
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
    const bool two_scales =
        parameters.boundary_detection && stages == Stages::RECONSTRUCTION;
    result.smoothed = reduced && kurtosis >= NOISE_KURTOSIS &&
                      !(two_scales && kurtosis > HEAVY_KURTOSIS);
    undecided = reduced && !result.smoothed && kurtosis >= ALIKE_KURTOSIS && two_scales;
  }
  if (!result.smoothed && !undecided && noise.outliers == 0)
    return nullptr; // a clean cloud: the triangulation stands

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
      result.timings);
  clock.lap();
  result.boundary = std::move(undersampling.boundary);
  result.ratio = undersampling.ratio;

  result.umbrella_failed.assign(result.vertices, 0);
  if (stages == Stages::RECONSTRUCTION) {
    reconstruct(
        dt, cells, parameters, undersampling.rim_reach, undersampling.spacing, result);
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
  std::vector<std::uint8_t> resolved = usedVertices(result.triangles, result.vertices);
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
  if (parameters.noise_handling) {
    smoothed = handleNoise(dt, cells, parameters, stages, result, threads);
    if (!result.error.empty())
      return result;
  }
  result.timings.noise = clock.lap();
  if (!smoothed) {
    completeStages(dt, cells, parameters, stages, ids, threads, result);
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
  completeStages(dt, cells, parameters, stages, ids, threads, result);
  const double given_ms = clock.lap();
  completeStages(
      smoothed->dt, smoothed->cells, parameters, stages, ids, threads, alternative);
  const double smoothed_ms = clock.lap();
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
