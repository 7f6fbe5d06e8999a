/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <gtest/gtest.h>

#include <support/metrics.h>

#include <cstddef>

namespace cocone_test {

/** \brief Whether the mesh is what a closed sampled surface should give: an oriented
 * 2-manifold without border, of \a components pieces with Euler characteristic
 * \a euler, facing outward. Use as EXPECT_TRUE(closedSurface(m, 1, 2)). */
inline ::testing::AssertionResult
closedSurface(const MeshScore& m, std::size_t components, long euler)
{
  if (m.topology.manifold() && m.loops == 0 && m.topology.boundary_edges == 0 &&
      m.topology.components == components && m.topology.euler == euler &&
      m.volume > 0.0)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "expected a closed oriented surface of " << components
         << " component(s), Euler " << euler << "; got " << m.str();
}

} // namespace cocone_test
