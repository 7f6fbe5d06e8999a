/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/tiling.h>
#include <pcl/surface/reconstruction.h>
#include <pcl/memory.h>
#include <pcl/PointIndices.h>
#include <pcl/Vertices.h>

#include <string>
#include <vector>

namespace pcl {

/** \brief Surface reconstruction that detects undersampling: the boundary-aware
 * Co-cone of Dey & Giesen, "Detecting undersampling in surface reconstruction"
 * (SoCG 2001).
 *
 * The Voronoi cell of a sample well inside a densely sampled surface is long and
 * thin along the surface normal ("flat"); at open borders, holes and sharp
 * features it is not. The class labels every point from the Delaunay
 * triangulation alone, with no normals and no neighbourhood size:
 *  - a point is flat when rho * width <= height of its Voronoi cell (ratio
 *    condition) and its pole line agrees within theta with the pole lines of the
 *    points that have it as a co-cone neighbour (normal condition);
 *  - the interior set grows from the flat points to a fixed point; the rest are
 *    the boundary (undersampled) points;
 *  - beyond the paper (defaults, see setSpacingFactor() and setGapAngle()): a flat
 *    cell is also at most a few local spacings wide, and a point whose neighbours
 *    lie on one side only (a half disk) is a rim point, reported with the boundary.
 *
 * The reconstruction (reconstruct()) is the Co-cone algorithm in which only interior
 * points choose triangles: candidate triangles whose dual Voronoi edges meet the
 * co-cones of their interior vertices, an umbrella check, pruning of sharp edges
 * that never touches a boundary point, and a walk over the outside of the
 * candidates in every connected component. Holes and open borders stay open. The
 * walk's defects next to boundary points are repaired locally (see
 * getReconstructionCounts()), so the output is always an oriented 2-manifold with
 * boundary, closed components facing outward.
 *
 * \code
 * pcl::CoConeBoundary<pcl::PointXYZ> cocone;
 * cocone.setInputCloud (cloud);
 * pcl::PolygonMesh mesh;
 * cocone.reconstruct (mesh);
 * pcl::PointIndices boundary;
 * cocone.getBoundaryPointIndices (boundary);
 * \endcode
 *
 * Noise and outliers (see setNoiseHandling(), on by default): the points that lie
 * off the surface their neighbours sample are set aside as outliers
 * (getOutlierIndices()) and are in no triangle; when the cloud is noisy
 * (getNoiseLevel(), about the noise sigma in sample spacings) every decision is
 * taken on a smoothed copy of the points (isSmoothed(), getSmoothedCloud()), while
 * the mesh still indexes the input cloud. A clean cloud without outliers gives the
 * same result as without noise handling.
 *
 * Non-finite points are skipped and exact duplicates share one Delaunay vertex;
 * every index this class returns refers to the input cloud, also with setIndices().
 * The mesh's cloud is the whole input cloud with all its fields. Every input index
 * is either in the mesh, an outlier, non-finite, or undersampled or otherwise left
 * out of the mesh (or not among the indices set); duplicates share their vertex,
 * its triangles and its labels.
 *
 * \ingroup surface
 */
template <typename PointInT>
class CoConeBoundary : public SurfaceReconstruction<PointInT> {
public:
  /** \brief Shared pointer to the class. */
  using Ptr = shared_ptr<CoConeBoundary<PointInT>>;
  /** \brief Shared pointer to a const instance. */
  using ConstPtr = shared_ptr<const CoConeBoundary<PointInT>>;

  /** \brief Constructor: the automatic ratio with the spacing test, theta = pi / 6,
   * co-cone angle 3 pi / 8. */
  CoConeBoundary();

