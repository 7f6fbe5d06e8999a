/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/repair.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief The smallest core runTiled() accepts: below, a tile's own statistics (the
 * automatic ratio, the median gap of the half-disk test, the noise level) and its
 * spacing are read off too few points. */
constexpr std::size_t MINIMUM_TILE_POINTS = 1000;

/** \brief Peak memory of a one-piece reconstruction per input point, at most, in
 * bytes. Measured with the command-line tool, one thread: random samples of 1M to 4M
 * points need 700 (monkey saddle, torus with noise of 0.5 spacings) to 1,140 bytes
 * (the clean 1M torus, whose triangulation has 14 cells per point against 6 to 8);
 * the library alone about 130 bytes less. */
constexpr std::size_t ONE_PIECE_BYTES_PER_POINT = 1300;
/** \brief Peak memory of a tiled reconstruction per input point besides its tiles,
 * at most, in bytes: the cloud, the tiles' results and the stitched mesh (measured as
 * ONE_PIECE_BYTES_PER_POINT: 410 to 500). A tile in flight needs
 * ONE_PIECE_BYTES_PER_POINT for each of its points, core and halo. */
constexpr std::size_t TILED_BYTES_PER_POINT = 550;

/** \brief The memory this process can reach at its peak, in bytes: what it holds
 * now (its resident set) plus what the system has available (MemAvailable in
 * /proc/meminfo; otherwise the physical memory), the latter bounded by what the
 * process' control group may still take (cgroup v2 memory.max or v1
 * memory.limit_in_bytes, less its use). 0 if none of these can be read. */
std::size_t
availableMemory();

/** \brief The tile size for a cloud of \a points to be reconstructed within
 * \a memory bytes: 0 (one piece) when a one-piece run fits (ONE_PIECE_BYTES_PER_POINT
 * per point), else the largest core that lets one tile, with a halo of a quarter of
 * its core, run beside the stitch's TILED_BYTES_PER_POINT per point, rounded down to
 * the series 1, 1.25, 1.6, 2, 2.5, 3.2, 4, 5, 6.3, 8 times a power of ten (a little
 * more or less memory free gives the same tiles, so the same mesh); at least
 * MINIMUM_TILE_POINTS (when not even that fits, the run will likely run out of memory:
 * the result is then MINIMUM_TILE_POINTS, and \a fits is set false). Independent of
 * the threads, so that the mesh is too; automaticTilesInFlight() says how many such
 * tiles fit at once.
 *
 * \param[in] points the number of points
 * \param[in] memory the memory to plan for, in bytes (availableMemory()); 0: unknown,
 *            one piece
 * \param[out] fits if given, whether the plan fits \a memory
 */
std::size_t
automaticTilePoints(std::size_t points, std::size_t memory, bool* fits = nullptr);

/** \brief How many tiles of \a tile_points (automaticTilePoints()) fit in \a memory
 * at once beside the stitch, at most \a threads and at least 1. */
unsigned int
automaticTilesInFlight(std::size_t points,
                       std::size_t memory,
                       std::size_t tile_points,
                       unsigned int threads);

/** \brief How runTiled() cuts a cloud into tiles (independent of Parameters). */
struct TilingOptions {
  /** At most this many points in the core of a tile; 0, or at least the number of
   * finite points: one piece (run()). Otherwise at least MINIMUM_TILE_POINTS. */
  std::size_t tile_points = 0;
  /** Width of the halo in local spacings s, s the median nearest-neighbour distance
   * of the core's points. Measured against one piece (random samples, 50,000
   * points, 16 tiles): the labels of the points near the seams agree from 4 (torus,
   * sphere with holes) to 6 (monkey saddle, the torus with noise of 0.3 spacings)
   * on; the triangles of a core are then those of a one-piece run, except near
   * the sampled surface's border (see runTiled()). The default doubles the largest.
   */
  double halo_spacings = 8.0;
  /** Tiles reconstructed at the same time; 0: one per thread of
   * Parameters::threads. Peak memory grows with it (each holds one tile's
   * triangulation); the output does not depend on it. */
  unsigned int tiles_in_flight = 0;
};

/** \brief The tiling for a cloud of \a points within \a memory bytes:
 * automaticTilePoints(), and as many tiles at once as automaticTilesInFlight() fits
 * with \a threads threads (0: one per processor); one piece: the default options.
 * What the command-line tool's and the Python bindings' tile_points "auto" use.
 * \param[out] fits if given, whether the plan fits \a memory */
TilingOptions
automaticTiling(std::size_t points,
                std::size_t memory,
                unsigned int threads,
                bool* fits = nullptr);

