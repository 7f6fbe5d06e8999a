/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

/** \brief HASUMBRELLA (Dey & Giesen, section 6.1) for one vertex.
 *
 * Deletes, virtually, the sharp edges at p and their triangles in a cascade
 * restricted to the star of p; p has an umbrella if a triangle survives.
 * \param[in,out] kept if given and p has an umbrella, the count of each surviving
 *                triangle is incremented
 */
bool
hasUmbrella(const TriangleComplex& complex,
            int p,
            std::vector<std::uint8_t>* kept = nullptr);

/** \brief Stage 5: the vertices outside B that have no non-sharp umbrella.
 *
 * \param[in] complex the candidate triangles
 * \param[in] boundary per vertex: in B (these are not checked)
 * \param[out] umbrella_triangles if given, per triangle: it survives in the umbrella
 *             of each of its three vertices (all three checked and passed)
 * \param[in] threads threads to check the vertices with
 * \return per vertex: failed the umbrella check
 */
std::vector<std::uint8_t>
umbrellaFailures(const TriangleComplex& complex,
                 const std::vector<std::uint8_t>& boundary,
                 std::vector<std::uint8_t>* umbrella_triangles = nullptr,
                 int threads = 1);

} // namespace cocone
} // namespace pcl