  /** \brief Set the ratio rho of the flatness test rho * width <= height.
   *
   * Larger values mark more points as undersampled. The paper uses 1.5 on every data
   * set and reports that 1.1-1.7 work; theory asks for 1 / (1.3 epsilon) on an
   * epsilon-sample, so no fixed value suits every cloud: a hole whose radius is
   * smaller than about the local feature size divided by rho passes as well sampled.
   * With 0 (the default) rho is chosen from the cloud as
   * clamp(1 / (2 Q95(w / h)), 0.5, 4), Q95 the 95th percentile of width / height
   * over the points; getUsedRatio() tells the value of the last run.
   * setRatio (1.5) with setSpacingFactor (0) and setGapAngle (0) is the paper's test
   * exactly.
   * \param[in] ratio rho, finite and > 0, or 0 for automatic (default 0)
   */
  void
  setRatio(double ratio);

  /** \brief Get the ratio setting (0 = automatic). */
  double
  getRatio() const
  {
    return parameters_.ratio;
  }

  /** \brief The ratio rho used by the last run. */
  double
  getUsedRatio() const
  {
    return result_.ratio;
  }

  /** \brief Set the spacing factor a: a flat point's Voronoi cell also has
   * width <= a * s_p, s_p the local sample spacing (the mean distance to the 6
   * nearest Delaunay neighbours, maximised over the point and those neighbours).
   *
   * Interior cells are about one spacing wide (w / s <= 1.3 measured, whatever the
   * noise or scale), border cells reach out 3 or more: the test finds the borders of
   * nearly flat sheets and small holes that the scale-free ratio test passes.
   * \param[in] factor a >= 0; 0 turns the test off (default 3)
   */
  void
  setSpacingFactor(double factor);

  /** \brief Get the spacing factor (0 = off). */
  double
  getSpacingFactor() const
  {
    return parameters_.spacing_factor;
  }

  /** \brief Set the gap angle of the half-disk test.
   *
   * A point on a border has its surface neighbours on one side: seen along its pole
   * line, its neighbours within 1.75 local spacings leave an angular gap larger than
   * this, and so do those of two of its neighbours (a border is a curve). Such a rim
   * point is reported as a boundary point even when its Voronoi cell is flat, as
   * where a scanner grazes the surface or across a slit a few spacings wide; it
   * chooses only triangles without an interior vertex, within one spacing.
   * \param[in] angle in radians, in [0, pi); 0 turns the test off (default 80 degrees)
   */
  void
  setGapAngle(double angle);

  /** \brief Get the gap angle of the half-disk test in radians (0 = off). */
  double
  getGapAngle() const
  {
    return parameters_.gap_angle;
  }

  /** \brief Set the normal angle theta of the flatness test.
   *
   * A point is flat only if its pole line makes an angle of at most theta with the
   * pole line of every point that has it as a co-cone neighbour.
   * \param[in] angle theta in radians, in (0, pi / 2] (default pi / 6; 0.14 in the
   *            paper's proofs)
   */
  void
  setNormalAngle(double angle);

  /** \brief Get the normal angle theta in radians. */
  double
  getNormalAngle() const
  {
    return parameters_.normal_angle;
  }

  /** \brief Set the co-cone angle.
   *
   * The co-cone of p is the part of its Voronoi cell seen from p at an angle of at
   * least this much from the pole line. The paper uses 3 pi / 8 in theory and
   * practice: smaller angles widen the co-cone and make the ratio test fail more
   * often, larger ones miss surface triangles.
   * \param[in] angle in radians, in (0, pi / 2) (default 3 pi / 8)
   */
  void
  setCoconeAngle(double angle);

  /** \brief Get the co-cone angle in radians. */
  double
  getCoconeAngle() const
  {
    return parameters_.cocone_angle;
  }

  /** \brief Enable or disable boundary detection.
   * \param[in] enabled false: every point counts as interior (the original Co-cone,
   *            which covers holes); default true
   */
  void
  setBoundaryDetection(bool enabled)
  {
    parameters_.boundary_detection = enabled;
  }

  /** \brief Whether boundary detection is enabled. */
  bool
  getBoundaryDetection() const
  {
    return parameters_.boundary_detection;
  }

