/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Small helpers on points shared by the stages' sources (not installed).
 */

#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

inline bool
isFinite(const Eigen::Vector3d& p)
{
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

/** Whether edge ab is at most \a reach times the larger local spacing of its ends
 * long: as short as the triangles of the sampling there. */
inline bool
withinReach(const std::vector<Eigen::Vector3d>& points,
            const std::vector<double>& spacing,
            double reach,
            int a,
            int b)
{
  const double longest = reach * std::max(spacing[a], spacing[b]);
  return (points[a] - points[b]).squaredNorm() <= longest * longest;
}

/** Lexicographic order of coordinates: the canonical order for tie-breaks. */
inline bool
lexLess(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

/** Sort the first \a n (3 or 4) entries of \a a by \a key with compare-exchanges
 * (a sorting network): the per-cell and per-facet orders of the passes over the
 * cells, where a call of std::sort costs more than the sorting. */
template <typename Array, typename Key>
inline void
sortCorners(Array& a, int n, Key key)
{
  const auto order = [&](int i, int j) {
    if (key(a[j]) < key(a[i]))
      std::swap(a[i], a[j]);
  };
  if (n == 4) {
    order(0, 1);
    order(2, 3);
    order(0, 2);
    order(1, 3);
    order(1, 2);
  }
  else {
    order(0, 1);
    order(1, 2);
    order(0, 1);
  }
}

/** The facet of cell \a v opposite its vertex v[i]: the other three ids ascending,
 * and the parity of the permutation from v to (those three, v[i]), +1 even, -1
 * odd. For a positively oriented cell, +1 means v[i] lies where (p1 - p0) x
 * (p2 - p0) of the facet's points points: CGAL's orientations, read exactly. */
struct OppositeFacet {
  std::array<int, 3> ids;
  int parity;
};

inline OppositeFacet
oppositeFacet(const std::array<int, 4>& v, int i)
{
  OppositeFacet f;
  for (int k = 0, m = 0; k < 4; ++k)
    if (k != i)
      f.ids[m++] = v[k];
  // v[i] moved last: 3 - i transpositions; then the inversions among the rest.
  const int swaps =
      3 - i + (f.ids[0] > f.ids[1]) + (f.ids[0] > f.ids[2]) + (f.ids[1] > f.ids[2]);
  f.parity = swaps % 2 == 0 ? 1 : -1;
  sortCorners(f.ids, 3, [](int id) { return id; });
  return f;
}

} // namespace detail
} // namespace cocone
} // namespace pcl