/** \brief What runTiled() did, beyond the Result. */
struct TilingReport {
  /** Number of tiles (1: one piece). */
  std::size_t tiles = 0;
  /** Halo points summed over the tiles. */
  std::size_t halo_points = 0;
  /** The most points (core and halo) one tile was reconstructed from. */
  std::size_t largest_tile = 0;
  /** Per point passed to runTiled(): the tile whose core holds it; -1 if it is not
   * finite. */
  std::vector<int> point_tile;
  /** Per triangle of Result::polygons: the tile that kept it; -1 for a triangle the
   * stitch added to close a seam hole. */
  std::vector<int> triangle_tile;
  /** Patches: connected pieces of the triangles one tile kept. */
  std::size_t patches = 0;
  /** Patches turned over to agree with their neighbours across the seams. */
  std::size_t patches_flipped = 0;
  /** Kept triangles left out because a vertex of theirs is an outlier in the tile
   * that owns that vertex. */
  std::size_t seam_dropped = 0;
  /** What the repair of the stitched mesh changed (at the seams). */
  RepairCounts stitch;
  /** Triangles added to close seam holes: from the tiles' own meshes, or a hole's
   * own triangle. */
  std::size_t seam_filled = 0;
  /** Wall-clock time of cutting the cloud into tiles and finding their halos
   * (planTiles()), in milliseconds. */
  double cut_ms = 0.0;
  /** Wall-clock time of reconstructing the tiles, in milliseconds. */
  double tiles_ms = 0.0;
  /** Wall-clock time of the stitch, in milliseconds. */
  double stitch_ms = 0.0;
  /** Tiles whose points are degenerate (fewer than 4 distinct, or collinear): their
   * core points are labelled undersampled and are in no triangle. */
  std::size_t degenerate_tiles = 0;
};

/** \brief How a cloud is cut into tiles: the first phase of runTiled().
 *
 * Plain data: the cores and halos are positions in the planned points, so that the
 * tiles can be handed to other threads or processes (reconstructTile()) and their
 * results brought back to stitchTiles(). */
struct TilePlan {
  /** Why there is no plan (bad options or ids); empty if there is one. */
  std::string error;
  /** The cloud fits one tile (TilingOptions::tile_points is 0 or at least the number
   * of finite points): runTiled() then calls run() on the whole. The plan is still
   * one of one tile without a halo, but the phases below would give the stitch of
   * that tile, not necessarily run()'s result. */
  bool one_piece = false;
  /** Number of points planned (finite or not). */
  std::size_t points = 0;
  /** The finite points' positions, core after core: tile t's core is
   * order[core_begin[t]] to order[core_begin[t + 1] - 1]. */
  std::vector<int> order;
  /** Where each core starts in \a order; one more entry than there are tiles. */
  std::vector<std::size_t> core_begin;
  /** Per tile, the positions of its halo points (in other tiles' cores), in the order
   * of the tiles. */
  std::vector<std::vector<int>> halo;
  /** Per point, the tile whose core holds it; -1 if it is not finite. */
  std::vector<int> point_tile;
  /** The centre of the finite points' box: the Result's offset. */
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  /** Wall-clock time of the plan, in milliseconds. */
  double cut_ms = 0.0;

  /** Number of tiles. */
  std::size_t
  tiles() const
  {
    return core_begin.empty() ? 0 : core_begin.size() - 1;
  }

  /** Number of points in the core of \a tile. */
  std::size_t
  coreSize(std::size_t tile) const
  {
    return core_begin[tile + 1] - core_begin[tile];
  }

  /** The positions of \a tile's points, its core first, then its halo: the points
   * reconstructTile() takes, in that order. */
  std::vector<int>
  tilePoints(std::size_t tile) const;
};

/** \brief What one tile leaves for stitchTiles(): the labels of its core, the
 * triangles it keeps and the others of its mesh.
 *
 * Plain vectors over the caller's ids (no pointers into the cloud), so that it can be
 * made in another process and sent back. The per-core-point fields follow the order
 * of the core in the TilePlan. */