  /** \brief Set the number of threads (PCL convention: 0 = all processors).
   *
   * The output does not depend on it. The Delaunay triangulation (from about ten
   * thousand points a thread), the passes over the Voronoi cells, the half-disk test
   * and most of the reconstruction run in parallel; the walk on one thread. Where a
   * noisy cloud is reconstructed at both scales (see setNoiseHandling()), the two
   * run at once, half the threads each (both in memory together).
   * \param[in] nr_threads number of threads, 0 for all (default 1)
   */
  void
  setNumberOfThreads(unsigned int nr_threads = 0)
  {
    parameters_.threads = nr_threads;
  }

  /** \brief The number of threads set (0 = all processors). */
  unsigned int
  getNumberOfThreads() const
  {
    return parameters_.threads;
  }

  /** \brief Reconstruct tile by tile (cocone::runTiled()): for clouds too large for
   * one triangulation in memory.
   *
   * The cloud is cut by median splits into tiles of at most this many points, each
   * reconstructed with a halo of its neighbours' points and one at a time per
   * thread (see setNumberOfThreads()); every triangle is kept by exactly one tile,
   * the one holding its lowest input index, and the pieces are stitched into one
   * oriented manifold whose border loops are those of the whole. Peak memory
   * follows the tile size. The mesh's topology is that of the one-piece run; on
   * random samples a few percent of the triangles can differ (the walk's choices at
   * flat tetrahedra, see cocone::runTiled()). detectBoundary() always runs in one
   * piece.
   * \param[in] tile_points 0 (the default): one piece; otherwise at least
   *            cocone::MINIMUM_TILE_POINTS
   */
  void
  setTilePoints(std::size_t tile_points);

  /** \brief The most points of a tile's core (0: one piece). */
  std::size_t
  getTilePoints() const
  {
    return tiling_.tile_points;
  }

  /** \brief Tiles reconstructed at the same time (cocone::TilingOptions::
   * tiles_in_flight): peak memory grows with it, the output does not depend on it.
   * \param[in] tiles 0 (the default): one per thread */
  void
  setTilesInFlight(unsigned int tiles)
  {
    tiling_.tiles_in_flight = tiles;
  }

  /** \brief Tiles reconstructed at the same time (0: one per thread). */
  unsigned int
  getTilesInFlight() const
  {
    return tiling_.tiles_in_flight;
  }

  /** \brief Enable or disable the noise handling.
   *
   * Outliers, points off the surface their neighbours sample (flying pixels, points
   * far from everything), are set aside: in no triangle, reported by
   * getOutlierIndices(). When the cloud's noise level (getNoiseLevel()) exceeds 0.1
   * every decision is taken on a copy of the points projected twice onto local
   * degree-2 jets, provided this took the noise out (isSmoothed()): it left at most
   * half the level, and moved the points as noise would, each by its own amount (a
   * tube a few samples round, or two sheets closer than the spacing, would be
   * flattened and keeps its points); the mesh still indexes the input points. A
   * clean cloud without outliers keeps its result.
   * \param[in] enabled false: the points as given, no outliers (default true)
   */
  void
  setNoiseHandling(bool enabled)
  {
    parameters_.noise_handling = enabled;
  }

