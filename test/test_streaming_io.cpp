/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The out-of-core mode's streaming reader and mesh writer, on files PCL writes and
 * on headers written by hand.
 */

#include <pcl/common/io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/PCLPointField.h>
#include <pcl/point_types.h>
#include <pcl/PolygonMesh.h>

#include <gtest/gtest.h>

#include "cloud_io.h"
#include "streaming_io.h"
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

using Points = std::vector<Eigen::Vector3d>;

const double NaN = std::numeric_limits<double>::quiet_NaN();

class StreamingIo : public ::testing::Test {
protected:
  static void
  SetUpTestSuite()
  {
    char pattern[] = "/tmp/cocone_streaming_XXXXXX";
    dir_ = ::mkdtemp(pattern);
  }

  static void
  TearDownTestSuite()
  {
    fs::remove_all(dir_);
  }

  static std::string
  file(const std::string& name)
  {
    return dir_ + "/" + name;
  }

  static std::string dir_;
};

std::string StreamingIo::dir_;

/** Float values (exact in a float file), with some NaN points when asked. */
Points
randomPoints(std::size_t n, bool with_nan, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-100.0f, 100.0f);
  Points p(n);
  for (std::size_t i = 0; i < n; ++i)
    p[i] = with_nan && i % 101 == 5 ? Eigen::Vector3d(NaN, NaN, NaN)
                                    : Eigen::Vector3d(u(rng), u(rng), u(rng));
  return p;
}

/** Equal, NaN equal to NaN. */
bool
same(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  for (int k = 0; k < 3; ++k)
    if (!(a[k] == b[k] || (std::isnan(a[k]) && std::isnan(b[k]))))
      return false;
  return true;
}

/** Stream \a path with chunks of 1, 7 and 100000 points, two passes each, and
 * compare every point and every chunk's size with \a expected. */
void
expectStreams(const std::string& path, const Points& expected)
{
  for (const std::size_t max : {std::size_t(1), std::size_t(7), std::size_t(100000)}) {
    SCOPED_TRACE(path + ", chunks of " + std::to_string(max));
    std::size_t points = 0;
    std::string error;
    auto source = cocone_app::openPointStream(path, points, error);
    ASSERT_TRUE(source) << error;
    EXPECT_EQ(points, expected.size());
    for (int pass = 0; pass < 2; ++pass) {
      if (pass > 0) {
        ASSERT_TRUE(source->rewind(error)) << error;
      }
      Points chunk;
      std::size_t read = 0;
      for (;;) {
        ASSERT_TRUE(source->read(chunk, max, error)) << error;
        if (chunk.empty())
          break;
        ASSERT_EQ(chunk.size(), std::min(max, expected.size() - read));
        for (std::size_t i = 0; i < chunk.size(); ++i)
          ASSERT_TRUE(same(chunk[i], expected[read + i]))
              << "point " << read + i << ": " << chunk[i].transpose() << " vs "
              << expected[read + i].transpose();
        read += chunk.size();
      }
      EXPECT_EQ(read, expected.size());
      // The end of a pass stays the end.
      ASSERT_TRUE(source->read(chunk, max, error)) << error;
      EXPECT_TRUE(chunk.empty());
    }
  }
}

/** The error of a file that cannot be streamed (and that there is no source). */
std::string
refusal(const std::string& path)
{
  std::size_t points = 12345;
  std::string error;
  auto source = cocone_app::openPointStream(path, points, error);
  EXPECT_FALSE(source) << path;
  EXPECT_EQ(points, 0u);
  EXPECT_FALSE(error.empty());
  return error;
}

bool
contains(const std::string& text, const std::string& part)
{
  return text.find(part) != std::string::npos;
}

pcl::PointCloud<pcl::PointXYZ>
toXYZ(const Points& p)
{
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (const auto& x : p)
    cloud.push_back(pcl::PointXYZ(float(x.x()), float(x.y()), float(x.z())));
  cloud.is_dense = false;
  return cloud;
}

