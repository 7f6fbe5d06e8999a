/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/candidates.h>
#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/repair.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief Parameters of the whole pipeline. */
struct Parameters {
  /** Ratio rho of the flatness test; 0: chosen from the cloud (automaticRatio()). */
  double ratio = 0.0;
  /** Spacing factor a of the flatness test (width <= a * local spacing); 0: off,
   * the paper's test. */
  double spacing_factor = 3.0;
  /** Gap angle of the half-disk test in radians: a point whose nearby neighbours,
   * seen along its pole line, leave a larger angular gap (and two of whose neighbours
   * do too) is a rim point (see halfDiskTest()); 0: off. */
  double gap_angle = 1.3962634015954636; ///< 80 degrees
  /** Reach of the half-disk test in local spacings s_p. */
  double gap_reach = 1.75;
  /** Normal angle theta in radians. */
  double normal_angle = 0.5235987755982988; ///< pi / 6
  /** Co-cone angle in radians. */
  double cocone_angle = 1.1780972450961724; ///< 3 pi / 8
  /** false: every vertex counts as interior (the original Co-cone). */
  bool boundary_detection = true;
  /** Which triangles the interior vertices choose (stage 4). */
  CandidateRule candidate_rule = CandidateRule::INTERIOR_CHOOSES;
  /** Close border loops of at most this many edges with Delaunay triangles: holes
   * below the sampling resolution (one or a few missing triangles); 0: none. */
  std::size_t fill_hole_edges = 6;
  /** Close the border loops that are undersampled holes (first those the advancing
   * front joins through samples in no triangle, a tunnel's wall: fillHolesFromMesh()
   * with join_loops; then fillUndersampledHoles(), then fillHolesFromMesh() with the
   * original Co-cone's triangles, which also cover parts too coarse for the flatness
   * test), cut the handles no sample lies round (cutShortHandles()), and reopen
   * the loops left in crumpled clusters wider and close them again
   * (trianglesRoundLoop()): the mesh is open only where the sampled surface ends. */
  bool fill_undersampled_holes = true;
  /** The longest edge of a hole's patch, in local spacings. Measured: the holes
   * noise tears where registered views overlap (one or two points missing) need
   * 2.3 to 2.6; on noisy closed meshes (vertex sets with noise 0.3 to 0.5 of the
   * spacing, smoothed, some points set aside as outliers) patches of 3 to 4 close
   * 10 to 17 more loops (2.75 left FinalBaseMesh, the bunny, the casting and the
   * Power Crust knot 36 and 42 wrong loops at 0.3 and 0.5, 4.0 left 26 and 25),
   * and the clean originalHead's last loop; at 6.0 two touching spheres bridge. A
   * true hole is kept open by classifyBorderLoops() first: only one it takes for
   * undersampled and whose patch has no edge beyond this reach closes. */
  double hole_reach = 4.0;
  /** The widest undersampled hole with no sample in it, in diameters of the median
   * circumcircle of the triangles at its rim (classifyBorderLoops()): a wider empty
   * hole is where the sampling stops, a true border, and stays open. 0: every loop
   * may be filled. Measured: on an even grid one missing sample reads 1.4, two by
   * two 2.1, three by three 2.8; the holes noise tears where registered views
   * overlap up to about 2.4 (at 2.0, 3 of 12 such test clouds kept one). The last
   * Delaunay patches may have edges twice as long, in the same unit, where the
   * local spacing is finer (fillUndersampledHoles()'s rim_reach). */
  double hole_width = 2.5;
  /** Refine and fair the patches of the holes closed (refineFilledHoles()): new
   * vertices inside them, a smooth surface there; false: no new vertex. */
  bool refine_filled_holes = false;
  /** Border loops longer than this many edges stay open. */
  std::size_t max_hole_edges = 1000;
  /** Noise handling (see analyzeNoise()): outliers are set aside, and when the
   * cloud's noise level exceeds noise_threshold every decision is taken on a
   * smoothed copy of the points (smoothPoints()), the mesh still indexing the
   * caller's points, provided the smoothing took the noise out: it left at most
   * half the level and moved the points as noise would (displacementKurtosis() at
   * least 2.5; a surface too coarse or too creased for the jets, a tube a few
   * samples round or two sheets closer than the spacing, moves alike, below 1.8,
   * and is left as it is), and lengthened the poles as taking noise out does
   * (medianPoleHeight() at least 1.6 times the given points'; a clean but unevenly
   * sampled mesh's vertex set can read as noisy). In between, where noise on a
   * coarse or creased surface moves the points partly as noise and partly alike, or
   * the poles stay put, a reconstruction runs on both and the smoothed points' mesh is
   * kept if it leaves out or has on its border at most 0.8 of the points that the given
   * points' mesh does (boundary detection alone keeps the given points). false: the
   * points as given. */
  bool noise_handling = true;
  /** The cloud noise level (about sigma in sample spacings) above which the
   * decisions are taken on smoothed points: where the pipeline without smoothing
   * starts to tear holes (Gaussian noise of 0.15 spacings, which reads 0.17, gives
   * 3 to 12 loops on random samples of the test surfaces; clean samples read below
   * 0.05). */
  double noise_threshold = 0.1;
  /** Projections onto local jets when smoothing. */
  int smoothing_iterations = 2;
  /** Threads for the parallel stages, 0 for all processors; the output does not
   * depend on it. */
  unsigned int threads = 1;
  /** Only the first this many points passed to run() count in the statistics read
   * off the whole cloud: the automatic ratio, the median gap of the half-disk test,
   * the noise level before and after smoothing. 0: every point. A tile of
   * runTiled() passes its core first and counts it alone, so that its halo, whose
   * outer points lack neighbours, does not weigh in. */
  std::size_t statistics_points = 0;
};

