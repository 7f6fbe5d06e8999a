/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include "cloud_io.h"

#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/io/obj_io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/io/vtk_io.h>
#include <pcl/io/vtk_lib_io.h>
#include <pcl/PCLPointField.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace cocone_app {

namespace {

bool
isFile(const std::string& path)
{
  std::ifstream f(path, std::ios::binary);
  return f.good() && f.peek() != std::ifstream::traits_type::eof();
}

std::string
directoryOf(const std::string& path)
{
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos)
    return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

/** A temporary name next to \a path with the same extension. */
std::string
temporaryName(const std::string& path)
{
  const auto slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  return dir + ".partial-" + std::to_string(::getpid()) + "-" + name;
}

/** Write through a temporary file renamed into place: a failure leaves no partial
 * file. PCL's writers print their own complaints; the tool prints one line instead. */
template <typename Write>
bool
writeAtomically(const std::string& path, const Write& write, std::string& error)
{
  const std::string tmp = temporaryName(path);
  const auto verbosity = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  const bool written = write(tmp);
  pcl::console::setVerbosityLevel(verbosity);
  if (!written || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    error = "cannot write '" + path + "'";
    return false;
  }
  return true;
}

/** Read whitespace-separated x y z lines; '#' starts a comment. */
bool
readText(const std::string& path, pcl::PCLPointCloud2& cloud, std::string& error)
{
  std::ifstream in(path);
  std::vector<float> xyz;
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto hash = line.find('#');
    if (hash != std::string::npos)
      line.resize(hash);
    std::istringstream fields(line);
    double v[3];
    int n = 0;
    while (n < 3 && fields >> v[n])
      ++n;
    if (n == 0 && fields.eof())
      continue; // blank line
    if (n < 3) {
      error = "line " + std::to_string(number) + " is not 'x y z'";
      return false;
    }
    for (const double c : v)
      xyz.push_back(static_cast<float>(c));
  }
  if (xyz.empty()) {
    error = "no points";
    return false;
  }
  cloud = pcl::PCLPointCloud2();
  for (int k = 0; k < 3; ++k) {
    pcl::PCLPointField f;
    f.name = std::string(1, "xyz"[k]);
    f.offset = 4 * k;
    f.datatype = pcl::PCLPointField::FLOAT32;
    f.count = 1;
    cloud.fields.push_back(f);
  }
  cloud.point_step = 12;
  cloud.width = static_cast<std::uint32_t>(xyz.size() / 3);
  cloud.height = 1;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = false;
  cloud.data.resize(xyz.size() * sizeof(float));
  std::memcpy(cloud.data.data(), xyz.data(), cloud.data.size());
  return true;
}

} // namespace

std::string
extension(const std::string& path)
{
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) {
    return static_cast<char>(std::tolower(c));
  });
  return ext;
}

bool
isInputFormat(const std::string& ext)
{
  return ext == "pcd" || ext == "ply" || ext == "obj" || ext == "xyz" || ext == "txt" ||
         ext == "pts";
}

bool
isMeshFormat(const std::string& ext)
{
  return ext == "vtk" || ext == "ply" || ext == "obj" || ext == "stl";
}

bool
readCloud(const std::string& path, pcl::PCLPointCloud2& cloud, std::string& error)
{
  const std::string ext = extension(path);
  if (!isInputFormat(ext)) {
    error = "unknown input format '" + ext + "' (use .pcd, .ply, .obj, .xyz, .txt)";
    return false;
  }
  if (!isFile(path)) {
    error = "cannot read '" + path + "' (missing, unreadable or empty)";
    return false;
  }
  // PCL's readers print their own complaints; the tool prints one line instead.
  const auto verbosity = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  int status = 0;
  bool ok = true;
  try {
    if (ext == "pcd") {
      // PCL's reader crashes on some malformed files whose header it rejects: read
      // the header first.
      pcl::PCDReader reader;
      Eigen::Vector4f origin;
      Eigen::Quaternionf orientation;
      int version = 0, type = 0;
      unsigned int data_start = 0;
      status = reader.readHeader(
          path, cloud, origin, orientation, version, type, data_start);
      if (status >= 0 && (cloud.fields.empty() || cloud.point_step == 0))
        status = -1;
      if (status >= 0)
        status = reader.read(path, cloud);
    }
    else if (ext == "ply")
      status = pcl::io::loadPLYFile(path, cloud);
    else if (ext == "obj")
      status = pcl::io::loadOBJFile(path, cloud);
    else
      ok = readText(path, cloud, error);
  }
  catch (const std::exception& e) {
    status = -1;
  }
  pcl::console::setVerbosityLevel(verbosity);
  if (!ok) {
    error = "cannot read '" + path + "': " + error;
    return false;
  }
  if (status < 0) {
    error = "cannot read '" + path + "': not a valid ." + ext + " file";
    return false;
  }
  const std::size_t points = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (points == 0 || cloud.point_step == 0 ||
      cloud.data.size() < points * cloud.point_step) {
    error = "cannot read '" + path + "': no points";
    return false;
  }
  return true;
}

