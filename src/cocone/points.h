/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Small helpers on points shared by the stages' sources (not installed).
 */

#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <utility>

namespace pcl {
namespace cocone {
namespace detail {

inline bool
isFinite(const Eigen::Vector3d& p)
{
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
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

} // namespace detail
} // namespace cocone
} // namespace pcl
