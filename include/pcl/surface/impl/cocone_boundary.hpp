/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#ifndef PCL_SURFACE_IMPL_COCONE_BOUNDARY_HPP_
#define PCL_SURFACE_IMPL_COCONE_BOUNDARY_HPP_

#include <pcl/console/print.h>
#include <pcl/surface/cocone_boundary.h>
#include <pcl/conversions.h>

#include <algorithm>
#include <cmath>
#include <limits>

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
  if (!std::isfinite(ratio) || ratio < 0.0) {
    PCL_ERROR("[pcl::%s::setRatio] The ratio must be finite and positive, or 0 for "
              "automatic (got %g); keeping %g.\n",
              getClassName().c_str(),
              ratio,
              parameters_.ratio);
    return;
  }
  parameters_.ratio = ratio;
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::setSpacingFactor(double factor)
{
  if (!std::isfinite(factor) || factor < 0.0) {
    PCL_ERROR("[pcl::%s::setSpacingFactor] The spacing factor must be finite and >= 0 "
              "(got %g); keeping %g.\n",
              getClassName().c_str(),
              factor,
              parameters_.spacing_factor);
    return;
  }
  parameters_.spacing_factor = factor;
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::setGapAngle(double angle)
{
  if (!(angle >= 0.0 && angle < M_PI)) {
    PCL_ERROR("[pcl::%s::setGapAngle] The gap angle must be in [0, pi) (got %g); "
              "keeping %g.\n",
              getClassName().c_str(),
              angle,
              parameters_.gap_angle);
    return;
  }
  parameters_.gap_angle = angle;
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
void
CoConeBoundary<PointInT>::setTilePoints(std::size_t tile_points)
{
  if (tile_points > 0 && tile_points < cocone::MINIMUM_TILE_POINTS) {
    PCL_ERROR("[pcl::%s::setTilePoints] A tile holds 0 (one piece) or at least %zu "
              "points (got %zu); keeping %zu.\n",
              getClassName().c_str(),
              cocone::MINIMUM_TILE_POINTS,
              tile_points,
              tiling_.tile_points);
    return;
  }
  tiling_.tile_points = tile_points;
}

template <typename PointInT>
bool
CoConeBoundary<PointInT>::compute(cocone::Stages stages, const char* caller)
{
  result_ = cocone::Result();
  timings_ = cocone::Timings();
  cloud_size_ = input_->size();
  std::vector<Eigen::Vector3d> points;
  ids_.clear();
  points.reserve(indices_->size());
  ids_.reserve(indices_->size());
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
    ids_.push_back(static_cast<int>(i));
  }

  const std::size_t count = points.size();
  result_ = stages == cocone::Stages::RECONSTRUCTION && tiling_.tile_points > 0
                ? cocone::runTiled(std::move(points), parameters_, tiling_, ids_)
                : cocone::run(std::move(points), parameters_, stages, ids_);
  timings_ = result_.timings;
  if (!result_.error.empty()) {
    PCL_ERROR("[pcl::%s::%s] No result: %s.\n",
              getClassName().c_str(),
              caller,
              result_.error.c_str());
    result_ = cocone::Result();
    return false;
  }
  PCL_DEBUG("[pcl::%s::%s] %zu points, %zu unique; timings (ms): unique %.1f, "
            "Delaunay %.1f, Voronoi %.1f, noise %.1f, boundary %.1f, reconstruction "
            "%.1f; rho %.3f; noise level %.3f%s, %zu outliers; %zu boundary points, "
            "%zu triangles.\n",
            getClassName().c_str(),
            caller,
            count,
            result_.vertices,
            timings_.unique,
            timings_.delaunay,
            timings_.voronoi,
            timings_.noise,
            timings_.boundary,
            timings_.reconstruction,
            result_.ratio,
            result_.noise_level,
            result_.smoothed ? " (smoothed)" : "",
            result_.outlier_indices.size(),
            result_.boundary_indices.size(),
            result_.triangles.size());
  if (stages == cocone::Stages::RECONSTRUCTION && result_.triangles.empty() &&
      parameters_.boundary_detection && !result_.boundary_indices.empty())
    PCL_WARN("[pcl::%s::%s] No point reads as well sampled (%zu undersampled): the "
             "mesh is empty. The cloud is too coarse or too noisy for the flatness "
             "test; a larger normal angle (setNormalAngle ()) or no boundary "
             "detection (setBoundaryDetection (false)) meshes it.\n",
             getClassName().c_str(),
             caller,
             result_.boundary_indices.size());
  return true;
}

template <typename PointInT>
bool
CoConeBoundary<PointInT>::detectBoundary(pcl::PointIndices& boundary)
{
  boundary.indices.clear();
  result_ = cocone::Result();
  if (!input_) {
    PCL_ERROR("[pcl::%s::detectBoundary] No input cloud was set.\n",
              getClassName().c_str());
    return false;
  }
  boundary.header = input_->header;
  if (!initCompute())
    return false;
  const bool ok = compute(cocone::Stages::BOUNDARY_DETECTION, "detectBoundary");
  deinitCompute();
  getBoundaryPointIndices(boundary);
  return ok;
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::getBoundaryPointIndices(pcl::PointIndices& boundary) const
{
  toPointIndices(result_.boundary_indices, boundary);
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::getOutlierIndices(pcl::PointIndices& outliers) const
{
  toPointIndices(result_.outlier_indices, outliers);
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::toPointIndices(const std::vector<int>& ids,
                                         pcl::PointIndices& out) const
{
  if (input_)
    out.header = input_->header;
  out.indices = pcl::Indices(ids);
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::getPointNoiseLevels(std::vector<float>& levels) const
{
  levels.assign(cloud_size_, std::numeric_limits<float>::quiet_NaN());
  // point_noise is indexed like the points passed to the core (ids_); empty without
  // noise handling.
  if (result_.point_noise.size() != ids_.size())
    return;
  for (std::size_t i = 0; i < ids_.size(); ++i)
    levels[ids_[i]] = result_.point_noise[i];
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::getSmoothedCloud(pcl::PointCloud<pcl::PointXYZ>& cloud) const
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cloud.clear();
  cloud.resize(cloud_size_, pcl::PointXYZ(nan, nan, nan));
  cloud.is_dense = false;
  if (input_) {
    cloud.header = input_->header;
    if (input_->size() == cloud_size_ && input_->height > 1) {
      cloud.width = input_->width;
      cloud.height = input_->height;
    }
  }
  if (result_.vertex_of_input.size() != ids_.size())
    return;
  const bool from_input = !result_.smoothed && input_ && input_->size() == cloud_size_;
  for (std::size_t i = 0; i < ids_.size(); ++i) {
    const int v = result_.vertex_of_input[i];
    // v < 0: not finite (-1) or an outlier (-2).
    if (v < 0 || static_cast<std::size_t>(v) >= result_.positions.size())
      continue;
    if (from_input) { // the input position, exactly
      const PointInT& p = (*input_)[ids_[i]];
      cloud[ids_[i]] = pcl::PointXYZ(p.x, p.y, p.z);
      continue;
    }
    const Eigen::Vector3d q = result_.positions[v] + result_.offset;
    cloud[ids_[i]] = pcl::PointXYZ(static_cast<float>(q.x()),
                                   static_cast<float>(q.y()),
                                   static_cast<float>(q.z()));
  }
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::getBoundaryLoops(std::vector<pcl::Vertices>& loops) const
{
  toVertices(result_.border_loops, loops);
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::getFilledHoles(std::vector<pcl::Vertices>& rims) const
{
  toVertices(result_.filled_holes, rims);
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::toVertices(const std::vector<std::vector<int>>& loops,
                                     std::vector<pcl::Vertices>& out)
{
  out.clear();
  out.reserve(loops.size());
  for (const auto& loop : loops) {
    pcl::Vertices v;
    v.vertices.assign(loop.begin(), loop.end());
    out.push_back(std::move(v));
  }
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::getPointNormals(pcl::PointCloud<pcl::Normal>& normals) const
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  normals.clear();
  normals.resize(cloud_size_, pcl::Normal(nan, nan, nan, nan));
  normals.is_dense = false;
  if (input_)
    normals.header = input_->header;
  if (result_.normals.empty())
    return;
  for (std::size_t i = 0; i < ids_.size(); ++i) {
    const int v = result_.vertex_of_input[i];
    // v < 0: not finite (-1) or an outlier (-2), in no triangle.
    if (v < 0 || static_cast<std::size_t>(v) >= result_.normals.size() ||
        !std::isfinite(result_.normals[v].x()))
      continue;
    const Eigen::Vector3d& n = result_.normals[v];
    normals[ids_[i]] = pcl::Normal(static_cast<float>(n.x()),
                                   static_cast<float>(n.y()),
                                   static_cast<float>(n.z()),
                                   0.0f);
  }
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::fillPolygons(std::vector<pcl::Vertices>& polygons) const
{
  // The vertices refineFilledHoles() added follow the input cloud's points.
  const int first_added =
      ids_.empty() ? 0 : *std::max_element(ids_.begin(), ids_.end()) + 1;
  const auto index = [&](int id) {
    return id < first_added ? id : static_cast<int>(cloud_size_) + (id - first_added);
  };
  polygons.reserve(polygons.size() + result_.polygons.size());
  for (const auto& t : result_.polygons) {
    pcl::Vertices v;
    v.vertices = {index(t[0]), index(t[1]), index(t[2])};
    polygons.push_back(std::move(v));
  }
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::appendAddedPoints(pcl::PointCloud<PointInT>& points) const
{
  const std::size_t added = result_.added_vertices;
  if (added == 0)
    return;
  const std::size_t first = result_.positions.size() - added;
  for (std::size_t k = 0; k < added; ++k) {
    const Eigen::Vector3d p = result_.positions[first + k] + result_.offset;
    PointInT q;
    q.x = static_cast<float>(p.x());
    q.y = static_cast<float>(p.y());
    q.z = static_cast<float>(p.z());
    points.push_back(q); // an organized cloud becomes one row
  }
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::reconstruct(pcl::PolygonMesh& output)
{
  if (!input_) {
    PCL_ERROR("[pcl::%s::reconstruct] No input cloud was set.\n",
              getClassName().c_str());
    result_ = cocone::Result();
    output = pcl::PolygonMesh();
    return;
  }
  SurfaceReconstruction<PointInT>::reconstruct(output);
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::reconstruct(pcl::PointCloud<PointInT>& points,
                                      std::vector<pcl::Vertices>& polygons)
{
  if (!input_) {
    PCL_ERROR("[pcl::%s::reconstruct] No input cloud was set.\n",
              getClassName().c_str());
    result_ = cocone::Result();
    points.clear();
    polygons.clear();
    return;
  }
  SurfaceReconstruction<PointInT>::reconstruct(points, polygons);
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::performReconstruction(pcl::PolygonMesh& output)
{
  output.polygons.clear();
  if (!compute(cocone::Stages::RECONSTRUCTION, "reconstruct")) {
    // A defined empty result: no cloud, no polygons.
    output.cloud = pcl::PCLPointCloud2();
    output.cloud.header = input_->header;
    return;
  }
  if (result_.added_vertices > 0) {
    pcl::PointCloud<PointInT> points = *input_;
    appendAddedPoints(points);
    pcl::toPCLPointCloud2(points, output.cloud);
  }
  fillPolygons(output.polygons);
}

template <typename PointInT>
void
CoConeBoundary<PointInT>::performReconstruction(pcl::PointCloud<PointInT>& points,
                                                std::vector<pcl::Vertices>& polygons)
{
  polygons.clear();
  if (!compute(cocone::Stages::RECONSTRUCTION, "reconstruct")) {
    points.clear();
    points.header = input_->header;
    return;
  }
  // The polygons index the whole input cloud, as in the PolygonMesh overload.
  points = *input_;
  appendAddedPoints(points);
  fillPolygons(polygons);
}

} // namespace pcl

#define PCL_INSTANTIATE_CoConeBoundary(T)                                              \
  template class PCL_EXPORTS pcl::CoConeBoundary<T>;

#endif // PCL_SURFACE_IMPL_COCONE_BOUNDARY_HPP_