/** A cloud of double x, y, z and a float intensity between them. */
pcl::PCLPointCloud2
doubleCloud(const Points& p)
{
  pcl::PCLPointCloud2 cloud;
  const char* names[] = {"x", "intensity", "y", "z"};
  std::uint32_t offset = 0;
  for (const char* name : names) {
    pcl::PCLPointField f;
    f.name = name;
    f.offset = offset;
    f.datatype =
        name[0] == 'i' ? pcl::PCLPointField::FLOAT32 : pcl::PCLPointField::FLOAT64;
    f.count = 1;
    offset += name[0] == 'i' ? 4 : 8;
    cloud.fields.push_back(f);
  }
  cloud.point_step = offset;
  cloud.width = static_cast<std::uint32_t>(p.size());
  cloud.height = 1;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = false;
  cloud.data.resize(cloud.row_step);
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::uint8_t* d = cloud.data.data() + i * cloud.point_step;
    const float intensity = float(i);
    std::memcpy(d, &p[i].x(), 8);
    std::memcpy(d + 8, &intensity, 4);
    std::memcpy(d + 12, &p[i].y(), 8);
    std::memcpy(d + 20, &p[i].z(), 8);
  }
  return cloud;
}

/** A binary value in the given byte order. */
template <typename T>
void
put(std::string& out, T value, bool big_endian)
{
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big_endian)
    std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

void
writeFile(const std::string& path, const std::string& content)
{
  std::ofstream(path, std::ios::binary) << content;
}

/** A PLY with a scalar element before the vertices (skipped by size), vertices of
 * mixed types (double x, float y, float64 z between other properties) and faces
 * after them. */
std::string
handWrittenPly(const Points& p, bool big_endian)
{
  std::string s =
      "ply\nformat " +
      std::string(big_endian ? "binary_big_endian" : "binary_little_endian") +
      " 1.0\ncomment written by hand\nelement info 3\nproperty uchar a\n"
      "property double b\nelement vertex " +
      std::to_string(p.size()) +
      "\nproperty uchar flag\nproperty double x\nproperty float y\n"
      "property int16 s\nproperty float64 z\nproperty uint32 u\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 3; ++i) {
    put<std::uint8_t>(s, 0xAB, big_endian);
    put<double>(s, 1e300, big_endian);
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    put<std::uint8_t>(s, std::uint8_t(i), big_endian);
    put<double>(s, p[i].x(), big_endian);
    put<float>(s, float(p[i].y()), big_endian);
    put<std::int16_t>(s, -7, big_endian);
    put<double>(s, p[i].z(), big_endian);
    put<std::uint32_t>(s, 0xDEADBEEF, big_endian);
  }
  put<std::uint8_t>(s, 3, big_endian);
  for (int k = 0; k < 3; ++k)
    put<std::int32_t>(s, k, big_endian);
  return s;
}

TEST_F(StreamingIo, PlyOfPointXYZ)
{
  const Points p = randomPoints(200003, false, 1); // several 1 MB blocks
  ASSERT_EQ(pcl::io::savePLYFileBinary(file("xyz.ply"), toXYZ(p)), 0);
  expectStreams(file("xyz.ply"), p);
}

TEST_F(StreamingIo, PcdOfPointXYZWithNaN)
{
  const Points p = randomPoints(200003, true, 2);
  ASSERT_EQ(pcl::io::savePCDFileBinary(file("xyz.pcd"), toXYZ(p)), 0);
  expectStreams(file("xyz.pcd"), p);
}

