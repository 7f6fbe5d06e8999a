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

} // namespace detail
} // namespace cocone
} // namespace pcl
