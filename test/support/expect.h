/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <gtest/gtest.h>

#include <support/metrics.h>

#include <cstddef>
#include <cstring>
#include <vector>

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

/** The same bits (NaN equal to NaN). */
template <typename T>
bool
sameBits(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/** \brief Expect two results to be the same, bit for bit where they hold numbers. */
inline void
expectSameResult(const pcl::cocone::Result& a, const pcl::cocone::Result& b)
{
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.polygons, b.polygons);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.border_loops, b.border_loops);
  EXPECT_EQ(a.filled_holes, b.filled_holes);
  EXPECT_EQ(a.boundary_indices, b.boundary_indices);
  EXPECT_EQ(a.outlier_indices, b.outlier_indices);
  EXPECT_EQ(a.vertex_of_input, b.vertex_of_input);
  EXPECT_EQ(a.representative, b.representative);
  EXPECT_TRUE(sameBits(a.positions, b.positions));
  EXPECT_TRUE(sameBits(a.normals, b.normals));
  EXPECT_TRUE(sameBits(a.point_noise, b.point_noise));
  EXPECT_EQ(a.offset, b.offset);
  EXPECT_EQ(a.ratio, b.ratio);
  EXPECT_EQ(a.noise_level, b.noise_level);
}

} // namespace cocone_test
