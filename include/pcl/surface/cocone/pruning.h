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

/** \brief Stage 6: PRUNING, the cascaded removal of triangles at sharp edges.
 *
 * A triangle with a vertex in \a boundary is never removed: otherwise the surface
 * would erode from its border inwards. Nor is a triangle that survives in the
 * umbrella of each of its vertices (\a keep): with few or no boundary vertices (the
 * plain Co-cone, or noise that hides the borders) the paper's cascade runs from the
 * border through the whole surface, while the flaps pruning is meant for are not part
 * of their vertices' umbrellas.
 *
 * \param[in] complex the candidate triangles
 * \param[in] boundary per vertex: B plus the umbrella failures
 * \param[out] removed number of triangles removed (may be null)
 * \param[in] keep per triangle: never remove (may be empty)
 * \return per triangle of the complex: still present
 */
std::vector<std::uint8_t>
prune(const TriangleComplex& complex,
      const std::vector<std::uint8_t>& boundary,
      std::size_t* removed = nullptr,
      const std::vector<std::uint8_t>& keep = {});

} // namespace cocone
} // namespace pcl