TEST_F(StreamingIo, PointXYZRGBNormalSkipsTheOtherFields)
{
  const Points p = randomPoints(30011, false, 3);
  pcl::PointCloud<pcl::PointXYZRGBNormal> cloud;
  for (std::size_t i = 0; i < p.size(); ++i) {
    pcl::PointXYZRGBNormal q;
    q.x = float(p[i].x());
    q.y = float(p[i].y());
    q.z = float(p[i].z());
    q.r = std::uint8_t(i);
    q.g = 7;
    q.b = 200;
    q.normal_x = 1.0f;
    q.normal_y = -2.0f;
    q.normal_z = 3.0f;
    q.curvature = 0.5f;
    cloud.push_back(q);
  }
  ASSERT_EQ(pcl::io::savePLYFileBinary(file("rgbn.ply"), cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileBinary(file("rgbn.pcd"), cloud), 0);
  expectStreams(file("rgbn.ply"), p);
  expectStreams(file("rgbn.pcd"), p);
}

TEST_F(StreamingIo, DoubleCoordinatesKeepTheirPrecision)
{
  Points p = randomPoints(5003, false, 4);
  for (auto& x : p)
    x += Eigen::Vector3d(500000.123456789, 4000000.987654321, 0.1);
  const pcl::PCLPointCloud2 cloud = doubleCloud(p);
  ASSERT_EQ(pcl::io::savePCDFile(file("double.pcd"),
                                 cloud,
                                 Eigen::Vector4f::Zero(),
                                 Eigen::Quaternionf::Identity(),
                                 true),
            0);
  ASSERT_EQ(pcl::io::savePLYFile(file("double.ply"),
                                 cloud,
                                 Eigen::Vector4f::Zero(),
                                 Eigen::Quaternionf::Identity(),
                                 true),
            0);
  expectStreams(file("double.pcd"), p);
  expectStreams(file("double.ply"), p);
}

TEST_F(StreamingIo, HandWrittenPlyBothByteOrders)
{
  Points p = randomPoints(1000, true, 5);
  for (auto& x : p)
    x.x() += 0.1; // not a float
  writeFile(file("little.ply"), handWrittenPly(p, false));
  writeFile(file("big.ply"), handWrittenPly(p, true));
  expectStreams(file("little.ply"), p);
  expectStreams(file("big.ply"), p);
}

TEST_F(StreamingIo, TruncatedFilesAreRefusedAtOpen)
{
  const Points p = randomPoints(1000, false, 6);
  ASSERT_EQ(pcl::io::savePCDFileBinary(file("cut.pcd"), toXYZ(p)), 0);
  ASSERT_EQ(pcl::io::savePLYFileBinary(file("cut.ply"), toXYZ(p)), 0);
  // PCL's PLY writer puts a camera element after the vertices: cut into the
  // vertices themselves.
  const std::string ply = handWrittenPly(p, false);
  writeFile(file("cut_hand.ply"), ply.substr(0, ply.size() - 13 - 10));
  fs::resize_file(file("cut.pcd"), fs::file_size(file("cut.pcd")) - 1);
  fs::resize_file(file("cut.ply"), fs::file_size(file("cut.ply")) / 2);
  for (const char* name : {"cut.pcd", "cut.ply", "cut_hand.ply"})
    EXPECT_TRUE(contains(refusal(file(name)), "truncated")) << name;
  // Into the element before the vertices, and into the header.
  writeFile(file("cut_info.ply"), ply.substr(0, ply.find("end_header\n") + 11 + 20));
  EXPECT_TRUE(contains(refusal(file("cut_info.ply")), "truncated"));
  writeFile(file("cut_header.ply"), ply.substr(0, ply.find("end_header")));
  refusal(file("cut_header.ply"));
  writeFile(file("cut_header.pcd"), "# .PCD\nVERSION 0.7\nFIELDS x y z\n");
  refusal(file("cut_header.pcd"));
}

TEST_F(StreamingIo, TextAndCompressedFilesAreRefused)
{
  const auto cloud = toXYZ(randomPoints(100, false, 7));
  ASSERT_EQ(pcl::io::savePLYFileASCII(file("ascii.ply"), cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileASCII(file("ascii.pcd"), cloud), 0);
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(file("compressed.pcd"), cloud), 0);
  const std::string ply = refusal(file("ascii.ply"));
  EXPECT_TRUE(contains(ply, "is ASCII: streaming needs binary")) << ply;
  for (const char* name : {"ascii.pcd", "compressed.pcd"}) {
    const std::string error = refusal(file(name));
    EXPECT_TRUE(contains(error, "streaming needs uncompressed binary")) << error;
  }
  writeFile(file("points.xyz"), "1 2 3\n");
  EXPECT_TRUE(contains(refusal(file("points.xyz")),
                       "only binary .ply and .pcd files can be streamed"));
  refusal(file("missing.ply"));
  writeFile(file("empty.pcd"), "");
  refusal(file("empty.pcd"));
}

TEST_F(StreamingIo, MissingOrUnusableFieldsAreRefused)
{
  pcl::PCLPointCloud2 cloud = doubleCloud(randomPoints(10, false, 8));
  cloud.fields.pop_back(); // no z
  ASSERT_EQ(pcl::io::savePCDFile(file("noz.pcd"),
                                 cloud,
                                 Eigen::Vector4f::Zero(),
                                 Eigen::Quaternionf::Identity(),
                                 true),
            0);
  ASSERT_EQ(pcl::io::savePLYFile(file("noz.ply"),
                                 cloud,
                                 Eigen::Vector4f::Zero(),
                                 Eigen::Quaternionf::Identity(),
                                 true),
            0);
  for (const char* name : {"noz.pcd", "noz.ply"}) {
    const std::string error = refusal(file(name));
    EXPECT_TRUE(contains(error, "no 'z'")) << error;
  }
  const std::string head = "ply\nformat binary_little_endian 1.0\n";
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string data(1000, '\0');
  // A list among the vertex's properties, and before the vertices.
  writeFile(file("list.ply"),
            head + "element vertex 2\n" + xyz +
                "property list uchar int l\nend_header\n" + data);
  EXPECT_TRUE(contains(refusal(file("list.ply")), "list"));
  writeFile(file("list_before.ply"),
            head + "element face 1\nproperty list uchar int vertex_indices\n" +
                "element vertex 2\n" + xyz + "end_header\n" + data);
  EXPECT_TRUE(contains(refusal(file("list_before.ply")), "before the vertex element"));
  // Integer coordinates, negative, huge and missing counts, no vertex element.
  writeFile(file("int.ply"),
            head + "element vertex 2\nproperty int x\nproperty float y\n" +
                "property float z\nend_header\n" + data);
  EXPECT_TRUE(contains(refusal(file("int.ply")), "float or double"));
  writeFile(file("negative.ply"), head + "element vertex -5\n" + xyz + "end_header\n");
  refusal(file("negative.ply"));
  writeFile(file("huge.ply"),
            head + "element vertex 999999999999\n" + xyz + "end_header\n" + data);
  EXPECT_TRUE(contains(refusal(file("huge.ply")), "truncated"));
  writeFile(file("overflow.ply"),
            head + "element vertex 99999999999999999999999\n" + xyz + "end_header\n");
  refusal(file("overflow.ply"));
  writeFile(file("novertex.ply"),
            head + "element point 2\n" + xyz + "end_header\n" + data);
  EXPECT_TRUE(contains(refusal(file("novertex.ply")), "no vertex element"));
  writeFile(file("zero.ply"), head + "element vertex 0\n" + xyz + "end_header\n");
  EXPECT_TRUE(contains(refusal(file("zero.ply")), "no points"));
  const std::string pcd = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n";
  writeFile(file("negative.pcd"),
            pcd + "COUNT 1 1 1\nWIDTH -3\nHEIGHT 1\nPOINTS 3\nDATA binary\n" + data);
  refusal(file("negative.pcd"));
  writeFile(file("count.pcd"),
            pcd + "COUNT 1 2 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary\n" + data);
  EXPECT_TRUE(contains(refusal(file("count.pcd")), "COUNT 1"));
  writeFile(file("huge.pcd"),
            pcd + "COUNT 1 1 1\nWIDTH 100000000000\nHEIGHT 1\nDATA binary\n" + data);
  EXPECT_TRUE(contains(refusal(file("huge.pcd")), "truncated"));
  writeFile(file("overflow.pcd"),
            pcd + "WIDTH 999999999999\nHEIGHT 999999999999\nDATA binary\n" + data);
  refusal(file("overflow.pcd"));
  writeFile(file("points.pcd"),
            pcd + "WIDTH 3\nHEIGHT 1\nPOINTS 4\nDATA binary\n" + data);
  refusal(file("points.pcd"));
}

/** The names in the test's directory that start as the writer's temporary files. */
std::size_t
partialFiles(const std::string& dir)
{
  std::size_t n = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    n += entry.path().filename().string().rfind(".partial-", 0) == 0;
  return n;
}

TEST_F(StreamingIo, PlyMeshWriterRoundTrip)
{
  const Points positions = randomPoints(100003, false, 9);
  Points normals = randomPoints(positions.size(), true, 10);
  std::vector<pcl::cocone::Triangle> triangles;
  for (int i = 0; i + 2 < int(positions.size()); i += 3)
    triangles.push_back({{i, i + 2, i + 1}});
  const std::string path = file("mesh.ply");
  std::string error;
  {
    cocone_app::PlyMeshWriter writer(path);
    ASSERT_TRUE(writer.begin(positions.size(), triangles.size(), error)) << error;
    // In pieces, as runOutOfCore() writes them.
    const std::size_t half = positions.size() / 2;
    ASSERT_TRUE(writer.addVertices(Points(positions.begin(), positions.begin() + half),
                                   Points(normals.begin(), normals.begin() + half),
                                   {},
                                   error))
        << error;
    ASSERT_TRUE(writer.addVertices(Points(positions.begin() + half, positions.end()),
                                   Points(normals.begin() + half, normals.end()),
                                   {},
                                   error))
        << error;
    const auto middle = triangles.begin() + triangles.size() / 3;
    ASSERT_TRUE(writer.addTriangles({triangles.begin(), middle}, error)) << error;
    ASSERT_TRUE(writer.addTriangles({}, error)) << error;
    ASSERT_TRUE(writer.addTriangles({middle, triangles.end()}, error)) << error;
    EXPECT_FALSE(fs::exists(path)); // not before end()
    ASSERT_TRUE(writer.end(error)) << error;
  }
  EXPECT_EQ(partialFiles(dir_), 0u);
  pcl::PolygonMesh mesh;
  ASSERT_EQ(pcl::io::loadPLYFile(path, mesh), 0);
  ASSERT_EQ(std::size_t(mesh.cloud.width) * mesh.cloud.height, positions.size());
  ASSERT_EQ(mesh.polygons.size(), triangles.size());
  const char* names[] = {"x", "y", "z", "normal_x", "normal_y", "normal_z"};
  int index[6];
  for (int k = 0; k < 6; ++k) {
    index[k] = pcl::getFieldIndex(mesh.cloud, names[k]);
    ASSERT_GE(index[k], 0) << names[k];
    ASSERT_EQ(mesh.cloud.fields[index[k]].datatype, pcl::PCLPointField::FLOAT32);
  }
  for (std::size_t i = 0; i < positions.size(); ++i) {
    Eigen::Vector3d got[2];
    for (int k = 0; k < 6; ++k) {
      float v;
      std::memcpy(&v,
                  mesh.cloud.data.data() + i * mesh.cloud.point_step +
                      mesh.cloud.fields[index[k]].offset,
                  4);
      got[k / 3][k % 3] = v;
    }
    ASSERT_TRUE(same(got[0], positions[i])) << "vertex " << i;
    ASSERT_TRUE(same(got[1], normals[i])) << "normal " << i;
  }
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    ASSERT_EQ(mesh.polygons[t].vertices.size(), 3u);
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(int(mesh.polygons[t].vertices[k]), triangles[t][k]) << "triangle " << t;
  }
  // The file is a binary PLY the stream reads back too (the faces after the
  // vertices are skipped).
  expectStreams(path, positions);
}

