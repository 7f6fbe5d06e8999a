/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The pieces the in-memory and the out-of-core tilings share: the cut, the
 * spacing that sets the halo, the sums over the tiles.
 */

#pragma once

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/pipeline.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Seam holes of up to this many edges are closed with the tiles' triangles: where
 * two tiles disagree the gap is a triangle or two (loops of 3 to 6 edges). */
constexpr std::size_t SEAM_HOLE_EDGES = 12;

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::max());

  void
  extend(const Eigen::Vector3d& p)
  {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }

  double
  distance(const Eigen::Vector3d& p) const
  {
    return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
  }

  double
  distance(const Box& b) const
  {
    return (lo - b.hi).cwiseMax(b.lo - hi).cwiseMax(0.0).norm();
  }
};

/** The tiles: a k-d tree of median splits over the finite points, its leaves the
 * cores. */
class Tiles {
public:
  struct Node {
    std::size_t begin = 0, end = 0; ///< range of order
    Box box;                        ///< of the node's points
    int left = -1, right = -1;      ///< children; -1 at a leaf
    int axis = 0;                   ///< of the split
    Eigen::Vector3d pivot;          ///< of the split
    bool equal_left = false;        ///< the pivot's duplicates went left
    int leaf = -1;                  ///< its tile, at a leaf
  };

  Tiles(const std::vector<Eigen::Vector3d>& points,
        std::vector<int> finite,
        std::size_t tile_points)
  : points_(points), order_(std::move(finite)), tile_points_(tile_points)
  {
    nodes_.reserve(4 * (order_.size() / tile_points + 1));
    nodes_.emplace_back();
    nodes_[0].end = order_.size();
    split(0);
    // Each core in the order of the points: what a tile is given does not depend on
    // how the splits shuffled them.
    for (const int leaf : leaves_)
      std::sort(order_.begin() + static_cast<std::ptrdiff_t>(nodes_[leaf].begin),
                order_.begin() + static_cast<std::ptrdiff_t>(nodes_[leaf].end));
  }

  /** The tile whose core \a p falls in, by the splits (the tile of a point the tree
   * was made of is the one that holds it). */
  std::size_t
  locate(const Eigen::Vector3d& p) const
  {
    int n = 0;
    while (nodes_[n].left >= 0) {
      const Node& node = nodes_[n];
      const bool left = node.equal_left ? !less(node.axis, node.pivot, p)
                                        : less(node.axis, p, node.pivot);
      n = left ? node.left : node.right;
    }
    return static_cast<std::size_t>(nodes_[n].leaf);
  }

  std::size_t
  size() const
  {
    return leaves_.size();
  }

  const Node&
  core(std::size_t tile) const
  {
    return nodes_[leaves_[tile]];
  }

  const std::vector<int>&
  order() const
  {
    return order_;
  }

  /** The order, moved out: the tiles are of no further use. */
  std::vector<int>
  takeOrder()
  {
    return std::move(order_);
  }

  /** The positions of the points not in \a tile's core within \a reach of its box,
   * in the order of the tiles. */
  std::vector<int>
  halo(std::size_t tile, double reach) const
  {
    std::vector<int> out;
    const int own = leaves_[tile];
    const Box& box = nodes_[own].box;
    std::vector<int> stack{0};
    while (!stack.empty()) {
      const int n = stack.back();
      stack.pop_back();
      const Node& node = nodes_[n];
      if (n == own || node.box.distance(box) > reach)
        continue;
      if (node.left >= 0) {
        stack.push_back(node.right); // the left child first
        stack.push_back(node.left);
        continue;
      }
      for (std::size_t i = node.begin; i < node.end; ++i)
        if (box.distance(points_[order_[i]]) <= reach)
          out.push_back(order_[i]);
    }
    return out;
  }

private:
  /** Along \a axis, then by the other coordinates: exact duplicates compare equal
   * and are kept on one side, so that a vertex has one core. */
  static bool
  less(int axis, const Eigen::Vector3d& p, const Eigen::Vector3d& q)
  {
    if (p[axis] != q[axis])
      return p[axis] < q[axis];
    return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
  }

  void
  addLeaf(int n)
  {
    nodes_[n].leaf = static_cast<int>(leaves_.size());
    leaves_.push_back(n);
  }