  /** \brief Close the border loops that are undersampled holes, keep the true
   * borders open (the question the paper leaves open).
   *
   * First, a part of the surface whose points the walk's mesh mostly leaves out
   * (joined by co-cone triangles of the local spacing, at least 64 points, fewer
   * than half in a triangle: the flatness test flagged it nearly all over, such as a
   * tube a few samples round under noise) gets the original Co-cone's mesh instead.
   * Where samples in no triangle lie between two loops or more and CGAL's advancing
   * front over them closes those loops at once, its triangles do, joining them if
   * so (a tunnel whose wall the walk left out: the genus grows). After that every
   * border loop of up to 1,000 edges is closed when
   * CGAL's minimum-weight hole triangulation over the loop's Delaunay faces (or,
   * up to 40 edges, over all triangles of its points) finds a patch whose new edges
   * are all at most 4 local spacings long: an undersampled hole has samples all
   * around it that continue the surface at that spacing, where the sampled surface
   * really ends nothing is that close across. A loop left, and points in no
   * triangle, then get the original Co-cone's triangles there where those make a
   * disk bounded by the loop or a closed surface, with edges as short (a part
   * sampled too coarsely for the flatness test, such as a thin tube, which it flags
   * all over). What those leave the advancing front's triangles may close (the
   * density changing faster than the co-cones follow), then the samples inside a
   * hole that no mesh used, then the advancing front over a whole piece whose hole
   * winds round it, and last the patch of least total edge length within the same
   * reach (a long narrow hole, such as a slit along the rim of a plate thinner than
   * the spacing). No new vertex; the mesh stays an oriented manifold.
   * Then the tunnels no sample lies round are closed too (handles of topological
   * noise, where the walk met two sheets within the noise or a couple of spacings
   * apart): a handle with a non-separating cycle of fewer than 6 edges whose sides
   * meet again within 32 triangles is cut along the cycle and both cuts closed
   * (getReconstructionCounts().handles_cut), and so is a neck no sample resolves
   * (two bodies that touch, which the walk joined: a separating cycle of fewer than
   * 6 edges round the filled holes, the surface opening out and going on for 32
   * rings on both sides; getReconstructionCounts().necks_cut). Each loop left (the 24
   * shortest where more are left) is reopened by one to three rings of triangles (a
   * crumpled cluster where two sheets meet within the noise, a handle through the loop)
   * and the wider hole goes through the passes again; kept only if the loop closes with
   * no handle and no piece more and every point it leaves out lies within two local
   * spacings of the new surface, or three sigmas of the cloud's noise
   * (getNoiseLevel()) where that is wider, and goes into its nearest triangle.
   * A loop that is wider than setMaxHoleWidth() of its rim's triangles with no
   * sample in it is a true border and is left as it is. getBoundaryPointIndices() is
   * not changed by it (the paper's output); getBoundaryLoops() lists the loops left.
   * \param[in] enabled false: the holes left open, the mesh as without the step
   *            (default true)
   */
  void
  setFillUndersampledHoles(bool enabled)
  {
    parameters_.fill_undersampled_holes = enabled;
  }

  /** \brief Whether undersampled holes are closed. */
  bool
  getFillUndersampledHoles() const
  {
    return parameters_.fill_undersampled_holes;
  }

  /** \brief The widest empty hole taken for undersampling: a border loop with no
   * sample in it that is wider than \a width times the triangles at its rim (the
   * diameter of their median circumcircle) is where the sampling stops, a true
   * border, and stays open (pcl::cocone::classifyBorderLoops()).
   *
   * The default 2.5 closes a hole where one sample, a row of them or two by two are
   * missing, and keeps one of three by three samples or more open: a range
   * scanner's dropout, a cut-out 4 sample spacings across. The holes noise tears
   * where registered views overlap are about as wide: lower values keep more of
   * those open (2: 3 of 12 multi-view test clouds), higher close more true holes.
   * Points inside a hole share its width (m points: width / sqrt(m + 1)). A flat face
   * that the points sample only along its outline (a CAD mesh's vertices) reads as a
   * true border when wider than this. \param[in] width in rim triangle diameters; 0:
   * every loop may be closed
   */
  void
  setMaxHoleWidth(double width)
  {
    parameters_.hole_width = width;
  }

  /** \brief The widest empty hole taken for undersampling (setMaxHoleWidth()). */
  double
  getMaxHoleWidth() const
  {
    return parameters_.hole_width;
  }

  /** \brief Refine and fair the patches that close the undersampled holes, for a
   * smooth surface there (pcl::cocone::refineFilledHoles(): CGAL's refine() and
   * fair(), as its triangulate_refine_and_fair_hole()).
   *
   * The patches then have new vertices, which follow the input cloud's points in
   * the output (reconstruct() appends them to the mesh's cloud, their other fields
   * zero; an organized cloud becomes one row); every other output still indexes
   * the input cloud alone. \param[in] enabled default false: no new vertex */
  void
  setRefineFilledHoles(bool enabled)
  {
    parameters_.refine_filled_holes = enabled;
  }