TEST_F(StreamingIo, PlyMeshWriterFailuresLeaveNoFile)
{
  const Points three = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const Points normals(3, Eigen::Vector3d(0, 0, 1));
  const std::string path = file("failed.ply");
  std::string error;
  { // Fewer triangles than announced.
    cocone_app::PlyMeshWriter writer(path);
    ASSERT_TRUE(writer.begin(3, 2, error)) << error;
    ASSERT_TRUE(writer.addVertices(three, normals, {}, error)) << error;
    ASSERT_TRUE(writer.addTriangles({{{0, 1, 2}}}, error)) << error;
    EXPECT_FALSE(writer.end(error));
    EXPECT_TRUE(contains(error, "1 of the 2 triangles")) << error;
  }
  EXPECT_FALSE(fs::exists(path));
  { // Fewer vertices than announced.
    cocone_app::PlyMeshWriter writer(path);
    ASSERT_TRUE(writer.begin(4, 0, error)) << error;
    ASSERT_TRUE(writer.addVertices(three, normals, {}, error)) << error;
    EXPECT_FALSE(writer.end(error));
  }
  EXPECT_FALSE(fs::exists(path));
  { // More vertices than announced, a bad index, triangles too early.
    cocone_app::PlyMeshWriter a(path), b(path), c(path);
    ASSERT_TRUE(a.begin(2, 0, error)) << error;
    EXPECT_FALSE(a.addVertices(three, normals, {}, error));
    EXPECT_FALSE(a.end(error)); // failed for good
    ASSERT_TRUE(b.begin(3, 1, error)) << error;
    ASSERT_TRUE(b.addVertices(three, normals, {}, error)) << error;
    EXPECT_FALSE(b.addTriangles({{{0, 1, 3}}}, error));
    ASSERT_TRUE(c.begin(3, 1, error)) << error;
    EXPECT_FALSE(c.addTriangles({{{0, 1, 2}}}, error));
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(partialFiles(dir_), 0u);
  // An existing file is replaced only by a complete one.
  writeFile(path, "old");
  {
    cocone_app::PlyMeshWriter writer(path);
    ASSERT_TRUE(writer.begin(3, 1, error)) << error;
    ASSERT_TRUE(writer.addVertices(three, normals, {}, error)) << error;
  } // destroyed before end()
  EXPECT_EQ(fs::file_size(path), 3u);
  EXPECT_EQ(partialFiles(dir_), 0u);
  // A directory that does not exist.
  cocone_app::PlyMeshWriter nowhere(file("no/such/dir/mesh.ply"));
  EXPECT_FALSE(nowhere.begin(3, 1, error));
  EXPECT_TRUE(contains(error, "cannot write")) << error;
}

/** Write a mesh under a file size limit (a stand-in for a full disk: writes past it
 * fail with EFBIG); exit with 3 if the writer reported the failure. */
void
writeUnderSizeLimit(const std::string& path)
{
  std::signal(SIGXFSZ, SIG_IGN);
  const rlimit limit{65536, 65536};
  ::setrlimit(RLIMIT_FSIZE, &limit);
  const Points p = randomPoints(100000, false, 11);
  cocone_app::PlyMeshWriter writer(path);
  std::string error;
  const bool ok = writer.begin(p.size(), 0, error) &&
                  writer.addVertices(p, p, {}, error) && writer.end(error);
  std::exit(!ok && contains(error, "cannot write") ? 3 : 0);
}

TEST_F(StreamingIo, PlyMeshWriterReportsAFullDisk)
{
  const std::string path = file("full.ply");
  EXPECT_EXIT(writeUnderSizeLimit(path), ::testing::ExitedWithCode(3), "");
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(partialFiles(dir_), 0u);
}

} // namespace

