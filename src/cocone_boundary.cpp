/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/impl/instantiate.hpp>
#include <pcl/surface/cocone_boundary.h>
#include <pcl/surface/impl/cocone_boundary.hpp>
#include <pcl/point_types.h>

#ifndef PCL_NO_PRECOMPILE
// clang-format off
PCL_INSTANTIATE(CoConeBoundary, PCL_XYZ_POINT_TYPES)
// clang-format on
#endif