  /** \brief Whether the patches of the filled holes are refined and faired. */
  bool
  getRefineFilledHoles() const
  {
    return parameters_.refine_filled_holes;
  }

  /** \brief Number of vertices the last reconstruction added inside the holes it
   * closed (setRefineFilledHoles()): the points after the input's in its mesh. */
  std::size_t
  getNumberOfAddedPoints() const
  {
    return result_.added_vertices;
  }

  /** \brief Whether the noise handling is enabled. */
  bool
  getNoiseHandling() const
  {
    return parameters_.noise_handling;
  }

  /** \brief The noise level of the cloud in the last run: the median over the points
   * of getPointNoiseLevels(), about the sigma of Gaussian noise in units of the
   * sample spacing (clean samples read below 0.05); 0 without noise handling. */
  double
  getNoiseLevel() const
  {
    return result_.noise_level;
  }

  /** \brief The noise level of the cloud in the last run read again on the smoothed
   * points (same neighbours): smoothing is kept when it leaves at most half of
   * getNoiseLevel() and moved the points as noise would (isSmoothed()); 0 if
   * smoothing was not tried (the cloud's level at most 0.1, or no noise handling). */
  double
  getNoiseLevelAfterSmoothing() const
  {
    return result_.noise_after_smoothing;
  }

  /** \brief The noise level of every point in the last run: the RMS distance of the
   * point and its nearest neighbours to their least-squares degree-2 jet over their
   * spread along it (about sigma in spacings, as getNoiseLevel()).
   * \param[out] levels one per input cloud point; NaN where the point was not used
   *             (not finite, not among the indices, or no noise handling)
   */
  void
  getPointNoiseLevels(std::vector<float>& levels) const;

  /** \brief The outliers of the last run: the points set aside by the noise handling,
   * in no triangle, as indices into the input cloud, ascending (every duplicate of
   * an outlier is listed).
   * \param[out] outliers the indices; empty without noise handling
   */
  void
  getOutlierIndices(pcl::PointIndices& outliers) const;

  /** \brief Whether the decisions of the last run were taken on smoothed points (the
   * cloud was noisy, see setNoiseHandling()). */
  bool
  isSmoothed() const
  {
    return result_.smoothed;
  }

  /** \brief The positions the last run took its decisions on.
   * \param[out] cloud one point per input cloud point: its smoothed position, or its
   *             input position if the cloud was not smoothed; NaN for the points not
   *             used (not finite, not among the indices) and for the outliers
   */
  void
  getSmoothedCloud(pcl::PointCloud<pcl::PointXYZ>& cloud) const;

  /** \brief Number of distinct finite points (Delaunay vertices) of the last run. */
  std::size_t
  getNumberOfUniquePoints() const
  {
    return result_.vertices;
  }

  /** \brief Detect the undersampled points (stages 1-3: Delaunay triangulation,
   * Voronoi cell geometry, flatness and growth), without building a mesh.
   * \param[out] boundary indices into the input cloud, ascending; empty on error
   * \return true on success
   */
  bool
  detectBoundary(pcl::PointIndices& boundary);

  /** \brief The undersampled points of the last run, indices into the input cloud,
   * ascending: the boundary set B of the detection with the rim points of the
   * half-disk test, and after reconstruct() also the points that failed the umbrella
   * check.
   * \param[out] boundary the indices
   */
  void
  getBoundaryPointIndices(pcl::PointIndices& boundary) const;

  /** \brief The borders of the last reconstructed mesh as closed loops of input
   * indices, each ordered with the mesh on its left.
   *
   * Not the same as the undersampled points: a point next to a sharp crease is
   * undersampled, yet the mesh may pass over it.
   * \param[out] loops one pcl::Vertices per border
   */
  void
  getBoundaryLoops(std::vector<pcl::Vertices>& loops) const;

