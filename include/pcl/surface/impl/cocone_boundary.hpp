/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#ifndef PCL_SURFACE_IMPL_COCONE_BOUNDARY_HPP_
#define PCL_SURFACE_IMPL_COCONE_BOUNDARY_HPP_

#include <pcl/console/print.h>
#include <pcl/surface/cocone_boundary.h>

#include <cmath>

namespace pcl {

template <typename PointInT>
CoConeBoundary<PointInT>::CoConeBoundary()
{
  // The Delaunay triangulation replaces any neighbour search.
  check_tree_ = false;
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::setRatio(double ratio)
{
  if (!std::isfinite(ratio) || ratio <= 0.0) {
    PCL_ERROR("[pcl::%s::setRatio] The ratio must be finite and positive (got %g); "
              "keeping %g.\n",
              getClassName().c_str(),
              ratio,
              parameters_.ratio);
    return;
  }
  parameters_.ratio = ratio;
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::setNormalAngle(double angle)
{
  if (!(angle > 0.0 && angle <= M_PI / 2.0)) {
    PCL_ERROR("[pcl::%s::setNormalAngle] The normal angle must be in (0, pi/2] "
              "(got %g); keeping %g.\n",
              getClassName().c_str(),
              angle,
              parameters_.normal_angle);
    return;
  }
  parameters_.normal_angle = angle;
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::setCoconeAngle(double angle)
{
  if (!(angle > 0.0 && angle < M_PI / 2.0)) {
    PCL_ERROR("[pcl::%s::setCoconeAngle] The co-cone angle must be in (0, pi/2) "
              "(got %g); keeping %g.\n",
              getClassName().c_str(),
              angle,
              parameters_.cocone_angle);
    return;
  }
  parameters_.cocone_angle = angle;
}

template <typename PointInT>
bool
CoConeBoundary<PointInT>::compute(cocone::Stages stages, const char* caller)
{
  boundary_indices_.clear();
  timings_ = cocone::Timings();
  std::vector<Eigen::Vector3d> points;
  std::vector<int> ids;
  points.reserve(indices_->size());
  ids.reserve(indices_->size());
  for (const auto i : *indices_) {
    if (i < 0 || static_cast<std::size_t>(i) >= input_->size()) {
      PCL_ERROR("[pcl::%s::%s] Index %d is outside the input cloud (%zu points).\n",
                getClassName().c_str(),
                caller,
                static_cast<int>(i),
                static_cast<std::size_t>(input_->size()));
      return false;
    }
    const PointInT& p = (*input_)[i];
    points.emplace_back(p.x, p.y, p.z);
    ids.push_back(static_cast<int>(i));
  }

  cocone::Result result = cocone::run(points, parameters_, stages, ids);
  timings_ = result.timings;
  if (!result.error.empty()) {
    PCL_ERROR("[pcl::%s::%s] No result: %s.\n",
              getClassName().c_str(),
              caller,
              result.error.c_str());
    return false;
  }
  boundary_indices_.assign(result.boundary_indices.begin(),
                           result.boundary_indices.end());
  PCL_DEBUG("[pcl::%s::%s] %zu points, %zu unique; timings (ms): unique %.1f, "
            "Delaunay %.1f, Voronoi %.1f, boundary %.1f, reconstruction %.1f; "
            "%zu boundary points.\n",
            getClassName().c_str(),
            caller,
            points.size(),
            result.vertices,
            timings_.unique,
            timings_.delaunay,
            timings_.voronoi,
            timings_.boundary,
            timings_.reconstruction,
            boundary_indices_.size());
  return true;
}

template <typename PointInT>
bool
CoConeBoundary<PointInT>::detectBoundary(pcl::PointIndices& boundary)
{
  boundary.indices.clear();
  if (!input_) {
    PCL_ERROR("[pcl::%s::detectBoundary] No input cloud was set.\n",
              getClassName().c_str());
    boundary_indices_.clear();
    return false;
  }
  boundary.header = input_->header;
  if (!initCompute()) {
    boundary_indices_.clear();
    return false;
  }
  const bool ok = compute(cocone::Stages::BOUNDARY_DETECTION, "detectBoundary");
  deinitCompute();
  boundary.indices = boundary_indices_;
  return ok;
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::getBoundaryPointIndices(pcl::PointIndices& boundary) const
{
  if (input_)
    boundary.header = input_->header;
  boundary.indices = boundary_indices_;
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::performReconstruction(pcl::PolygonMesh& output)
{
  output.polygons.clear();
  PCL_ERROR("[pcl::%s::reconstruct] Not implemented yet.\n", getClassName().c_str());
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::performReconstruction(pcl::PointCloud<PointInT>& points,
                                                std::vector<pcl::Vertices>& polygons)
{
  points.clear();
  polygons.clear();
  PCL_ERROR("[pcl::%s::reconstruct] Not implemented yet.\n", getClassName().c_str());
}

} // namespace pcl

#define PCL_INSTANTIATE_CoConeBoundary(T) template class PCL_EXPORTS pcl::CoConeBoundary<T>;

#endif // PCL_SURFACE_IMPL_COCONE_BOUNDARY_HPP_