struct TileResult {
  /** A failure that fails the run (no memory, no thread, bad input); empty if none. */
  std::string error;
  /** Why the tile's points give no mesh (run()'s error); empty if they do. Such a
   * tile does not fail the run: its core points are labelled undersampled. */
  std::string degenerate;
  /** The points the tile was reconstructed from (core and halo). */
  std::size_t points = 0;
  /** Per core point: the caller id of its vertex's representative, -2 for an
   * outlier. */
  std::vector<int> representative;
  /** Per core point: bit 0 boundary, bit 1 umbrella failure. */
  std::vector<std::uint8_t> flags;
  /** Per core point its noise level; empty without noise handling. */
  std::vector<float> noise;
  /** Per core point that represents its vertex, in the order of the core: the
   * position, in the caller's frame. */
  std::vector<Eigen::Vector3d> position;
  /** The normal of each vertex of \a position (NaN in a degenerate tile). */
  std::vector<Eigen::Vector3d> normal;
  /** The triangles the tile keeps (the ownership rule, see runTiled()), oriented,
   * over caller ids. */
  std::vector<Triangle> kept;
  /** The tile's other triangles, each with its ids ascending: they may close a seam
   * hole where the tiles that own them disagree. */
  std::vector<Triangle> seen;
  /** The undersampled holes the tile closed with a rim point in its core, as
   * Result::filled_holes (the stitch lists each hole once). */
  std::vector<std::vector<int>> filled_holes;
  /** The ratio the tile used. */
  double ratio = 0.0;
  /** The tile's noise level after smoothing; 0 if it did not try. */
  double noise_after_smoothing = 0.0;
  /** Whether the tile smoothed its points. */
  bool smoothed = false;
  /** The tile's counts (halo included). */
  ReconstructionCounts counts;
  /** The tile's timings (halo included). */
  Timings timings;
};

/** \brief Cut \a points into tiles with their halos: the first phase of runTiled().
 *
 * See runTiled() for the cut and the halo. The halos are found with up to
 * Parameters::threads threads; nothing else of \a parameters is used.
 *
 * \param[in] points the points; non-finite points and duplicates are allowed
 * \param[in] parameters the threads to use
 * \param[in] tiling how to cut the cloud
 * \param[in] ids the caller's id of each point, distinct; empty: the position in
 *            \a points (checked here, so that a bad list fails before any work)
 * \return the plan, or one with TilePlan::error set
 */
TilePlan
planTiles(const std::vector<Eigen::Vector3d>& points,
          const Parameters& parameters,
          const TilingOptions& tiling,
          const std::vector<int>& ids = {});

/** \brief Reconstruct one tile of a plan: the second phase of runTiled().
 *
 * Gathers the tile's points (TilePlan::tilePoints()) and their ids and calls the
 * overload below. Tiles are independent: any number may run at once, in any order.
 *
 * \param[in] plan the plan of \a points
 * \param[in] tile the tile, below plan.tiles()
 * \param[in] points the points the plan was made of
 * \param[in] parameters the parameters of the tile's run()
 * \param[in] ids the caller's ids the plan was made with
 */
TileResult
reconstructTile(const TilePlan& plan,
                std::size_t tile,
                const std::vector<Eigen::Vector3d>& points,
                const Parameters& parameters,
                const std::vector<int>& ids = {});

/** \brief Reconstruct one tile from its own points, which is all a remote worker
 * needs: run() on the points, then the labels of the core and the triangles the tile
 * keeps.
 *
 * The result depends only on the arguments (not on Parameters::threads, nor on where
 * or how often it runs). Never throws: a failure is TileResult::error.
 *
 * \param[in] points the tile's points, its core first (TilePlan::tilePoints())
 * \param[in] ids their caller ids, distinct, as many as \a points
 * \param[in] core_points how many of \a points are the core
 * \param[in] parameters the parameters of the tile's run()
 */
TileResult
reconstructTile(std::vector<Eigen::Vector3d> points,
                const std::vector<int>& ids,
                std::size_t core_points,
                const Parameters& parameters);

/** \brief Stitch the tiles' results into one mesh: the last phase of runTiled().
 *
 * With the results of every tile of \a plan (in the order of the tiles, each made
 * from the points and ids of the plan with the same parameters), the Result is that
 * of runTiled() for a plan of more than one tile, whatever made the results. Taken
 * by value, so that the caller can move them in and the stitch free them as it goes.
 *
 * \param[in] plan the plan
 * \param[in] results one per tile, in the order of the tiles
 * \param[in] parameters the parameters of the tiles (noise handling, threads)
 * \param[in] ids the caller's ids the plan was made with
 * \param[out] report if given, what the tiling did (all but tiles_ms, which the
 *             caller measures)
 * \return the stitched mesh; Result::error if a tile failed, the results do not fit
 *         the plan, or no tile has a mesh
 */
Result
stitchTiles(TilePlan plan,
            std::vector<TileResult> results,
            const Parameters& parameters,
            const std::vector<int>& ids = {},
            TilingReport* report = nullptr);