/** \brief Sizes of the intermediate results of stages 4-7. */
struct ReconstructionCounts {
  std::size_t candidates = 0;        ///< stage 4
  std::size_t umbrella_failures = 0; ///< stage 5
  std::size_t pruned = 0;            ///< stage 6: triangles removed
  std::size_t walk_components = 0;   ///< stage 7: components of the pruned complex
  std::size_t walked = 0;            ///< stage 7: triangles the walk kept
  std::size_t walk_conflicts = 0; ///< stage 7: triangles reached with both orientations
  std::size_t walk_reseeds = 0;   ///< stage 7: walks started after one per component
  RepairCounts repair;            ///< changes by the manifold repair
  std::size_t unmeshed_parts = 0; ///< triangles of the Co-cone over unmeshed parts
  std::size_t true_borders = 0;   ///< border loops classified true borders, kept open
  std::size_t holes_filled = 0;   ///< undersampled holes closed
  std::size_t hole_triangles = 0; ///< triangles added to close them
  std::size_t handles_cut = 0;    ///< handles no sampled tunnel explains, cut
  std::size_t necks_cut = 0;      ///< necks no sample resolves, cut
};

/** \brief Wall-clock time of each stage, in milliseconds. */
struct Timings {
  double unique = 0.0;         ///< merging duplicates, numbering the vertices
  double delaunay = 0.0;       ///< stage 1
  double noise = 0.0;          ///< noise analysis, smoothing, second triangulation
  double voronoi = 0.0;        ///< stage 2
  double boundary = 0.0;       ///< stage 3
  double reconstruction = 0.0; ///< stages 4-7 and the repair
};

/** \brief What the pipeline returns.
 *
 * Vertex-level fields are indexed by Delaunay vertex id; the *_indices fields hold
 * the caller's ids of the points (see run()).
 */
struct Result {
  /** Empty on success; otherwise why there is no result. */
  std::string error;
  /** Per point passed to run(): its Delaunay vertex, -1 if the point is not finite,
   * -2 if it is an outlier. */
  std::vector<int> vertex_of_input;
  /** The noise level of the cloud (NoiseAnalysis::cloud_level; 0 without noise
   * handling). */
  double noise_level = 0.0;
  /** The noise level after smoothing (cloudNoiseLevel()), also when the smoothing
   * was then not kept; 0 if it was not tried. */
  double noise_after_smoothing = 0.0;
  /** Per point passed to run(): its noise level (NoiseAnalysis::level), NaN if it
   * is not finite; empty without noise handling. */
  std::vector<float> point_noise;
  /** The decisions were taken on smoothed points: positions are the smoothed ones. */
  bool smoothed = false;
  /** Caller ids of the outliers, ascending: set aside, in no triangle. */
  std::vector<int> outlier_indices;
  /** Number of Delaunay vertices (unique finite points). */
  std::size_t vertices = 0;
  /** Per vertex: undersampled (not in the interior set of stage 3), or a rim point
   * of the half-disk test. */
  std::vector<std::uint8_t> boundary;
  /** The ratio rho used (the automatic one when Parameters::ratio is 0). */
  double ratio = 0.0;
  /** Per vertex: failed the umbrella check (stage 5). */
  std::vector<std::uint8_t> umbrella_failed;
  /** Caller ids of the points labelled boundary (B, plus the umbrella failures after
   * a reconstruction), ascending. Every duplicate of a boundary vertex is listed. */
  std::vector<int> boundary_indices;
  /** Per vertex: the caller id that stands for it in polygons (its lowest). */
  std::vector<int> representative;
  /** Vertex positions, recentred: a point is positions[v] + offset. The smoothed
   * positions when smoothed is set. */
  std::vector<Eigen::Vector3d> positions;
  /** The offset subtracted before triangulating. */
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  /** The output mesh: oriented triangles over vertex ids. */
  std::vector<Triangle> triangles;
  /** The mesh's triangles over caller ids. */
  std::vector<Triangle> polygons;
  /** The border loop each undersampled hole had before it was closed, in caller ids
   * (the mesh on its left), each starting at its lowest id, ordered by it: where the
   * holes were and their sizes in edges. */
  std::vector<std::vector<int>> filled_holes;
  /** Vertices added inside the holes closed (Parameters::refine_filled_holes):
   * vertex ids from vertices on, caller ids from the largest id given plus one
   * (refineFilledHoles()). */
  std::size_t added_vertices = 0;
  /** Borders of the mesh as closed loops of caller ids. */
  std::vector<std::vector<int>> border_loops;
  /** Per vertex: unit pole direction turned to agree with the mesh (at undersampled
   * vertices the area-weighted normal of their triangles); NaN when the vertex is not
   * in the mesh. */
  std::vector<Eigen::Vector3d> normals;
  /** Sizes of the intermediate results of stages 4-7. */
  ReconstructionCounts counts;
  /** Wall-clock time of each stage. */
  Timings timings;
};

/** \brief Which stages to run. */
enum class Stages { BOUNDARY_DETECTION, RECONSTRUCTION };

/** \brief Run the stages on a set of points.
 *
 * \param[in] points the points; non-finite points and duplicates are allowed (taken
 *            by value: move them in, they are freed once the unique points are made)
 * \param[in] parameters the parameters
 * \param[in] stages how far to go
 * \param[in] ids the caller's id of each point (e.g. its index in a PCL cloud);
 *            empty: the position in \a points
 */
Result
run(std::vector<Eigen::Vector3d> points,
    const Parameters& parameters,
    Stages stages,
    const std::vector<int>& ids = {});

} // namespace cocone
} // namespace pcl