  /** \brief The undersampled holes the last reconstruction closed
   * (setFillUndersampledHoles()): the border loop each had before, as input indices
   * with the mesh on its left, each starting at its lowest index, ordered by it. A
   * rim's size is the hole's size in edges.
   * \param[out] rims one pcl::Vertices per hole closed
   */
  void
  getFilledHoles(std::vector<pcl::Vertices>& rims) const;

  /** \brief Oriented normals from the last reconstruction: the pole direction of
   * every point, turned to the side its mesh faces. A normal estimate with no
   * neighbourhood parameter. At undersampled points, where the pole is unreliable
   * (at a border it leans towards the convex hull), the area-weighted normal of the
   * point's triangles is given instead.
   * \param[out] normals one per input point; NaN for points not in the mesh
   */
  void
  getPointNormals(pcl::PointCloud<pcl::Normal>& normals) const;

  /** \brief Sizes of the intermediate results of the last reconstruction, including
   * what the manifold repair changed. */
  const cocone::ReconstructionCounts&
  getReconstructionCounts() const
  {
    return result_.counts;
  }

  /** \brief Reconstruct a mesh; with no input set, log an error and return an empty
   * mesh (the base class would dereference the missing cloud).
   * \param[out] output the mesh: the whole input cloud and triangles indexing it
   */
  void
  reconstruct(pcl::PolygonMesh& output) override;

  /** \brief Reconstruct a mesh as points and polygons.
   * \param[out] points a copy of the whole input cloud
   * \param[out] polygons triangles indexing \a points
   */
  void
  reconstruct(pcl::PointCloud<PointInT>& points,
              std::vector<pcl::Vertices>& polygons) override;

  /** \brief Wall-clock time of each stage of the last run, in milliseconds. */
  const cocone::Timings&
  getTimings() const
  {
    return timings_;
  }

protected:
  using SurfaceReconstruction<PointInT>::input_;
  using SurfaceReconstruction<PointInT>::indices_;
  using SurfaceReconstruction<PointInT>::initCompute;
  using SurfaceReconstruction<PointInT>::deinitCompute;
  using SurfaceReconstruction<PointInT>::check_tree_;

  /** \brief The class name, for PCL's messages. */
  std::string
  getClassName() const override
  {
    return "CoConeBoundary";
  }

  /** \brief Run the pipeline and fill the mesh's polygons (the base class has copied
   * the input cloud into it); on error an empty mesh. */
  void
  performReconstruction(pcl::PolygonMesh& output) override;

  /** \brief Run the pipeline; \a points becomes a copy of the input cloud. */
  void
  performReconstruction(pcl::PointCloud<PointInT>& points,
                        std::vector<pcl::Vertices>& polygons) override;

private:
  /** Run the core on the indexed points of the input; false (logged) on error. */
  bool
  compute(cocone::Stages stages, const char* caller);

  /** Input indices of the last run as PCL indices, with the input's header. */
  void
  toPointIndices(const std::vector<int>& ids, pcl::PointIndices& out) const;

  /** Loops of input indices as pcl::Vertices. */
  static void
  toVertices(const std::vector<std::vector<int>>& loops,
             std::vector<pcl::Vertices>& out);

  /** Append the vertices the refinement of the filled holes added. */
  void
  appendAddedPoints(pcl::PointCloud<PointInT>& points) const;

  /** Append the mesh's triangles. */
  void
  fillPolygons(std::vector<pcl::Vertices>& polygons) const;

  cocone::Parameters parameters_;
  cocone::TilingOptions tiling_;
  cocone::Timings timings_;
  /** The last run: its core result and the cloud size it was indexed against. */
  cocone::Result result_;
  /** Input index of each point passed to the core in the last run. */
  std::vector<int> ids_;
  std::size_t cloud_size_ = 0;
};

} // namespace pcl

#ifdef PCL_NO_PRECOMPILE
#include <pcl/surface/impl/cocone_boundary.hpp>
#endif