/** \brief Reconstruct tile by tile: the result of run() for a cloud too large for
 * one triangulation.
 *
 * The finite points are cut into tiles by recursive median splits along the longest
 * axis of the points' box (exact duplicates stay together), so that each core holds
 * at most TilingOptions::tile_points points and every point is in exactly one core,
 * in the order of the points (runOutOfCore() cuts the same way, from files). A tile
 * is its core plus the halo: the other points within TilingOptions::
 * halo_spacings local spacings of the core's box. run() reconstructs each tile on
 * its own, with the caller's ids. The three phases are planTiles(), reconstructTile()
 * per tile and stitchTiles(); runTiled() is them, in one process.
 *
 * Ownership rule: a triangle is kept by exactly one tile, the one whose core holds
 * the triangle's vertex with the smallest caller id (the vertex's representative,
 * Result::representative); the tiles' cores partition the points, so a triangle
 * found by several tiles is kept once. A point's labels (boundary, outlier, noise
 * level, normal, position) come from the tile whose core holds it.
 *
 * Stitching: the kept triangles are joined; each tile's kept triangles form patches
 * whose orientation is turned over where the edges shared with the neighbouring
 * patches say so (the agreement of most shared edges, strongest pairs first); the
 * union is then made an oriented 2-manifold by repairManifold() (where tiles
 * disagree at a seam an edge may have three triangles or a vertex two fans), small
 * seam holes are closed with triangles of the tiles' own meshes (fillHoles()), and a
 * seam hole of three edges by its own triangle when its vertices lie in two cores or
 * more or its edges' triangles come from two tiles or more, each component faces
 * outward, and the border loops are those of the whole mesh.
 *
 * The Result's fields read as those of run(): polygons, border_loops,
 * boundary_indices, outlier_indices and point_noise over the caller's ids,
 * vertex_of_input for every point (-1 not finite, -2 outlier). The vertices are
 * numbered in the order of their representatives' positions in \a points (loops
 * start at their lowest vertex so numbered, triangles are sorted by it); positions
 * are relative to offset, the centre of the finite points' box. normals are
 * recomputed against the stitched mesh as run() does. ratio is the median over the
 * tiles of the ratio each used, noise_level the median of point_noise,
 * noise_after_smoothing the median over the tiles that tried, smoothed is set if
 * any tile smoothed; counts and timings are summed over the tiles (their halos
 * included), and the stitch is added to timings.reconstruction.
 *
 * What can still differ from run(), measured on random samples with the default halo (8
 * tiles of a million points; 16 tiles of 30,000 in the tests). The walk chooses the
 * side of flat tetrahedra by the points alone (see walk()), so the interior of a tile
 * is triangulated as in one piece (1M random torus: no triangle differs; before, 0.3
 * %). A tile reads the automatic ratio, the median gap of the half-disk test and the
 * noise level from its core alone (Parameters::statistics_points), not its halo; these
 * are the figures of its region, not of the cloud: on a 250,000-point monkey saddle the
 * tiles' gap angles ranged from 161 to 177 degrees against 156 in one piece, which
 * moves the labels of border points (whose gaps are near a half turn) but hardly the
 * triangles. The cloud's own figures would need every tile's cells before any tile
 * labels its points (a second pass over the tiles). The triangles differ at the sampled
 * surface's border: 1M random monkey saddle 0.022 % of the triangles (0.28 % before;
 * 10M 0.0093 %, 0.072 % before), 434 of the 442 within 0.005 of its border (the square
 * is 2 wide). On the 250,000 points in 8 tiles, 198 triangles differ; 150 with a halo
 * of 32 spacings, 167 with the half-disk test off, 192 with the one-piece gap angle
 * forced on every tile: neither the halo nor the statistics are most of what is left,
 * whose cause is not yet known. A border loop that runs out of a tile's halo is not
 * closed as an undersampled hole by either tile. The topology (Euler characteristic,
 * components, border loops) is that of one piece on the torus and the saddle, not
 * where tiles are small against the features: a 1M terrain with steep walls in 8
 * tiles of 125,000 points has 20 loops against 9 (a wall one tile's ratio reads as
 * undersampled; with the ratio given, 16: the 7 extra loops each cross a cut, holes
 * the one piece closes that run out of both tiles' halos).
 *
 * The output does not depend on the number of threads or tiles in flight. A tile
 * that fails for lack of memory fails the run (Result::error); a degenerate tile
 * does not (TilingReport::degenerate_tiles).
 *
 * \param[in] points the points; non-finite points and duplicates are allowed
 * \param[in] parameters the parameters of every tile's run(); threads are shared
 *            among the tiles in flight
 * \param[in] tiling how to cut the cloud
 * \param[in] ids the caller's id of each point, distinct; empty: the position in
 *            \a points
 * \param[out] report if given, what the tiling did
 */
Result
runTiled(std::vector<Eigen::Vector3d> points,
         const Parameters& parameters,
         const TilingOptions& tiling,
         const std::vector<int>& ids = {},
         TilingReport* report = nullptr);

} // namespace cocone
} // namespace pcl
