/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

// The undersampled holes closed, the true borders kept (the paper's open question):
// every border loop the walk leaves classified, then the holes patched with the
// Delaunay triangles of their own vertices, the original Co-cone's and the advancing
// front's triangles, reopened where a patch leaves a crumpled cluster.

#include <pcl/surface/cocone/border_classification.h>
#include <pcl/surface/cocone/handle_removal.h>
#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/hole_reopening.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/repair.h>
#include <pcl/surface/cocone/triangulation.h>

#include "cocone_neighbours.h"
#include "disjoint_sets.h"
#include "points.h"
#include "stages.h"

#include <algorithm>
#include <iterator>
#include <set>
#include <utility>

namespace pcl {
namespace cocone {
namespace detail {

namespace {

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
 * closeUndersampledHoles()). */
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

/** One ring: mark in \a grown the corners of those \a triangles that have one in
 * \a region. */
void
addRing(const std::vector<Triangle>& triangles,
        const std::vector<std::uint8_t>& region,
        std::vector<std::uint8_t>& grown)
{
  for (const auto& t : triangles)
    if (region[t[0]] || region[t[1]] || region[t[2]])
      grown[t[0]] = grown[t[1]] = grown[t[2]] = 1;
}

} // namespace

void
closeUndersampledHoles(const std::vector<Eigen::Vector3d>& points,
                       const VoronoiCells& cells,
                       const Parameters& parameters,
                       const std::vector<double>& spacing,
                       CoconeTrianglesWithinReach& within_reach,
                       EdgeIncidences& incidences,
                       Result& result)
{
  if (!parameters.fill_undersampled_holes || spacing.empty())
    return;
  auto& counts = result.counts;
  const int threads = resolveThreads(parameters.threads);
  // Each loop classified once, on the mesh as the walk left it: what the sampling
  // says there, before any patch changes the triangles round it.
  const std::vector<std::uint8_t> loop_is_border =
      classifyBorderLoops(points,
                          result.triangles,
                          result.border_loops,
                          cells.triangles,
                          parameters.hole_width,
                          parameters.max_hole_edges);
  counts.true_borders = static_cast<std::size_t>(
      std::count(loop_is_border.begin(), loop_is_border.end(), 1));
  std::vector<std::uint8_t> true_border;
  if (counts.true_borders > 0) {
    true_border.assign(points.size(), 0);
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
    record(fillUndersampledHoles(points,
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
  // The rings grow through co-cone triangles within reach (CoconeTrianglesWithinReach):
  // at a tile's cut those across a wide void reached over most of the tile (75,000
  // of 128,000 points for a 1M saddle's tile of 125,000, the advancing front then
  // taking 44 % of its time).
  const auto grow = [&](std::vector<std::uint8_t> region, int rings) {
    const std::vector<std::uint8_t>& reach = within_reach.mask();
    for (int ring = 0; ring < rings; ++ring) {
      std::vector<std::uint8_t> grown = region;
      for (std::size_t i = 0; i < cells.triangles.size(); ++i) {
        const auto& t = cells.triangles[i].v;
        if (reach[i] && (region[t[0]] || region[t[1]] || region[t[2]]))
          grown[t[0]] = grown[t[1]] = grown[t[2]] = 1;
      }
      addRing(result.triangles, region, grown);
      region = std::move(grown);
    }
    return region;
  };
  // The region's islands for the advancing front (advancingFrontMesh()): its
  // points joined by the triangles grow() follows, numbered in the order of their
  // lowest vertex (the root: the sets keep the lowest).
  const auto islands = [&](const std::vector<std::uint8_t>& region) {
    DisjointSets sets(region.size());
    const auto join = [&](const auto& corners) {
      for (int i = 0; i < 3; ++i)
        if (region[corners[i]] && region[corners[(i + 1) % 3]])
          sets.unite(corners[i], corners[(i + 1) % 3]);
    };
    const std::vector<std::uint8_t>& reach = within_reach.mask();
    for (std::size_t i = 0; i < cells.triangles.size(); ++i)
      if (reach[i])
        join(cells.triangles[i].v);
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
    std::vector<std::uint8_t> region(points.size(), free_points ? 1 : 0);
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
  const auto loops_region = [&](const std::vector<std::vector<int>>& loops, int rings) {
    std::vector<std::uint8_t> start(points.size(), 0);
    for (const auto& loop : loops)
      for (const int v : loop)
        start[v] = 1;
    const std::vector<std::uint8_t> near = grow(start, rings);
    const std::vector<std::uint8_t> used =
        usedVertices(result.triangles, points.size());
    const CoconeNeighbours free_around = coconeNeighbours(
        cells.triangles, points.size(), [&](int b) { return !used[b]; });
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
    record(fillHolesFromMesh(points,
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
    record(fillHolesWithInnerSamples(points,
                                     spacing,
                                     cells.triangles,
                                     result.triangles,
                                     incidences,
                                     result.border_loops,
                                     parameters.hole_reach,
                                     parameters.max_hole_edges,
                                     true_border,
                                     result.noise_level));
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
    const std::size_t n = points.size();
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
    const double reach = std::max(REOPENED_REACH, REOPENED_SIGMAS * result.noise_level);
    // One advancing front for every attempt, over the samples in no triangle and
    // the loops' surroundings as far as they are reopened: remade for each, it
    // took 90 % of the time (twenty loops on a noisy FinalBaseMesh: 16 s).
    const std::vector<std::uint8_t> front_region =
        loops_region(chosen, ADVANCING_FRONT_RINGS + REOPENED_RINGS);
    const std::vector<Triangle> front =
        advancingFrontMesh(points, islands(front_region), threads);
    // Its triangles within FRONT_RINGS of a reopened region: the patches' and
    // the bands' (the whole front, matched against every loop, took 60 % of the
    // time).
    const auto front_near = [&](std::vector<std::uint8_t> near) {
      constexpr int FRONT_RINGS = 2;
      for (int ring = 0; ring < FRONT_RINGS; ++ring) {
        std::vector<std::uint8_t> grown = near;
        addRing(front, near, grown);
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
            const bool inserted =
                insertLeftOut(points, spacing, kept, result.triangles, region, reach);
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
    fill_from(
        advancingFrontMesh(points, islands(region), threads), BAND_PER_LOOP_EDGE, true);
  patch_loops(HoleWeight::DIHEDRAL_ANGLES, 0.0);
  region = open_region(PLAIN_COCONE_RINGS, true);
  if (!region.empty())
    fill_from(plainCoconeMesh(points, cells, region, threads), 0, false);
  region = open_region(ADVANCING_FRONT_RINGS, false);
  if (!region.empty())
    fill_from(advancingFrontMesh(points, islands(region), threads),
              BAND_PER_LOOP_EDGE,
              false);
  // Pieces dropped (\a dropped triangles) go with their loops and holes.
  const auto forget_dropped = [&](std::size_t dropped) {
    counts.repair.speck += dropped;
    if (dropped == 0)
      return;
    result.border_loops = boundaryLoops(incidences, points.size());
    const std::vector<std::uint8_t> used =
        usedVertices(result.triangles, points.size());
    const auto gone =
        std::remove_if(result.filled_holes.begin(),
                       result.filled_holes.end(),
                       [&](const std::vector<int>& rim) { return !used[rim[0]]; });
    counts.holes_filled -= static_cast<std::size_t>(result.filled_holes.end() - gone);
    result.filled_holes.erase(gone, result.filled_holes.end());
  };
  // What the walk left between sheets a couple of spacings apart, closed by the
  // patches or not, is no surface: the specks go.
  forget_dropped(
      dropSpecks(result.triangles, points.size(), MIN_PIECE_VERTICES, &incidences));
  // Holes round samples no mesh made a surface of, closed through them.
  fill_through_inner_samples();
  // Pieces whose holes no patch closes, closed whole by the advancing front.
  record(closePiecesWithAdvancingFront(points,
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
      points, result.triangles, incidences, MIN_TUNNEL_SAMPLES, threads);
  // Loops left in a crumpled cluster, reopened wider and closed again; the
  // handles their new patches leave, cut as before.
  if (reopen_loops())
    counts.handles_cut += cutShortHandles(
        points, result.triangles, incidences, MIN_TUNNEL_SAMPLES, threads);
  // Necks too narrow for any sample round them: where the walk joined two bodies
  // that touch, across sheets closer than the spacing, and the holes round the
  // join were closed. Searched from the filled holes' rims and the ring round
  // them (on the touching spheres the neck's cycle runs through a rim).
  if (!result.filled_holes.empty()) {
    std::vector<std::uint8_t> rim(points.size(), 0);
    for (const auto& loop : result.filled_holes)
      for (const int v : loop)
        rim[v] = 1;
    std::vector<std::uint8_t> near = rim;
    addRing(result.triangles, rim, near);
    std::vector<int> seeds;
    for (std::size_t v = 0; v < near.size(); ++v)
      if (near[v])
        seeds.push_back(static_cast<int>(v));
    counts.necks_cut =
        cutShortNecks(points, result.triangles, incidences, seeds, MIN_TUNNEL_SAMPLES);
  }
  // The layers between two surfaces closer than the spacing, which the patches and
  // cuts have left apart from both.
  forget_dropped(dropLayers(points, spacing, result.triangles, &incidences));
  // The borders left through the samples on them.
  counts.repair.peeled =
      peelBorderSlivers(points, result.triangles, incidences, result.border_loops);
}

} // namespace detail
} // namespace cocone
} // namespace pcl
