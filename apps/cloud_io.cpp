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
#include <pcl/conversions.h>
#include <pcl/PCLPointField.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace cocone_app {

std::string
temporaryName(const std::string& path)
{
  const auto slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  return dir + ".partial-" + std::to_string(::getpid()) + "-" + name;
}

bool
parseCount(const std::string& token, std::size_t& value)
{
  if (token.empty() || token.size() > 12 ||
      token.find_first_not_of("0123456789") != std::string::npos)
    return false;
  value = std::stoull(token);
  return true;
}

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

std::size_t
fileSize(const std::string& path)
{
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  return f ? static_cast<std::size_t>(f.tellg()) : 0;
}

} // namespace

const std::set<std::string>&
pcdHeaderKeys()
{
  static const std::set<std::string> keys{"VERSION",
                                          "FIELDS",
                                          "COLUMNS",
                                          "SIZE",
                                          "TYPE",
                                          "COUNT",
                                          "WIDTH",
                                          "HEIGHT",
                                          "VIEWPOINT",
                                          "POINTS",
                                          "DATA"};
  return keys;
}

namespace {

/** A PCD header PCL's reader can be trusted with: consistent FIELDS, SIZE, TYPE and
 * COUNT, a known DATA kind, and no more points than the file can hold (compressed
 * data shrinks by less than 100 times). */
bool
checkPcdHeader(const std::string& path, std::string& error)
{
  const std::set<std::string>& keys = pcdHeaderKeys();
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> fields, sizes, types, counts;
  std::size_t width = 0, height = 1, points = 0;
  bool have_width = false, have_points = false;
  std::string line, data;
  std::set<std::string> seen;
  for (int lines = 0; lines < 64 && std::getline(in, line); ++lines) {
    if (line.size() > 65536)
      break;
    // A header is plain text: PCL's parser and its data offset disagree otherwise.
    if (std::any_of(line.begin(), line.end(), [](char c) {
          return (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r') ||
                 static_cast<unsigned char>(c) >= 0x7f;
        }))
      break;
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    if (line.empty() || std::isspace(static_cast<unsigned char>(line[0])))
      break; // PCL's parser reads such a line differently
    std::istringstream tokens(line);
    std::string key, token;
    tokens >> key;
    std::vector<std::string> values;
    while (tokens >> token)
      values.push_back(token);
    if (key.empty() || key[0] == '#')
      continue;
    // Only the keys of the format, each once: PCL's parser matches others loosely.
    if (!keys.count(key) || !seen.insert(key).second)
      break;
    if (key == "FIELDS" || key == "COLUMNS")
      fields = values;
    else if (key == "SIZE")
      sizes = values;
    else if (key == "TYPE")
      types = values;
    else if (key == "COUNT")
      counts = values;
    else if (key == "WIDTH" &&
             !(have_width = values.size() == 1 && parseCount(values[0], width)))
      break;
    else if (key == "HEIGHT" && !(values.size() == 1 && parseCount(values[0], height)))
      break;
    else if (key == "POINTS" &&
             !(have_points = values.size() == 1 && parseCount(values[0], points)))
      break;
    else if (key == "VIEWPOINT" && values.size() != 7)
      break;
    else if (key == "DATA") {
      data = values.empty() ? "" : values[0];
      break;
    }
  }
  const std::size_t data_start = in ? static_cast<std::size_t>(in.tellg()) : 0;
  error = "not a valid .pcd file (header)";
  if (fields.empty() || sizes.size() != fields.size() ||
      types.size() != fields.size() ||
      (!counts.empty() && counts.size() != fields.size()) || !have_width ||
      (data != "ascii" && data != "binary" && data != "binary_compressed"))
    return false;
  std::size_t step = 0;
  for (std::size_t k = 0; k < fields.size(); ++k) {
    std::size_t size = 0, count = 1;
    if (!parseCount(sizes[k], size) ||
        (size != 1 && size != 2 && size != 4 && size != 8))
      return false;
    if ((types[k] != "I" && types[k] != "U" && types[k] != "F") ||
        (types[k] == "F" && size < 4))
      return false;
    if (!counts.empty() &&
        (!parseCount(counts[k], count) || count == 0 || count > 65536))
      return false;
    step += size * count;
  }
  const std::size_t n = width * height, file_size = fileSize(path);
  if (n == 0 || step > 65536 || (have_points && points != n) ||
      n > 100 * (file_size + 1) || data_start == 0 || data_start > file_size)
    return false;
  if (data == "binary" && file_size - data_start < n * step)
    return false; // truncated
  if (data == "binary_compressed") {
    std::uint32_t sizes_of[2] = {0, 0}; // compressed, uncompressed
    in.read(reinterpret_cast<char*>(sizes_of), sizeof(sizes_of));
    if (!in || sizes_of[1] != n * step || sizes_of[0] > file_size - data_start - 8)
      return false;
  }
  // PCL's parser reads on after DATA, skipping empty lines and comments, while the
  // first word of a line starts like a key; a key there declares the fields again
  // behind the reader's back (a use after free in PCL 1.13). Refuse such data.
  std::ifstream rest(path, std::ios::binary);
  rest.seekg(static_cast<std::streamoff>(data_start));
  char buffer[256];
  for (int lines = 0; lines < 64 && rest.good(); ++lines) {
    rest.getline(buffer, sizeof(buffer));
    if (rest.fail() && !rest.eof()) { // a longer line: its start is enough
      rest.clear();
      rest.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    }
    std::istringstream tokens(buffer);
    std::string first;
    tokens >> first;
    if (buffer[0] == '\0' || (!first.empty() && first[0] == '#'))
      continue;
    for (const auto& key : keys)
      if (first.compare(0, key.size(), key) == 0)
        return false;
    break;
  }
  error.clear();
  return true;
}

/** A PLY header PCL's reader can be trusted with: a known format, elements with
 * counts the file can hold, properties of known types. */
bool
checkPlyHeader(const std::string& path, std::string& error)
{
  static const std::set<std::string> TYPES{"char",
                                           "uchar",
                                           "short",
                                           "ushort",
                                           "int",
                                           "uint",
                                           "float",
                                           "double",
                                           "int8",
                                           "uint8",
                                           "int16",
                                           "uint16",
                                           "int32",
                                           "uint32",
                                           "float32",
                                           "float64"};
  std::ifstream in(path, std::ios::binary);
  std::string line;
  error = "not a valid .ply file (header)";
  if (!std::getline(in, line) || (line != "ply" && line != "ply\r"))
    return false;
  const std::size_t file_size = fileSize(path);
  std::size_t elements = 0;
  bool format = false;
  for (int lines = 0; lines < 4096 && std::getline(in, line); ++lines) {
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    std::istringstream tokens(line);
    std::string key;
    tokens >> key;
    std::vector<std::string> values;
    for (std::string t; tokens >> t;)
      values.push_back(t);
    if (key == "end_header") {
      if (!format)
        return false;
      error.clear();
      return true;
    }
    if (key == "format")
      format = values.size() == 2 &&
               (values[0] == "ascii" || values[0] == "binary_little_endian" ||
                values[0] == "binary_big_endian");
    else if (key == "element") {
      std::size_t count = 0;
      if (values.size() != 2 || !parseCount(values[1], count))
        return false;
      elements += count;
      if (elements > 100 * (file_size + 1))
        return false;
    }
    else if (key == "property") {
      const bool list = !values.empty() && values[0] == "list";
      if (list
              ? values.size() != 4 || !TYPES.count(values[1]) || !TYPES.count(values[2])
              : values.size() != 2 || !TYPES.count(values[0]))
        return false;
    }
    else if (key != "comment" && key != "obj_info")
      return false;
  }
  return false;
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

/** \a cloud as the points \a xyz (x, y, z as floats). */
void
xyzCloud(const std::vector<Eigen::Vector3d>& xyz, pcl::PCLPointCloud2& cloud)
{
  pcl::PointCloud<pcl::PointXYZ> points;
  for (const Eigen::Vector3d& x : xyz)
    points.push_back(pcl::PointXYZ(static_cast<float>(x.x()),
                                   static_cast<float>(x.y()),
                                   static_cast<float>(x.z())));
  points.is_dense = false;
  pcl::toPCLPointCloud2(points, cloud);
}

/** The next line of \a in without its comment ('#' to the end), \a number counting
 * the lines read; false at the end. */
bool
readDataLine(std::istream& in, std::string& line, std::size_t& number)
{
  if (!std::getline(in, line))
    return false;
  ++number;
  const auto hash = line.find('#');
  if (hash != std::string::npos)
    line.resize(hash);
  return true;
}

/** A polygon's corners as a fan of triangles from its first, appended to \a out. */
void
appendFan(const std::vector<int>& polygon, std::vector<std::array<int, 3>>& out)
{
  for (std::size_t k = 2; k < polygon.size(); ++k)
    out.push_back({polygon[0], polygon[k - 1], polygon[k]});
}

/** Read whitespace-separated x y z lines; '#' starts a comment. With \a obj, only
 * the vertex lines ("v x y z") of a Wavefront file count. PCL's OBJ reader crashes on
 * a vertex line with fewer than three numbers, so OBJ files are read here too. */
bool
readText(const std::string& path,
         pcl::PCLPointCloud2& cloud,
         std::string& error,
         bool obj = false)
{
  std::ifstream in(path);
  std::vector<Eigen::Vector3d> xyz;
  std::string line;
  std::size_t number = 0;
  while (readDataLine(in, line, number)) {
    std::istringstream fields(line);
    if (obj) {
      std::string tag;
      if (!(fields >> tag) || tag != "v")
        continue; // faces, normals, texture coordinates, groups, ...
    }
    double v[3];
    int n = 0;
    while (n < 3 && fields >> v[n])
      ++n;
    if (n == 0 && fields.eof())
      continue; // blank line
    if (n < 3) {
      error = "line " + std::to_string(number) +
              (obj ? " is not 'v x y z'" : " is not 'x y z'");
      return false;
    }
    xyz.emplace_back(v[0], v[1], v[2]);
  }
  if (xyz.empty()) {
    error = "no points";
    return false;
  }
  xyzCloud(xyz, cloud);
  return true;
}

} // namespace

bool
readOff(const std::string& path,
        std::vector<Eigen::Vector3d>& vertices,
        std::vector<std::array<int, 3>>* faces,
        std::string& error)
{
  std::ifstream in(path);
  if (!in) {
    error = "cannot read '" + path + "'";
    return false;
  }
  vertices.clear();
  std::string line;
  std::size_t number = 0;
  // The next line that is not blank or a comment, as a stream of its fields.
  const auto next = [&](std::istringstream& fields) {
    while (readDataLine(in, line, number))
      if (line.find_first_not_of(" \t\r") != std::string::npos) {
        fields.clear();
        fields.str(line);
        return true;
      }
    return false;
  };
  const auto fail = [&](const std::string& why) {
    error = (number > 0 ? "line " + std::to_string(number) + ": " : "") + why;
    return false;
  };
  std::istringstream fields;
  std::string header;
  if (!next(fields) || !(fields >> header))
    return fail("no OFF header");
  // [ST][C][N]OFF: texture coordinates, colours and normals follow x y z on a
  // vertex's line and are skipped (4OFF and nOFF, other dimensions, are refused).
  const std::size_t off = header.rfind("OFF");
  const std::string prefix = header.substr(0, off);
  if (off == std::string::npos || off + 3 != header.size() ||
      prefix.find_first_not_of("STCN") != std::string::npos)
    return fail("not a 3D OFF header: '" + header + "'");
  // The counts (vertices, faces, edges) follow on the header's line or the next.
  std::vector<std::string> tokens;
  std::string token;
  while (fields >> token)
    tokens.push_back(token);
  if (!tokens.empty() && tokens[0] == "BINARY")
    return fail("binary OFF is not read");
  while (tokens.size() < 2 && next(fields))
    while (fields >> token)
      tokens.push_back(token);
  std::size_t counts[2] = {0, 0};
  if (tokens.size() < 2 || tokens.size() > 3 || !parseCount(tokens[0], counts[0]) ||
      !parseCount(tokens[1], counts[1]))
    return fail("no vertex, face and edge counts");
  for (std::size_t v = 0; v < counts[0]; ++v) {
    double x[3];
    if (!next(fields) || !(fields >> x[0] >> x[1] >> x[2]))
      return fail("vertex " + std::to_string(v) + " is not 'x y z'");
    vertices.emplace_back(x[0], x[1], x[2]);
  }
  if (!faces)
    return true;
  faces->clear();
  std::vector<int> face;
  for (std::size_t f = 0; f < counts[1]; ++f) {
    std::size_t corners = 0;
    if (!next(fields) || !(fields >> token) || !parseCount(token, corners))
      return fail("face " + std::to_string(f) + " has no corner count");
    face.clear();
    for (std::size_t c = 0; c < corners; ++c) {
      std::size_t v = 0;
      if (!(fields >> token) || !parseCount(token, v) || v >= vertices.size())
        return fail("face " + std::to_string(f) + " names a missing vertex");
      face.push_back(static_cast<int>(v));
    }
    appendFan(face, *faces);
  }
  return true;
}

bool
readFaces(const std::string& path,
          std::vector<std::array<int, 3>>& faces,
          std::string& error)
{
  faces.clear();
  if (extension(path) == "off") {
    std::vector<Eigen::Vector3d> vertices;
    return readOff(path, vertices, &faces, error);
  }
  std::ifstream in(path);
  if (!in) {
    error = "cannot read '" + path + "'";
    return false;
  }
  long vertices = 0;
  std::string line;
  std::size_t number = 0;
  std::vector<int> face;
  while (readDataLine(in, line, number)) {
    std::istringstream fields(line);
    std::string tag;
    if (!(fields >> tag))
      continue;
    if (tag == "v")
      ++vertices;
    if (tag != "f")
      continue;
    face.clear();
    std::string corner;
    while (fields >> corner) {
      // v, v/vt, v//vn or v/vt/vn: the vertex is the first number.
      char* end = nullptr;
      const long i = std::strtol(corner.c_str(), &end, 10);
      const long v = i > 0 ? i - 1 : vertices + i;
      if (end == corner.c_str() || i == 0 || v < 0 || v >= vertices) {
        error = "line " + std::to_string(number) + ": bad vertex '" + corner + "'";
        return false;
      }
      face.push_back(static_cast<int>(v));
    }
    appendFan(face, faces);
  }
  return true;
}

namespace {

/** The scans a Stanford range-scan configuration lists ("bmesh FILE tx ty tz qx qy
 * qz qw" lines, the files relative to the configuration's directory), each moved
 * into the common frame and merged. A listed scan that is missing is left out with
 * a warning (the repositories ship subsets); none found is an error. */
bool
readScanConfiguration(const std::string& path,
                      pcl::PCLPointCloud2& cloud,
                      std::string& error)
{
  std::ifstream in(path);
  const std::string directory = directoryOf(path);
  pcl::PointCloud<pcl::PointXYZ> merged;
  std::vector<std::string> missing;
  std::size_t listed = 0, number = 0;
  std::string line;
  while (std::getline(in, line)) {
    ++number;
    std::istringstream fields(line);
    std::string tag, file;
    if (!(fields >> tag) || tag != "bmesh")
      continue; // the camera, comments
    double t[3], q[4];
    if (!(fields >> file >> t[0] >> t[1] >> t[2] >> q[0] >> q[1] >> q[2] >> q[3])) {
      error = "line " + std::to_string(number) +
              " is not 'bmesh FILE tx ty tz qx qy qz qw'";
      return false;
    }
    ++listed;
    const std::string scan = file.front() == '/' ? file : directory + "/" + file;
    if (!isFile(scan)) {
      missing.push_back(file);
      continue;
    }
    pcl::PCLPointCloud2 blob;
    std::vector<Eigen::Vector3d> xyz;
    if (!readCloud(scan, blob, error) || !extractXYZ(blob, xyz, error)) {
      error = file + ": " + error;
      return false;
    }
    // The stored rotation takes the common frame to the scan's: a point moves by
    // its inverse (the conjugate quaternion), then the translation. Measured on the
    // Stanford bunny: so the overlapping scans agree within half a sample spacing;
    // the rotation itself leaves them several spacings apart.
    const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
    const Eigen::Matrix3d R = rotation.normalized().conjugate().toRotationMatrix();
    const Eigen::Vector3d translation(t[0], t[1], t[2]);
    for (const auto& x : xyz) {
      const Eigen::Vector3d y = R * x + translation;
      merged.push_back(pcl::PointXYZ(static_cast<float>(y.x()),
                                     static_cast<float>(y.y()),
                                     static_cast<float>(y.z())));
    }
  }
  if (listed == missing.size()) {
    error = listed == 0 ? "no 'bmesh' line" : "none of the scans it lists is there";
    return false;
  }
  if (!missing.empty()) {
    std::string names;
    for (const auto& name : missing)
      names += " " + name;
    pcl::console::print_warn("%s: %zu of the %zu scans listed are missing, merged the "
                             "others (missing:%s)\n",
                             path.c_str(),
                             missing.size(),
                             listed,
                             names.c_str());
  }
  merged.is_dense = false;
  pcl::toPCLPointCloud2(merged, cloud);
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
  return ext == "pcd" || ext == "ply" || ext == "obj" || ext == "off" || ext == "xyz" ||
         ext == "txt" || ext == "pts" || ext == "conf";
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
    error = "unknown input format '" + ext +
            "' (use .pcd, .ply, .obj, .off, .xyz, .txt, .conf)";
    return false;
  }
  if (!isFile(path)) {
    error = "cannot read '" + path + "' (missing, unreadable or empty)";
    return false;
  }
  if (ext == "conf") {
    if (readScanConfiguration(path, cloud, error))
      return true;
    error = "cannot read '" + path + "': " + error;
    return false;
  }
  // PCL's readers print their own complaints; the tool prints one line instead.
  const auto verbosity = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  int status = 0;
  bool ok = true;
  try {
    if (ext == "pcd") {
      // PCL's reader trusts the header: it allocates what it says (a negative SIZE
      // became 17 GB) and crashes on some malformed ones. Check it first.
      if (checkPcdHeader(path, error))
        status = pcl::io::loadPCDFile(path, cloud);
      else
        ok = false;
    }
    else if (ext == "ply") {
      if (checkPlyHeader(path, error))
        status = pcl::io::loadPLYFile(path, cloud);
      else
        ok = false;
    }
    else if (ext == "off") {
      std::vector<Eigen::Vector3d> vertices;
      ok = readOff(path, vertices, nullptr, error);
      if (ok && vertices.empty()) {
        ok = false;
        error = "no points";
      }
      if (ok)
        xyzCloud(vertices, cloud);
    }
    else
      ok = readText(path, cloud, error, ext == "obj");
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
appendPoints(pcl::PCLPointCloud2& cloud, const std::vector<Eigen::Vector3d>& xyz)
{
  if (xyz.empty())
    return;
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  cloud.data.resize((n + xyz.size()) * cloud.point_step, 0);
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    std::uint8_t* p = cloud.data.data() + (n + i) * cloud.point_step;
    for (int k = 0; k < 3; ++k) {
      const auto& f = cloud.fields[pcl::getFieldIndex(cloud, std::string(1, "xyz"[k]))];
      if (f.datatype == pcl::PCLPointField::FLOAT32) {
        const float v = static_cast<float>(xyz[i][k]);
        std::memcpy(p + f.offset, &v, 4);
      }
      else
        std::memcpy(p + f.offset, &xyz[i][k], 8);
    }
  }
  cloud.width = static_cast<std::uint32_t>(n + xyz.size());
  cloud.height = 1;
  cloud.row_step = cloud.width * cloud.point_step;
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

namespace {

/** x, y, z of point i in double, whatever the fields' types. */
Eigen::Vector3d
pointAt(const pcl::PCLPointCloud2& cloud, const int (&xyz)[3], std::size_t i)
{
  Eigen::Vector3d p;
  const std::uint8_t* base = cloud.data.data() + i * cloud.point_step;
  for (int k = 0; k < 3; ++k) {
    const auto& f = cloud.fields[xyz[k]];
    if (f.datatype == pcl::PCLPointField::FLOAT64)
      std::memcpy(&p[k], base + f.offset, 8);
    else {
      float v;
      std::memcpy(&v, base + f.offset, 4);
      p[k] = v;
    }
  }
  return p;
}

/** Colour of point i as 0xRRGGBB, or -1 without a colour field. */
long
colourAt(const pcl::PCLPointCloud2& cloud, int field, std::size_t i)
{
  if (field < 0)
    return -1;
  std::uint32_t rgb;
  std::memcpy(
      &rgb, cloud.data.data() + i * cloud.point_step + cloud.fields[field].offset, 4);
  return rgb & 0xffffff;
}

/** Legacy VTK (what pcl_viewer opens) in double precision: PCL's writer only takes
 * float coordinates and keeps 5 digits by default. */
bool
writeVtk(const std::string& path, const pcl::PolygonMesh& mesh, const int (&xyz)[3])
{
  const auto& c = mesh.cloud;
  const std::size_t n = std::size_t(c.width) * c.height;
  std::ofstream f(path);
  f.precision(17);
  f << "# vtk DataFile Version 3.0\npcl_cocone_reconstruction\nASCII\nDATASET "
       "POLYDATA\nPOINTS "
    << n << " double\n";
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = pointAt(c, xyz, i);
    f << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  }
  f << "POLYGONS " << mesh.polygons.size() << ' ' << 4 * mesh.polygons.size() << '\n';
  for (const auto& t : mesh.polygons)
    f << "3 " << t.vertices[0] << ' ' << t.vertices[1] << ' ' << t.vertices[2] << '\n';
  const int rgb = std::max(pcl::getFieldIndex(c, "rgb"), pcl::getFieldIndex(c, "rgba"));
  if (rgb >= 0) {
    f << "POINT_DATA " << n << "\nCOLOR_SCALARS scalars 3\n";
    f.precision(6);
    for (std::size_t i = 0; i < n; ++i) {
      const long v = colourAt(c, rgb, i);
      f << ((v >> 16) & 255) / 255.0 << ' ' << ((v >> 8) & 255) / 255.0 << ' '
        << (v & 255) / 255.0 << '\n';
    }
  }
  return static_cast<bool>(f);
}

/** Wavefront OBJ with full precision. */
bool
writeObj(const std::string& path, const pcl::PolygonMesh& mesh, const int (&xyz)[3])
{
  const auto& c = mesh.cloud;
  const std::size_t n = std::size_t(c.width) * c.height;
  std::ofstream f(path);
  f.precision(17);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = pointAt(c, xyz, i);
    f << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  }
  for (const auto& t : mesh.polygons)
    f << "f " << t.vertices[0] + 1 << ' ' << t.vertices[1] + 1 << ' '
      << t.vertices[2] + 1 << '\n';
  return static_cast<bool>(f);
}

/** Binary PLY whose vertices carry every field of the cloud in its own type (colour
 * as red, green, blue). */
bool
writePly(const std::string& path, const pcl::PolygonMesh& mesh)
{
  static const char* PLY_TYPE[] = {
      nullptr, "char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
  const auto& c = mesh.cloud;
  const std::size_t n = std::size_t(c.width) * c.height;
  std::ofstream f(path, std::ios::binary);
  f << "ply\nformat binary_little_endian 1.0\ncomment pcl_cocone_reconstruction\n"
    << "element vertex " << n << '\n';
  std::vector<const pcl::PCLPointField*> fields;
  for (const auto& field : c.fields) {
    if (field.count != 1 || field.datatype < 1 || field.datatype > 8 ||
        field.name == "_")
      continue;
    fields.push_back(&field);
    if (field.name == "rgb" || field.name == "rgba")
      f << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    else
      f << "property " << PLY_TYPE[field.datatype] << ' ' << field.name << '\n';
  }
  f << "element face " << mesh.polygons.size()
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < n; ++i)
    for (const auto* field : fields) {
      const std::uint8_t* v = c.data.data() + i * c.point_step + field->offset;
      if (field->name == "rgb" || field->name == "rgba") {
        const std::uint8_t rgb[3] = {v[2], v[1], v[0]};
        f.write(reinterpret_cast<const char*>(rgb), 3);
      }
      else
        f.write(reinterpret_cast<const char*>(v), pcl::getFieldSize(field->datatype));
    }
  for (const auto& t : mesh.polygons) {
    const std::uint8_t three = 3;
    const std::int32_t v[3] = {t.vertices[0], t.vertices[1], t.vertices[2]};
    f.write(reinterpret_cast<const char*>(&three), 1);
    f.write(reinterpret_cast<const char*>(v), sizeof(v));
  }
  return static_cast<bool>(f);
}

} // namespace

bool
writeMesh(const std::string& path, const pcl::PolygonMesh& mesh, std::string& error)
{
  const std::string ext = extension(path);
  if (!isMeshFormat(ext)) {
    error = "unknown output format '" + ext + "' (use .vtk, .ply, .obj or .stl)";
    return false;
  }
  int xyz[3];
  for (int k = 0; k < 3; ++k)
    if ((xyz[k] = pcl::getFieldIndex(mesh.cloud, std::string(1, "xyz"[k]))) < 0) {
      error = "cannot write '" + path + "': no x/y/z";
      return false;
    }
  // The text formats and PLY are written here so that double coordinates (lidar in
  // UTM) keep every digit; STL is single precision by definition.
  return writeAtomically(
      path,
      [&](const std::string& tmp) {
        if (ext == "vtk")
          return writeVtk(tmp, mesh, xyz);
        if (ext == "ply")
          return writePly(tmp, mesh);
        if (ext == "obj")
          return writeObj(tmp, mesh, xyz);
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