TEST(CloudIo, OffMeshesVerticesAndFaces)
{
  const std::string path =
      (std::filesystem::temp_directory_path() / "cocone_cloud_io_test.off").string();
  // Counts on the header's line, normals after x y z, a quad and a triangle.
  std::ofstream(path) << "NOFF 5 2 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n"
                         "0 1 0 0 0 1\n# apex\n0.5 0.5 1 0 0 1\n4 0 1 2 3\n3 0 1 4\n";
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> faces;
  std::string error;
  ASSERT_TRUE(cocone_app::readOff(path, vertices, &faces, error)) << error;
  ASSERT_EQ(vertices.size(), 5u);
  EXPECT_EQ(vertices[4], Eigen::Vector3d(0.5, 0.5, 1.0));
  const std::vector<std::array<int, 3>> fan = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}};
  EXPECT_EQ(faces, fan);
  // A face naming a vertex the file does not have.
  std::ofstream(path) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
  EXPECT_FALSE(cocone_app::readOff(path, vertices, &faces, error));
  EXPECT_NE(error.find("missing vertex"), std::string::npos) << error;
  // Read for the cloud alone, the faces are not looked at.
  EXPECT_TRUE(cocone_app::readOff(path, vertices, nullptr, error)) << error;
  EXPECT_EQ(vertices.size(), 3u);
  std::remove(path.c_str());
}
