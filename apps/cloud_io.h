/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * File input and output of the command-line tool.
 */

#pragma once

#include <pcl/PCLPointCloud2.h>
#include <pcl/PolygonMesh.h>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace cocone_app {

/** The keywords a PCD header may hold (the ones PCL writes and reads). */
const std::set<std::string>&
pcdHeaderKeys();

/** Lower-case extension of a path, without the dot ("" if none). */
std::string
extension(const std::string& path);

/** Whether the extension names a readable point cloud format. */
bool
isInputFormat(const std::string& ext);

/** Whether the extension names a writable mesh format. */
bool
isMeshFormat(const std::string& ext);

/** Read an Object File Format mesh (.off, as CGAL and Geomview write it): its
 * vertices, and if \a faces is given its faces as triangles (polygons as fans) over
 * them, numbered from 0. The header may be OFF, COFF, NOFF or CNOFF (the colours and
 * normals after x y z are skipped), its counts on its own line or the next; '#'
 * starts a comment. Binary OFF and higher dimensions are refused. False, and why
 * in \a error, if the file is not such a mesh or a face names a missing vertex. */
bool
readOff(const std::string& path,
        std::vector<Eigen::Vector3d>& vertices,
        std::vector<std::array<int, 3>>* faces,
        std::string& error);

/** Read the faces of a mesh file, .obj (Wavefront: polygons over its vertex lines,
 * numbered from 1, negative indices counting back from the last vertex read) or .off
 * (readOff()), as triangles (polygons as fans) over its vertices numbered from 0.
 * False, and why in \a error, if the file cannot be read or a face names a missing
 * vertex. */
bool
readFaces(const std::string& path,
          std::vector<std::array<int, 3>>& faces,
          std::string& error);

/** Read a point cloud (.pcd, .ply, .obj, .off, .xyz/.txt/.pts, or the registered range
 * scans a Stanford .conf lists, merged); on failure return false and say why in
 * \a error. Only the vertices of a mesh file are read. */
bool
readCloud(const std::string& path, pcl::PCLPointCloud2& cloud, std::string& error);

/** The x, y, z fields of every point in double precision (float or double fields). */
bool
extractXYZ(const pcl::PCLPointCloud2& cloud,
           std::vector<Eigen::Vector3d>& xyz,
           std::string& error);

/** Append points with the given x, y, z (in the fields' own types) and every other
 * field zero; an organized cloud becomes one row. The cloud has x, y, z (as
 * extractXYZ() checks). */
void
appendPoints(pcl::PCLPointCloud2& cloud, const std::vector<Eigen::Vector3d>& xyz);

/** Set a FLOAT32 field per point: overwrite it if the cloud has it, else append it. */
void
setFloatField(pcl::PCLPointCloud2& cloud,
              const std::string& name,
              const std::vector<float>& values);

/** Append a field of 4-byte values (UINT32 or FLOAT32 bit patterns) per point. */
void
appendField(pcl::PCLPointCloud2& cloud,
            const std::string& name,
            std::uint8_t datatype,
            const std::vector<std::uint32_t>& values);

/** Whether the cloud has a colour field (rgb or rgba). */
bool
hasColour(const pcl::PCLPointCloud2& cloud);

/** A temporary name next to \a path with the same extension (a hidden file named
 * for the process): written there and renamed into place, an output is never seen
 * half written. */
std::string
temporaryName(const std::string& path);

/** Parse an unsigned integer token strictly: digits only, at most 12 (a header's
 * count; a sign, a fraction or an overflow is not a count). */
bool
parseCount(const std::string& token, std::size_t& value);

/** Check before any work that a file can be created at \a path. */
bool
checkWritable(const std::string& path, std::string& error);

/** Write a mesh by extension (.vtk, .ply, .obj, .stl) or a cloud (.pcd) through a
 * temporary file renamed into place: a failure leaves no partial file. */
bool
writeMesh(const std::string& path, const pcl::PolygonMesh& mesh, std::string& error);

bool
writeCloud(const std::string& path,
           const pcl::PCLPointCloud2& cloud,
           std::string& error);

/** Write a text file the same way. */
bool
writeText(const std::string& path, const std::string& text, std::string& error);

} // namespace cocone_app