bool
extractXYZ(const pcl::PCLPointCloud2& cloud,
           std::vector<Eigen::Vector3d>& xyz,
           std::string& error)
{
  int index[3];
  for (int k = 0; k < 3; ++k) {
    const std::string name(1, "xyz"[k]);
    index[k] = pcl::getFieldIndex(cloud, name);
    if (index[k] < 0) {
      error = "the cloud has no '" + name + "' field";
      return false;
    }
    const auto& f = cloud.fields[index[k]];
    if (f.datatype != pcl::PCLPointField::FLOAT32 &&
        f.datatype != pcl::PCLPointField::FLOAT64) {
      error = "field '" + name + "' is not a float or double";
      return false;
    }
    const std::size_t size = f.datatype == pcl::PCLPointField::FLOAT32 ? 4 : 8;
    if (f.offset + size > cloud.point_step) {
      error = "field '" + name + "' lies outside the point";
      return false;
    }
  }
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  xyz.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = cloud.data.data() + i * cloud.point_step;
    for (int k = 0; k < 3; ++k) {
      const auto& f = cloud.fields[index[k]];
      if (f.datatype == pcl::PCLPointField::FLOAT32) {
        float v;
        std::memcpy(&v, p + f.offset, 4);
        xyz[i][k] = v;
      }
      else
        std::memcpy(&xyz[i][k], p + f.offset, 8);
    }
  }
  return true;
}

void
appendField(pcl::PCLPointCloud2& cloud,
            const std::string& name,
            std::uint8_t datatype,
            const std::vector<std::uint32_t>& values)
{
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  const std::uint32_t old_step = cloud.point_step;
  pcl::PCLPointField f;
  f.name = name;
  f.offset = old_step;
  f.datatype = datatype;
  f.count = 1;
  cloud.fields.push_back(f);
  std::vector<std::uint8_t> data(n * (old_step + 4));
  for (std::size_t i = 0; i < n; ++i) {
    std::memcpy(&data[i * (old_step + 4)], &cloud.data[i * old_step], old_step);
    std::memcpy(&data[i * (old_step + 4) + old_step], &values[i], 4);
  }
  cloud.data.swap(data);
  cloud.point_step = old_step + 4;
  cloud.row_step = cloud.point_step * cloud.width;
}

void
setFloatField(pcl::PCLPointCloud2& cloud,
              const std::string& name,
              const std::vector<float>& values)
{
  const int idx = pcl::getFieldIndex(cloud, name);
  if (idx >= 0 && cloud.fields[idx].datatype == pcl::PCLPointField::FLOAT32) {
    const std::size_t offset = cloud.fields[idx].offset;
    for (std::size_t i = 0; i < values.size(); ++i)
      std::memcpy(&cloud.data[i * cloud.point_step + offset], &values[i], 4);
    return;
  }
  std::vector<std::uint32_t> bits(values.size());
  std::memcpy(bits.data(), values.data(), 4 * values.size());
  appendField(cloud, name, pcl::PCLPointField::FLOAT32, bits);
}

bool
hasColour(const pcl::PCLPointCloud2& cloud)
{
  return pcl::getFieldIndex(cloud, "rgb") >= 0 ||
         pcl::getFieldIndex(cloud, "rgba") >= 0;
}

bool
checkWritable(const std::string& path, std::string& error)
{
  const std::string dir = directoryOf(path);
  if (::access(dir.c_str(), W_OK) != 0) {
    error =
        "cannot write '" + path + "': directory '" + dir + "' " + std::strerror(errno);
    return false;
  }
  return true;
}

bool
writeMesh(const std::string& path, const pcl::PolygonMesh& mesh, std::string& error)
{
  const std::string ext = extension(path);
  if (!isMeshFormat(ext)) {
    error = "unknown output format '" + ext + "' (use .vtk, .ply, .obj or .stl)";
    return false;
  }
  return writeAtomically(
      path,
      [&](const std::string& tmp) {
        if (ext == "vtk")
          return pcl::io::saveVTKFile(tmp, mesh, 10) >= 0;
        if (ext == "ply")
          return pcl::io::savePLYFileBinary(tmp, mesh) >= 0;
        if (ext == "obj")
          return pcl::io::saveOBJFile(tmp, mesh, 10) >= 0;
        return pcl::io::savePolygonFileSTL(tmp, mesh, true);
      },
      error);
}

bool
writeCloud(const std::string& path,
           const pcl::PCLPointCloud2& cloud,
           std::string& error)
{
  if (extension(path) != "pcd") {
    error = "'" + path + "' must be a .pcd file";
    return false;
  }
  return writeAtomically(
      path,
      [&](const std::string& tmp) {
        return pcl::io::savePCDFile(tmp,
                                    cloud,
                                    Eigen::Vector4f::Zero(),
                                    Eigen::Quaternionf::Identity(),
                                    true) >= 0;
      },
      error);
}

bool
writeText(const std::string& path, const std::string& text, std::string& error)
{
  return writeAtomically(
      path,
      [&](const std::string& tmp) {
        std::ofstream f(tmp);
        f << text;
        return static_cast<bool>(f);
      },
      error);
}

} // namespace cocone_app