  void
  split(int n)
  {
    const std::size_t begin = nodes_[n].begin, end = nodes_[n].end;
    Box box;
    for (std::size_t i = begin; i < end; ++i)
      box.extend(points_[order_[i]]);
    nodes_[n].box = box;
    const Eigen::Vector3d extent = box.hi - box.lo;
    int axis = 0;
    extent.maxCoeff(&axis);
    if (end - begin <= tile_points_ || !(extent[axis] > 0.0)) {
      addLeaf(n);
      return;
    }
    const auto less = [&](int a, int b) {
      return Tiles::less(axis, points_[a], points_[b]);
    };
    const auto first = order_.begin() + static_cast<std::ptrdiff_t>(begin);
    const auto last = order_.begin() + static_cast<std::ptrdiff_t>(end);
    auto middle = first + static_cast<std::ptrdiff_t>((end - begin) / 2);
    std::nth_element(first, middle, last, less);
    const int pivot = *middle;
    // The pivot's duplicates go right, or left when all of the left are such.
    auto cut = std::partition(first, middle, [&](int i) { return less(i, pivot); });
    const bool equal_left = cut == first;
    if (equal_left)
      cut = std::partition(middle, last, [&](int i) { return !less(pivot, i); });
    if (cut == first || cut == last) {
      addLeaf(n);
      return;
    }
    const auto mid = static_cast<std::size_t>(cut - order_.begin());
    const int left = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[n].left = left;
    nodes_[n].right = left + 1;
    nodes_[n].axis = axis;
    nodes_[n].pivot = points_[pivot];
    nodes_[n].equal_left = equal_left;
    nodes_[left].begin = begin;
    nodes_[left].end = mid;
    nodes_[left + 1].begin = mid;
    nodes_[left + 1].end = end;
    split(left);
    split(left + 1);
  }

  const std::vector<Eigen::Vector3d>& points_;
  std::vector<int> order_;
  std::size_t tile_points_;
  std::vector<Node> nodes_;
  std::vector<int> leaves_;
};

/** The median distance of the points of \a index to their nearest other point (a
 * distinct one), over an even sample of them; 0 if all coincide. */
double
medianSpacing(const std::vector<Eigen::Vector3d>& P,
              const int* index,
              std::size_t n,
              const Box& box);

/** Memory a tile of \a core points takes in flight: its halo adds about a quarter (8
 * spacings round a million points: 10 to 20 %). */
double
tileBytes(double core);

/** \a core rounded down to the series 1, 1.25, 1.6, 2, 2.5, 3.2, 4, 5, 6.3, 8 times
 * a power of ten, at least MINIMUM_TILE_POINTS: a little more or less memory free
 * gives the same tiles, so the same mesh. */
std::size_t
seriesTilePoints(double core);

/** \a a += \a b, field by field. */
void
add(ReconstructionCounts& a, const ReconstructionCounts& b);
void
add(Timings& a, const Timings& b);

/** The median of \a v (its upper middle element), 0 if empty. */
double
median(std::vector<double> v);

/** Whether the stitch closes a hole of three edges by its own triangle \a t (ids
 * ascending, none of the tiles kept it): its edges are border edges and it lies on a
 * seam, its vertices in more than one core or the triangles at its edges from more
 * than one tile. Tiles that triangulate a flat spot of five or more points
 * differently leave such a hole; on a 100M torus one had all three vertices in one
 * core, its edges' triangles from two tiles.
 * \param[in] incidences of the stitched triangles
 * \param[in] core_of per vertex, the tile whose core holds it
 * \param[in] tile_of per triangle (an index into what \a incidences group), the tile
 *            that kept it */
template <typename CoreOf, typename TileOf>
bool
closesSeamHole(const EdgeIncidences& incidences,
               const Triangle& t,
               const CoreOf& core_of,
               const TileOf& tile_of)
{
  std::array<int, 3> tile{};
  for (int k = 0; k < 3; ++k) {
    const std::ptrdiff_t e = incidences.find(t[k], t[(k + 1) % 3]);
    if (e < 0 || incidences.count(static_cast<std::size_t>(e)) != 1)
      return false;
    tile[k] = tile_of(incidences.triangle[incidences.first[e]]);
  }
  return core_of(t[0]) != core_of(t[1]) || core_of(t[0]) != core_of(t[2]) ||
         tile[0] != tile[1] || tile[0] != tile[2];
}

/** One entry per hole among the holes the tiles closed, each given as (whether
 * another tile owns its rim's lowest id, its rim). A hole near a seam is closed by
 * each tile that sees it, and tiles may disagree on where a hole is (the triangles
 * round it differ): the rims are taken owners' first, then in their order, and one
 * that shares a point with a rim taken is the same hole (a point is on one loop of a
 * mesh). */
std::vector<std::vector<int>>
distinctHoles(std::vector<std::pair<bool, std::vector<int>>> candidates);

/** Per patch (a connected piece of the triangles one tile kept), whether to turn it
 * over so that it agrees with its neighbours across the seams: per pair of patches
 * the edges they share vote, the pairs with the clearest vote first (the first pair
 * that joins two sets decides them).
 * \param[in] incidences of the stitched triangles
 * \param[in] patch per triangle its patch, below \a patches */
std::vector<std::uint8_t>
turnPatches(const EdgeIncidences& incidences,
            const std::vector<int>& patch,
            std::size_t patches);

/** A vertex normal against the stitched mesh, as run() turns them: NaN where no
 * triangle faces (\a facing, the sum of the area normals of the vertex's triangles,
 * is zero), the facing direction where the tile's normal is not to be trusted
 * (\a recompute: a boundary or umbrella-failed vertex) or not finite, else the
 * tile's normal turned to the facing side. */
void
turnNormal(Eigen::Vector3d& normal, const Eigen::Vector3d& facing, bool recompute);

} // namespace detail
} // namespace cocone
} // namespace pcl
