/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/PCLPointCloud2.h>
#include <pcl/PolygonMesh.h>
#include <pcl/types.h>

#include <string>

namespace cocone_app {

/** Render the mesh with its boundary points (drawn larger) to a PNG file. */
bool
renderScreenshot(const pcl::PolygonMesh& mesh,
                 const pcl::PCLPointCloud2& cloud,
                 const pcl::Indices& boundary,
                 const std::string& png,
                 std::string& error);

/** Run this program again under xvfb-run (for rendering without a display); does
 * not return unless xvfb-run cannot be started. */
void
reexecUnderXvfb(int argc, char** argv);

} // namespace cocone_app
