/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Streaming file input and output of the command-line tool's out-of-core mode: a
 * cloud larger than the memory is read in chunks, the mesh written as it comes.
 */

#pragma once

#include <pcl/surface/cocone/out_of_core.h>

#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace cocone_app {

/** Stream the x, y, z of a binary point cloud file without loading it: a .ply
 * (binary_little_endian or binary_big_endian; the vertex element's x, y, z as float
 * or double, its other scalar properties skipped) or a .pcd (DATA binary; x, y, z of
 * TYPE F, SIZE 4 or 8, COUNT 1). Text and compressed files cannot be read in place
 * by offset, so they are refused rather than loaded.
 *
 * The header is checked against the file's size when opening: a truncated file is
 * an error here, not a short pass later. Points are passed through as stored (NaN
 * included), converted to double.
 *
 * \param[in] path the file
 * \param[out] points the number of points in the file
 * \param[out] error why the file cannot be streamed
 * \return the source, positioned at the first point; nullptr on failure */
std::unique_ptr<pcl::cocone::PointSource>
openPointStream(const std::string& path, std::size_t& points, std::string& error);

/** \brief A mesh written to a binary little-endian PLY as runOutOfCore() produces
 * it: vertices (float x, y, z, nx, ny, nz), then faces (list uchar int
 * vertex_indices), each appended as it comes, so the mesh is never held in memory.
 *
 * The file is written under a temporary name in the same directory and renamed into
 * place by end() once the announced counts were met: a failure, or a writer
 * destroyed before end(), leaves no partial file (as writeMesh()). Coordinates are
 * single precision, as the PLY that PCL and most viewers read. */
class PlyMeshWriter : public pcl::cocone::MeshSink {
public:
  explicit PlyMeshWriter(std::string path);
  ~PlyMeshWriter() override;
  PlyMeshWriter(const PlyMeshWriter&) = delete;
  PlyMeshWriter&
  operator=(const PlyMeshWriter&) = delete;

  /** Create the temporary file and write the header with the counts. */
  bool
  begin(std::size_t vertices, std::size_t triangles, std::string& error) override;

  /** Append vertices; \a normals has one per position (NaN where none). More than
   * announced, or after a triangle, is an error. The ids are not written: the PLY
   * has no place that its readers know for them. */
  bool
  addVertices(const std::vector<Eigen::Vector3d>& positions,
              const std::vector<Eigen::Vector3d>& normals,
              const std::vector<int>& ids,
              std::string& error) override;

  /** Append triangles; an index outside the announced vertices, or more triangles
   * than announced, is an error (the file would not be a valid mesh). */
  bool
  addTriangles(const std::vector<pcl::cocone::Triangle>& triangles,
               std::string& error) override;

  /** Check that exactly the announced counts were written, flush, close and rename
   * the file into place. */
  bool
  end(std::string& error) override;

private:
  /** Record a failure: the temporary file is removed, later calls fail. */
  bool
  fail(const std::string& why, std::string& error);

  /** Append bytes to the buffer, writing it out when full. */
  bool
  put(const void* bytes, std::size_t size);

  /** Write the buffer out. */
  bool
  flush();

  std::string path_, temporary_;
  std::FILE* file_ = nullptr;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  std::size_t vertices_ = 0, triangles_ = 0;
  std::size_t vertices_written_ = 0, triangles_written_ = 0;
  bool begun_ = false, failed_ = false, ended_ = false;
};

} // namespace cocone_app
