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
 */
bool
hasUmbrella(const TriangleComplex& complex, int p);

/** \brief Stage 5: the vertices outside B that have no non-sharp umbrella.
 *
 * \param[in] complex the candidate triangles
 * \param[in] boundary per vertex: in B (these are not checked)
 * \return per vertex: failed the umbrella check
 */
std::vector<std::uint8_t>
umbrellaFailures(const TriangleComplex& complex,
                 const std::vector<std::uint8_t>& boundary);

} // namespace cocone
} // namespace pcl
