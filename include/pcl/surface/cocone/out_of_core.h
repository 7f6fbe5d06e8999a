/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/tiling.h>

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief The most points runOutOfCore() makes the cut on by default (96 MB of
 * positions): the cut is runTiled()'s for clouds of up to this many finite points. */
constexpr std::size_t OUT_OF_CORE_SAMPLE_POINTS = std::size_t{1} << 22;

/** \brief Memory of an out-of-core run per point of the cloud, besides its tiles in
 * flight, at most, in bytes: per point its tile, its vertex and its noise level, per
 * vertex its ring of the seams, the boundary and outlier lists (24 measured as
 * ONE_PIECE_BYTES_PER_POINT, on top of the tiles). */
constexpr std::size_t OUT_OF_CORE_BYTES_PER_POINT = 24;

/** \brief The tiling of runOutOfCore() for a cloud of \a points within \a memory
 * bytes: as many tiles in flight as \a threads (0: one per processor), each the
 * largest, rounded down as automaticTilePoints() rounds, that fits beside
 * OUT_OF_CORE_BYTES_PER_POINT per point; one tile in flight if not even
 * MINIMUM_TILE_POINTS fit so (\a fits is then false when one does not fit either).
 * \a memory 0 (unknown): tiles of a million points. */
TilingOptions
automaticOutOfCoreTiling(std::size_t points,
                         std::size_t memory,
                         unsigned int threads,
                         bool* fits = nullptr);

/** \brief A cloud read in passes, in chunks: a file streamed from disk.
 *
 * runOutOfCore() reads it twice from the start; the points must be the same, in the
 * same order, on each pass. */
class PointSource {
public:
  virtual ~PointSource() = default;

  /** Start a pass at the first point. False, with \a error, on failure. */
  virtual bool
  rewind(std::string& error) = 0;

  /** The next points of the pass, at most \a max (at least one unless the pass is at
   * its end: \a chunk is then empty). False, with \a error, on failure. */
  virtual bool
  read(std::vector<Eigen::Vector3d>& chunk, std::size_t max, std::string& error) = 0;
};

/** \brief Where runOutOfCore() writes the stitched mesh, in one pass: the counts,
 * then every vertex in order, then every triangle. */
class MeshSink {
public:
  virtual ~MeshSink() = default;

  /** The counts, before anything else. */
  virtual bool
  begin(std::size_t vertices, std::size_t triangles, std::string& error) = 0;

  /** The next vertices, numbered on from the last: positions in the caller's frame,
   * normals (NaN where a vertex has none) and the id of each vertex's representative
   * (the lowest id of the points at its position). */
  virtual bool
  addVertices(const std::vector<Eigen::Vector3d>& positions,
              const std::vector<Eigen::Vector3d>& normals,
              const std::vector<int>& ids,
              std::string& error) = 0;

  /** The next triangles, over the vertices' numbers, oriented. */
  virtual bool
  addTriangles(const std::vector<Triangle>& triangles, std::string& error) = 0;

  /** After the last triangle. */
  virtual bool
  end(std::string& error) = 0;
};

/** \brief What runOutOfCore() gives besides the mesh written to its MeshSink.
 *
 * Ids are positions in the source (0 is the first point read). */
struct OutOfCoreResult {
  /** Empty on success; otherwise why there is no (complete) mesh. */
  std::string error;
  /** Points read. */
  std::size_t points = 0;
  /** Of those, finite. */
  std::size_t finite = 0;
  /** Vertices written. */
  std::size_t vertices = 0;
  /** Triangles written. */
  std::size_t triangles = 0;
  /** The mesh's Euler characteristic V - E + F (V: the vertices in a triangle). */
  long euler = 0;
  /** The mesh's components: pieces of triangles joined through edges (a piece the
   * stitch's repair cut in two at a seam still counts once). */
  std::size_t components = 0;
  /** The mesh's border loops over ids (each starting at its lowest id). */
  std::vector<std::vector<int>> border_loops;
  /** Ids labelled boundary (as Result::boundary_indices), ascending. */
  std::vector<int> boundary_indices;
  /** Ids of the outliers, ascending. */
  std::vector<int> outlier_indices;
  /** Undersampled holes the tiles closed (each counted once). */
  std::size_t holes_filled = 0;
  /** The median of the tiles' ratios. */
  double ratio = 0.0;
  /** The cloud's noise level: the median over the points (Result::noise_level). */
  double noise_level = 0.0;
  /** Whether any tile smoothed its points. */
  bool smoothed = false;
  /** The tiles' counts, summed. */
  ReconstructionCounts counts;
  /** What the tiling did (point_tile and triangle_tile are left empty). */
  TilingReport tiling;
  /** The most bytes the work directory held (measured after the cut and when the
   * stitch has read the tiles' results: about 33 and 100 bytes per point). */
  std::size_t disk_bytes = 0;
};

/** \brief Reconstruct a cloud larger than the memory, tile by tile through files:
 * the mesh of runTiled(), with memory bounded by the tile rather than the cloud.
 *
 * Passes: (1) the source is read once for its size and an even sample of at most
 * \a sample_points finite points, on which the median splits of runTiled() are made (on
 * all the points when they are that few: the tiles are then runTiled()'s); (2) the
 * source is read again and each finite point written to its tile's file; each tile's
 * halo (runTiled()'s rule, on the core's own spacing) is then gathered from the cores'
 * files; (3) the tiles are reconstructed, TilingOptions::tiles_in_flight at a time,
 * each result written to a file; (4) the stitch reads the results tile by tile: the
 * triangles within two rings of the seams (those at a vertex of a triangle with
 * vertices in two cores, and the triangles at their vertices) are stitched in memory
 * as runTiled() stitches the whole (patches turned to agree, repairManifold(), the
 * seam holes closed); every other triangle is its tile's, turned with its patch, and
 * each component faces outward (signed volume about its centroid, summed per patch);
 * (5) the vertices, tile after tile, and the triangles go to \a sink.
 *
 * Memory: one tile in flight (ONE_PIECE_BYTES_PER_POINT per point of core and
 * halo) per TilingOptions::tiles_in_flight, the stitch's band, and
 * OUT_OF_CORE_BYTES_PER_POINT. Disk: about 100 bytes per point in \a directory (the
 * tiles' results), removed on return.
 *
 * What differs from runTiled() on the same tiles: the vertices are numbered tile
 * after tile (core order), not in input order, and the triangles come in that order;
 * a repair at the seams whose effects reach beyond the band's second ring is cut
 * there (measured in the tests: the triangles are the same).
 *
 * \param[in] source the cloud
 * \param[in] parameters the parameters of every tile's run() (refine_filled_holes is
 *            not available: an error)
 * \param[in] tiling tile_points must be at least MINIMUM_TILE_POINTS
 * \param[in] directory an existing directory for the work files
 * \param[in] sink where the mesh goes
 * \param[in] sample_points the most points the cut is made on (at least 1000):
 *            above, an even sample of sample_points / 2 to sample_points
 */
OutOfCoreResult
runOutOfCore(PointSource& source,
             const Parameters& parameters,
             const TilingOptions& tiling,
             const std::string& directory,
             MeshSink& sink,
             std::size_t sample_points = OUT_OF_CORE_SAMPLE_POINTS);

} // namespace cocone
} // namespace pcl
