/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The command-line tool, run as a user would.
 */

#include <pcl/io/obj_io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/io/vtk_lib_io.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone_boundary.h>
#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <support/surfaces.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <sstream>
#include <string>

namespace {

const std::string TOOL = COCONE_TOOL_PATH;

class Tool : public ::testing::Test {
protected:
  static void
  SetUpTestSuite()
  {
    char pattern[] = "/tmp/cocone_tool_XXXXXX";
    dir_ = ::mkdtemp(pattern);
    cocone_test::SampleOptions o;
    o.n = 2000;
    sample_ = new cocone_test::Sample(cocone_test::hemisphere(o));
    cloud_.reset(new pcl::PointCloud<pcl::PointXYZ>);
    for (const auto& p : sample_->points)
      cloud_->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
    pcl::io::savePCDFileBinary(dir_ + "/in.pcd", *cloud_);
    pcl::io::savePLYFileBinary(dir_ + "/in.ply", *cloud_);
    std::ofstream xyz(dir_ + "/in.xyz"), txt(dir_ + "/in.txt"), obj(dir_ + "/in.obj");
    xyz.precision(9);
    obj.precision(9);
    for (const auto& p : *cloud_) {
      xyz << p.x << ' ' << p.y << ' ' << p.z << '\n';
      obj << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
    // OFF as CGAL writes it, with a comment, the counts on their own line, colours
    // after each vertex and a quad face (the faces are not read for the cloud).
    std::ofstream off(dir_ + "/in.off");
    off.precision(9);
    off << "OFF\n# a hemisphere\n" << cloud_->size() << " 1 0\n";
    for (const auto& p : *cloud_)
      off << p.x << ' ' << p.y << ' ' << p.z << " 0.5 0.5 0.5 1\n";
    off << "4 0 1 2 3\n";
    txt << "# x y z\n";
    txt.precision(9);
    for (const auto& p : *cloud_)
      txt << p.x << '\t' << p.y << '\t' << p.z << '\n';
  }

  static void
  TearDownTestSuite()
  {
    std::system(("rm -rf " + dir_).c_str());
    delete sample_;
  }

  /** Run the tool; returns its exit code, stderr+stdout in \a output. */
  static int
  run(const std::string& args, std::string* output = nullptr)
  {
    const std::string log = dir_ + "/log.txt";
    const int status = std::system((TOOL + " " + args + " > " + log + " 2>&1").c_str());
    if (output) {
      std::ifstream f(log);
      std::stringstream s;
      s << f.rdbuf();
      *output = s.str();
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  static bool
  exists(const std::string& path)
  {
    struct stat st;
    return ::stat(path.c_str(), &st) == 0;
  }

  /** The library's own result on the same cloud. */
  static std::size_t
  libraryTriangles(pcl::PointIndices* boundary = nullptr)
  {
    pcl::CoConeBoundary<pcl::PointXYZ> cocone;
    cocone.setInputCloud(cloud_);
    pcl::PolygonMesh mesh;
    cocone.reconstruct(mesh);
    if (boundary)
      cocone.getBoundaryPointIndices(*boundary);
    return mesh.polygons.size();
  }

  static std::string dir_;
  static cocone_test::Sample* sample_;
  static pcl::PointCloud<pcl::PointXYZ>::Ptr cloud_;
};

std::string Tool::dir_;
cocone_test::Sample* Tool::sample_ = nullptr;
pcl::PointCloud<pcl::PointXYZ>::Ptr Tool::cloud_;

} // namespace

TEST_F(Tool, EveryInputFormatGivesTheLibraryResult)
{
  const std::size_t expected = libraryTriangles();
  ASSERT_GT(expected, 3000u);
  for (const std::string in :
       {"in.pcd", "in.ply", "in.obj", "in.off", "in.xyz", "in.txt"}) {
    std::string out;
    ASSERT_EQ(run(dir_ + "/" + in + " " + dir_ + "/out.vtk -q", &out), 0) << in << out;
    pcl::PolygonMesh mesh;
    ASSERT_GT(pcl::io::loadPolygonFileVTK(dir_ + "/out.vtk", mesh), 0) << in;
    EXPECT_EQ(mesh.polygons.size(), expected) << in;
    EXPECT_EQ(std::size_t(mesh.cloud.width) * mesh.cloud.height, cloud_->size()) << in;
  }
}

TEST_F(Tool, EveryOutputFormatReadsBack)
{
  const std::size_t expected = libraryTriangles();
  for (const std::string ext : {"vtk", "ply", "obj", "stl"}) {
    const std::string out = dir_ + "/mesh." + ext;
    ASSERT_EQ(run(dir_ + "/in.pcd " + out + " -q"), 0) << ext;
    pcl::PolygonMesh mesh;
    if (ext == "ply")
      ASSERT_EQ(pcl::io::loadPLYFile(out, mesh), 0);
    else if (ext == "obj")
      ASSERT_EQ(pcl::io::loadOBJFile(out, mesh), 0);
    else
      ASSERT_GT(pcl::io::loadPolygonFile(out, mesh), 0) << ext;
    EXPECT_EQ(mesh.polygons.size(), expected) << ext;
    // Every polygon is a triangle of distinct vertices inside the cloud.
    const std::size_t n = std::size_t(mesh.cloud.width) * mesh.cloud.height;
    for (const auto& p : mesh.polygons) {
      ASSERT_EQ(p.vertices.size(), 3u);
      for (const auto v : p.vertices)
        ASSERT_LT(std::size_t(v), n);
    }
  }
}

TEST_F(Tool, ReportAgreesWithTheLibrary)
{
  pcl::PointIndices boundary;
  const std::size_t triangles = libraryTriangles(&boundary);
  const std::string report = dir_ + "/report.json";
  ASSERT_EQ(run(dir_ + "/in.pcd " + dir_ + "/m.vtk -q -report " + report +
                " -boundary " + dir_ + "/b.pcd -normals " + dir_ + "/n.pcd"),
            0);
  std::ifstream f(report);
  std::stringstream s;
  s << f.rdbuf();
  const std::string json = s.str();
  for (const char* key : {"\"input\"",
                          "\"points\"",
                          "\"finite_points\"",
                          "\"unique_points\"",
                          "\"parameters\"",
                          "\"ratio\"",
                          "\"normal_angle\"",
                          "\"cocone_angle\"",
                          "\"boundary_detection\"",
                          "\"threads\"",
                          "\"triangles\"",
                          "\"components\"",
                          "\"boundary_loops\"",
                          "\"boundary_indices\"",
                          "\"border_indices\"",
                          "\"true_borders\"",
                          "\"holes_filled\"",
                          "\"filled_hole_sizes\"",
                          "\"handles_cut\"",
                          "\"necks_cut\"",
                          "\"timings_ms\"",
                          "\"load\"",
                          "\"delaunay\"",
                          "\"voronoi\"",
                          "\"boundary\"",
                          "\"reconstruction\"",
                          "\"total\"",
                          "\"save\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
  EXPECT_NE(json.find("\"triangles\": " + std::to_string(triangles) + ","),
            std::string::npos);
  EXPECT_NE(json.find("\"points\": " + std::to_string(cloud_->size()) + ","),
            std::string::npos);
  EXPECT_NE(json.find("\"boundary_loops\": 1,"), std::string::npos);
  std::string list;
  for (std::size_t i = 0; i < boundary.indices.size(); ++i)
    list += (i ? "," : "") + std::to_string(boundary.indices[i]);
  EXPECT_NE(json.find("\"boundary_indices\": [" + list + "]"), std::string::npos);

  // The boundary file holds exactly those points, with their input indices.
  pcl::PCLPointCloud2 b;
  ASSERT_EQ(pcl::io::loadPCDFile(dir_ + "/b.pcd", b), 0);
  EXPECT_EQ(std::size_t(b.width) * b.height, boundary.indices.size());
  EXPECT_GE(pcl::getFieldIndex(b, "index"), 0);
  pcl::PointCloud<pcl::PointNormal> normals;
  ASSERT_EQ(pcl::io::loadPCDFile(dir_ + "/n.pcd", normals), 0);
  EXPECT_EQ(normals.size(), cloud_->size());
  // The hemisphere's normals point away from its centre.
  std::size_t outward = 0;
  for (const auto& p : normals)
    outward += p.normal_x * p.x + p.normal_y * p.y + p.normal_z * p.z > 0.0f;
  EXPECT_GE(outward, normals.size() * 99 / 100);
}

TEST_F(Tool, RefinedHolesAddVerticesAfterTheInput)
{
  // A dropout in the hemisphere's middle, closed (-hole_width 0) and refined: the
  // mesh's cloud is the input's points, then the added ones (as the library's).
  pcl::PointCloud<pcl::PointXYZ> holed;
  const Eigen::Vector3f top(0.0f, 0.0f, 1.0f);
  for (const auto& p : *cloud_)
    if ((p.getVector3fMap() - top).norm() > 2.0f * float(sample_->spacing))
      holed.push_back(p);
  const std::string in = dir_ + "/holed.pcd", out = dir_ + "/refined.ply",
                    report = dir_ + "/refined.json";
  pcl::io::savePCDFileBinary(in, holed);
  ASSERT_EQ(run(in + " " + out + " -q -hole_width 0 -refine_holes -report " + report),
            0);
  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(holed.makeShared());
  cocone.setMaxHoleWidth(0.0);
  cocone.setRefineFilledHoles(true);
  pcl::PolygonMesh expected;
  cocone.reconstruct(expected);
  const std::size_t added = cocone.getNumberOfAddedPoints();
  ASSERT_GT(added, 0u);
  pcl::PolygonMesh mesh;
  ASSERT_EQ(pcl::io::loadPLYFile(out, mesh), 0);
  EXPECT_EQ(std::size_t(mesh.cloud.width) * mesh.cloud.height, holed.size() + added);
  EXPECT_EQ(mesh.polygons.size(), expected.polygons.size());
  std::ifstream f(report);
  std::stringstream json;
  json << f.rdbuf();
  EXPECT_NE(json.str().find("\"added_points\": " + std::to_string(added) + ","),
            std::string::npos);
  EXPECT_NE(json.str().find("\"refine_filled_holes\": true"), std::string::npos);
}

TEST_F(Tool, ErrorsExitNonZeroWithAMessage)
{
  const std::string out = dir_ + "/err.vtk";
  std::remove(out.c_str());
  // A cloud without x/y/z.
  {
    pcl::PointCloud<pcl::Intensity> c;
    c.resize(10);
    pcl::io::savePCDFileASCII(dir_ + "/noxyz.pcd", c);
  }
  std::ofstream(dir_ + "/empty.xyz").close();
  std::ofstream(dir_ + "/bad.xyz") << "1 2 3\n4 five 6\n";
  std::ofstream(dir_ + "/bad.pcd") << "this is not a point cloud\n";
  // PCL's parser would read on after DATA and take this line for new fields.
  std::ofstream(dir_ + "/redeclared.pcd")
      << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 4\n"
         "HEIGHT 1\nPOINTS 4\nDATA ascii\n\n# data\nCOLUMNS a\n0 0 0\n1 0 0\n0 1 0\n"
         "0 0 1\n";
  std::ofstream(dir_ + "/line.xyz") << "0 0 0\n1 1 1\n2 2 2\n3 3 3\n4 4 4\n";
  std::ofstream(dir_ + "/binary.off") << "OFF BINARY\n";
  std::ofstream(dir_ + "/4d.off") << "4OFF\n1 0 0\n0 0 0 0\n";
  std::ofstream(dir_ + "/short.off") << "OFF\n3 0 0\n0 0 0\n1 0 0\n";
  std::ofstream(dir_ + "/nocounts.off") << "OFF\n# nothing else\n";
  const std::string in = dir_ + "/in.pcd ";
  const std::pair<std::string, std::string> cases[] = {
      {dir_ + "/missing.pcd " + out, "cannot read"},
      {dir_ + "/in.las " + out, "unknown input format"},
      {in + dir_ + "/out.xyz", "unknown output format"},
      {dir_ + "/noxyz.pcd " + out, "no 'x' field"},
      {dir_ + "/empty.xyz " + out, "cannot read"},
      {dir_ + "/bad.xyz " + out, "line 2"},
      {dir_ + "/bad.pcd " + out, "cannot read"},
      {dir_ + "/redeclared.pcd " + out, "cannot read"},
      {dir_ + "/line.xyz " + out, "collinear"},
      {dir_ + "/binary.off " + out, "binary OFF"},
      {dir_ + "/4d.off " + out, "not a 3D OFF header"},
      {dir_ + "/short.off " + out, "vertex 2"},
      {dir_ + "/nocounts.off " + out, "no vertex, face and edge counts"},
      {in + out + " -rho abc", "not a number"},
      {in + out + " -rho -1", "-rho must be positive"},
      {in + out + " -spacing_factor -2", "-spacing_factor"},
      {in + out + " -theta 3", "-theta"},
      {in + out + " -threads 1.5", "-threads"},
      {in + out + " -rho", "needs a value"},
      {in + out + " -frobnicate", "unknown option"},
      {in + "/nonexistent-dir/out.vtk", "cannot write"},
      {in + out + " -boundary " + dir_ + "/b.txt", ".pcd"},
      {in, "expected INPUT and OUTPUT"},
  };
  for (const auto& c : cases) {
    std::string log;
    EXPECT_NE(run(c.first, &log), 0) << c.first;
    EXPECT_NE(log.find(c.second), std::string::npos) << c.first << ": " << log;
    EXPECT_NE(log.find("Error"), std::string::npos) << c.first;
    EXPECT_FALSE(exists(out)) << c.first << " left " << out;
  }
}

TEST_F(Tool, GeoreferencedDoubleCoordinates)
{
  // Lidar in UTM: x, y, z as 8-byte fields around (5e6, 5e6, 1e3). The tool gives the
  // result it gives at the origin and writes the coordinates back unchanged.
  const auto write = [&](const std::string& path, const Eigen::Vector3d& offset) {
    pcl::PCLPointCloud2 blob;
    for (int k = 0; k < 3; ++k) {
      pcl::PCLPointField f;
      f.name = std::string(1, "xyz"[k]);
      f.offset = 8 * k;
      f.datatype = pcl::PCLPointField::FLOAT64;
      f.count = 1;
      blob.fields.push_back(f);
    }
    blob.point_step = 24;
    blob.width = static_cast<std::uint32_t>(cloud_->size());
    blob.height = 1;
    blob.row_step = blob.point_step * blob.width;
    blob.data.resize(blob.row_step);
    for (std::size_t i = 0; i < cloud_->size(); ++i) {
      // Points on a 2^-10 grid: exact in double after the offset.
      const Eigen::Vector3d p =
          (cloud_->at(i).getVector3fMap().cast<double>() * 1024.0).array().round() /
              1024.0 +
          offset.array();
      std::memcpy(&blob.data[i * 24], p.data(), 24);
    }
    pcl::io::savePCDFile(
        path, blob, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(), true);
  };
  const Eigen::Vector3d utm(5e6, 5e6, 1e3);
  write(dir_ + "/origin.pcd", Eigen::Vector3d::Zero());
  write(dir_ + "/utm.pcd", utm);
  std::string log;
  ASSERT_EQ(run(dir_ + "/origin.pcd " + dir_ + "/origin.ply -q -boundary " + dir_ +
                    "/origin_b.pcd",
                &log),
            0)
      << log;
  ASSERT_EQ(
      run(dir_ + "/utm.pcd " + dir_ + "/utm.ply -q -boundary " + dir_ + "/utm_b.pcd",
          &log),
      0)
      << log;
  pcl::PolygonMesh a, b;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/origin.ply", a), 0);
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/utm.ply", b), 0);
  ASSERT_EQ(a.polygons.size(), b.polygons.size());
  for (std::size_t i = 0; i < a.polygons.size(); ++i)
    EXPECT_EQ(a.polygons[i].vertices, b.polygons[i].vertices);
  // The boundary points keep their double coordinates, bit for bit.
  pcl::PCLPointCloud2 in, out;
  ASSERT_EQ(pcl::io::loadPCDFile(dir_ + "/utm.pcd", in), 0);
  ASSERT_EQ(pcl::io::loadPCDFile(dir_ + "/utm_b.pcd", out), 0);
  ASSERT_GT(out.width, 0u);
  const int index = pcl::getFieldIndex(out, "index");
  ASSERT_GE(index, 0);
  for (std::size_t j = 0; j < out.width; ++j) {
    std::uint32_t i;
    std::memcpy(&i, &out.data[j * out.point_step + out.fields[index].offset], 4);
    EXPECT_EQ(
        std::memcmp(&out.data[j * out.point_step], &in.data[i * in.point_step], 24), 0);
  }
}

TEST_F(Tool, DeterministicAcrossRunsThreadsAndInputOrder)
{
  const auto slurp = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)),
                       std::istreambuf_iterator<char>());
  };
  // Repeated runs and any number of threads: the same bytes.
  std::string log;
  for (const char* threads : {"1", "1", "0", "3"}) {
    const std::string name = dir_ + "/det" + threads;
    ASSERT_EQ(run(dir_ + "/in.pcd " + name + ".ply -q -threads " + threads +
                      " -boundary " + name + "_b.pcd",
                  &log),
              0)
        << log;
    EXPECT_EQ(slurp(name + ".ply"), slurp(dir_ + "/det1.ply")) << threads;
    EXPECT_EQ(slurp(name + "_b.pcd"), slurp(dir_ + "/det1_b.pcd")) << threads;
  }

  // A shuffled cloud: the same mesh and boundary up to the permutation.
  std::vector<int> order(cloud_->size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  pcl::PointCloud<pcl::PointXYZ> shuffled;
  for (const int i : order)
    shuffled.push_back(cloud_->at(i));
  pcl::io::savePCDFileBinary(dir_ + "/shuffled.pcd", shuffled);
  ASSERT_EQ(run(dir_ + "/shuffled.pcd " + dir_ + "/shuffled.ply -q -threads 0 " +
                    "-boundary " + dir_ + "/shuffled_b.pcd",
                &log),
            0)
      << log;
  const auto triangles = [](const std::string& path, const std::vector<int>* map) {
    pcl::PolygonMesh mesh;
    EXPECT_EQ(pcl::io::loadPLYFile(path, mesh), 0) << path;
    std::vector<std::array<int, 3>> out;
    for (const auto& polygon : mesh.polygons) {
      std::array<int, 3> t;
      for (int k = 0; k < 3; ++k)
        t[k] = map ? (*map)[polygon.vertices[k]] : int(polygon.vertices[k]);
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      out.push_back(t);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  const auto boundary = [](const std::string& path, const std::vector<int>* map) {
    pcl::PCLPointCloud2 blob;
    EXPECT_EQ(pcl::io::loadPCDFile(path, blob), 0) << path;
    const int field = pcl::getFieldIndex(blob, "index");
    std::vector<int> out;
    for (std::size_t j = 0; field >= 0 && j < blob.width * blob.height; ++j) {
      std::uint32_t i;
      std::memcpy(&i, &blob.data[j * blob.point_step + blob.fields[field].offset], 4);
      out.push_back(map ? (*map)[i] : int(i));
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  const auto original = triangles(dir_ + "/det1.ply", nullptr);
  ASSERT_GT(original.size(), 1000u);
  EXPECT_EQ(triangles(dir_ + "/shuffled.ply", &order), original);
  const auto border = boundary(dir_ + "/det1_b.pcd", nullptr);
  ASSERT_FALSE(border.empty());
  EXPECT_EQ(boundary(dir_ + "/shuffled_b.pcd", &order), border);
}

TEST_F(Tool, FuzzCorpusFailsCleanly)
{
  // Every file the readers' fuzzer kept (crashes of PCL's readers among them): the
  // tool either reads it or says why, and never crashes. The first byte of each
  // corpus file picks the format.
  const char* extensions[] = {"pcd", "ply", "obj", "xyz", "off"};
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(COCONE_FUZZ_CORPUS)) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)),
                      std::istreambuf_iterator<char>());
    if (bytes.empty())
      continue;
    const std::string input =
        dir_ + "/fuzz." + extensions[static_cast<unsigned char>(bytes[0]) % 5];
    std::ofstream(input, std::ios::binary) << bytes.substr(1);
    std::string log;
    const int code = run(input + " " + dir_ + "/fuzz.vtk -q", &log);
    EXPECT_TRUE(code == 0 || code == 1)
        << entry.path() << " exit " << code << ": " << log;
    ++files;
  }
  EXPECT_GE(files, 5u);
}

TEST_F(Tool, ScreenshotIsNotBlank)
{
  const std::string png = dir_ + "/shot.png";
  std::string log;
  ASSERT_EQ(run(dir_ + "/in.pcd " + dir_ + "/s.vtk -q -screenshot " + png, &log), 0)
      << log;
  std::ifstream f(png, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(f)),
                    std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 24u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  // A blank 1024 x 768 frame compresses to a few kilobytes; a rendered mesh does not.
  EXPECT_GT(bytes.size(), 20000u);
}

namespace {

/** A PCD of the sample's points followed by \a extra points. */
void
savePoints(const std::string& path,
           const std::vector<Eigen::Vector3d>& points,
           const std::vector<Eigen::Vector3d>& extra = {})
{
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (const auto* set : {&points, &extra})
    for (const auto& p : *set)
      cloud.push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  pcl::io::savePCDFileBinary(path, cloud);
}

std::string
slurpText(const std::string& path)
{
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

} // namespace

TEST_F(Tool, OutliersFileAndReport)
{
  // A sphere of radius 1 with three points 10 radii away: those are the outliers.
  cocone_test::SampleOptions o;
  o.n = 3000;
  const cocone_test::Sample s = cocone_test::sphere(o);
  const std::vector<Eigen::Vector3d> far = {
      {10.0, 0.0, 0.0}, {0.0, -10.0, 0.0}, {0.0, 0.0, 10.0}};
  savePoints(dir_ + "/far.pcd", s.points, far);
  const int n = static_cast<int>(s.points.size());
  const std::string report = dir_ + "/far.json";
  std::string log;
  ASSERT_EQ(run(dir_ + "/far.pcd " + dir_ + "/far.ply -v -report " + report +
                    " -outliers " + dir_ + "/far_o.pcd",
                &log),
            0)
      << log;
  // -v tells the noise level, the smoothing and the outliers.
  EXPECT_NE(log.find("Noise level"), std::string::npos) << log;
  EXPECT_NE(log.find("3 outliers"), std::string::npos) << log;

  // The outliers file: exactly the far points, with their input indices and
  // coordinates.
  pcl::PCLPointCloud2 blob;
  ASSERT_EQ(pcl::io::loadPCDFile(dir_ + "/far_o.pcd", blob), 0);
  ASSERT_EQ(std::size_t(blob.width) * blob.height, far.size());
  const int index = pcl::getFieldIndex(blob, "index");
  ASSERT_GE(index, 0);
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(blob, points);
  for (std::size_t j = 0; j < far.size(); ++j) {
    std::uint32_t i;
    std::memcpy(&i, &blob.data[j * blob.point_step + blob.fields[index].offset], 4);
    EXPECT_EQ(i, std::uint32_t(n + j));
    EXPECT_EQ(points[j].getVector3fMap(), far[j].cast<float>());
  }
  // No triangle uses them.
  pcl::PolygonMesh mesh;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/far.ply", mesh), 0);
  ASSERT_GT(mesh.polygons.size(), 5000u);
  for (const auto& p : mesh.polygons)
    for (const auto v : p.vertices)
      ASSERT_LT(int(v), n);

  const std::string json = slurpText(report);
  for (const char* key : {"\"noise\": {\"level\": ",
                          "\"after_smoothing\": ",
                          "\"smoothed\": false",
                          "\"noise_handling\": true",
                          "\"noise\": "})
    EXPECT_NE(json.find(key), std::string::npos) << key << "\n" << json;
  EXPECT_NE(json.find("\"outliers\": 3,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"outlier_indices\": [" + std::to_string(n) + "," +
                      std::to_string(n + 1) + "," + std::to_string(n + 2) + "]"),
            std::string::npos)
      << json;
  // The noise timing is among the stages.
  const std::size_t timings = json.find("\"timings_ms\"");
  ASSERT_NE(timings, std::string::npos);
  EXPECT_NE(json.find("\"noise\": ", timings), std::string::npos) << json;

  // Bad file names fail before any work.
  EXPECT_NE(
      run(dir_ + "/far.pcd " + dir_ + "/far2.ply -outliers " + dir_ + "/o.txt", &log),
      0);
  EXPECT_NE(log.find("-outliers must name a .pcd file"), std::string::npos) << log;
  EXPECT_FALSE(exists(dir_ + "/far2.ply"));
}

TEST_F(Tool, NoDenoiseKeepsTheNoisyPoints)
{
  cocone_test::SampleOptions o;
  o.n = 5000;
  o.noise = 0.5;
  o.even = false;
  savePoints(dir_ + "/noisy.pcd", cocone_test::hemisphere(o).points);
  std::string log;
  ASSERT_EQ(run(dir_ + "/noisy.pcd " + dir_ + "/noisy.ply -q -report " + dir_ +
                    "/noisy.json -outliers " + dir_ + "/noisy_o.pcd",
                &log),
            0)
      << log;
  const std::string smoothed = slurpText(dir_ + "/noisy.json");
  EXPECT_NE(smoothed.find("\"smoothed\": true"), std::string::npos) << smoothed;
  EXPECT_NE(smoothed.find("\"noise_handling\": true"), std::string::npos);

  ASSERT_EQ(run(dir_ + "/noisy.pcd " + dir_ + "/raw.ply -q -no_denoise -report " +
                    dir_ + "/raw.json -outliers " + dir_ + "/raw_o.pcd",
                &log),
            0)
      << log;
  const std::string raw = slurpText(dir_ + "/raw.json");
  EXPECT_NE(raw.find("\"smoothed\": false"), std::string::npos) << raw;
  EXPECT_NE(raw.find("\"noise_handling\": false"), std::string::npos) << raw;
  EXPECT_NE(raw.find("\"outliers\": 0,"), std::string::npos) << raw;
  EXPECT_NE(raw.find("\"outlier_indices\": []"), std::string::npos) << raw;
  // Without noise handling the outliers file is written, empty.
  pcl::PCLPointCloud2 blob;
  ASSERT_EQ(pcl::io::loadPCDFile(dir_ + "/raw_o.pcd", blob), 0);
  EXPECT_EQ(std::size_t(blob.width) * blob.height, 0u);
}

TEST_F(Tool, StanfordConfigurationMergesTheRegisteredScans)
{
  // The hemisphere cut into two scans; the second stored in its own frame, which
  // the configuration's rotation (qx qy qz qw) and translation undo.
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  const Eigen::Vector3d t(0.25, -1.5, 3.0);
  pcl::PointCloud<pcl::PointXYZ> first, second, merged;
  for (const auto& p : *cloud_) {
    const Eigen::Vector3d y = p.getVector3fMap().cast<double>();
    if (y.x() < 0.0)
      first.push_back(p);
    else {
      const Eigen::Vector3d x = q.toRotationMatrix() * (y - t);
      second.push_back(pcl::PointXYZ(float(x.x()), float(x.y()), float(x.z())));
    }
  }
  ASSERT_GT(first.size(), 500u);
  ASSERT_GT(second.size(), 500u);
  pcl::io::savePLYFileBinary(dir_ + "/first.ply", first);
  pcl::io::savePLYFileBinary(dir_ + "/second.ply", second);
  {
    std::ofstream conf(dir_ + "/scans.conf");
    conf.precision(17);
    conf << "camera 0 0 1 0 0 0 1\n"
         << "bmesh first.ply 0 0 0 0 0 0 1\n"
         << "bmesh second.ply " << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x()
         << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n'
         << "bmesh not_scanned.ply 0 0 0 0 0 0 1\n";
  }
  std::string log;
  ASSERT_EQ(run(dir_ + "/scans.conf " + dir_ + "/scans.ply", &log), 0) << log;
  // A listed scan that is missing is named, the others merged.
  EXPECT_NE(log.find("1 of the 3 scans listed are missing"), std::string::npos) << log;
  EXPECT_NE(log.find("not_scanned.ply"), std::string::npos) << log;

  // The output's points are the hemisphere's again, scan by scan.
  pcl::PolygonMesh mesh;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/scans.ply", mesh), 0);
  pcl::PointCloud<pcl::PointXYZ> points;
  pcl::fromPCLPointCloud2(mesh.cloud, points);
  ASSERT_EQ(points.size(), cloud_->size());
  double worst = 0.0;
  std::size_t i = 0;
  for (const bool in_first : {true, false})
    for (const auto& p : *cloud_)
      if ((p.x < 0.0f) == in_first)
        worst = std::max(
            worst, double((points[i++].getVector3fMap() - p.getVector3fMap()).norm()));
  EXPECT_LT(worst, 1e-5);
  // And its mesh the library's on the hemisphere, up to the float rounding of the
  // moved points.
  const double expected = double(libraryTriangles());
  EXPECT_NEAR(double(mesh.polygons.size()), expected, 0.01 * expected);

  // Nothing listed there: an error, no output.
  {
    std::ofstream conf(dir_ + "/empty.conf");
    conf << "bmesh gone.ply 0 0 0 0 0 0 1\n";
  }
  EXPECT_NE(run(dir_ + "/empty.conf " + dir_ + "/empty.ply", &log), 0);
  EXPECT_NE(log.find("none of the scans"), std::string::npos) << log;
  EXPECT_FALSE(exists(dir_ + "/empty.ply"));
}

TEST_F(Tool, TilePointsRunsInTilesAndSaysSo)
{
  // A sphere of 6,000 points in tiles of at most 1,000: closed, the same topology as
  // one piece, and the report names the tile size.
  cocone_test::SampleOptions o;
  o.n = 6000;
  savePoints(dir_ + "/tiles.pcd", cocone_test::sphere(o).points);
  std::string log;
  ASSERT_EQ(run(dir_ + "/tiles.pcd " + dir_ + "/tiles.ply -tile_points 1000 -report " +
                    dir_ + "/tiles.json",
                &log),
            0)
      << log;
  pcl::PolygonMesh tiled, whole;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/tiles.ply", tiled), 0);
  ASSERT_EQ(run(dir_ + "/tiles.pcd " + dir_ + "/whole.ply", &log), 0) << log;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/whole.ply", whole), 0);
  // Closed over the same points, both have 2 V - 4 triangles.
  EXPECT_EQ(tiled.polygons.size(), whole.polygons.size());
  const std::string json = slurpText(dir_ + "/tiles.json");
  EXPECT_NE(json.find("\"tile_points\": 1000"), std::string::npos) << json;
  EXPECT_NE(json.find("\"boundary_loops\": 0,"), std::string::npos) << json;

  EXPECT_NE(run(dir_ + "/tiles.pcd " + dir_ + "/bad.ply -tile_points 5", &log), 0);
  EXPECT_NE(log.find("-tile_points must be"), std::string::npos) << log;
  EXPECT_FALSE(exists(dir_ + "/bad.ply"));
}

TEST_F(Tool, TileSizeFollowsTheMemory)
{
  // By default (-tile_points auto) a cloud that fits the memory is one piece; with
  // -memory too small for one piece the tool picks tiles that fit, and says so.
  cocone_test::SampleOptions o;
  o.n = 20000;
  const std::vector<Eigen::Vector3d> points = cocone_test::sphere(o).points;
  savePoints(dir_ + "/auto.pcd", points);
  std::string log;
  ASSERT_EQ(run(dir_ + "/auto.pcd " + dir_ + "/auto.ply -report " + dir_ + "/auto.json",
                &log),
            0)
      << log;
  std::string json = slurpText(dir_ + "/auto.json");
  EXPECT_NE(json.find("\"tile_points\": 0, \"automatic_tiles\": true"),
            std::string::npos)
      << json;
  pcl::PolygonMesh whole, tiled;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/auto.ply", whole), 0);

  // 20,000 points need about 20 MB in one piece, 11 MB besides the tiles in tiles.
  const std::size_t expected =
      pcl::cocone::automaticTilePoints(points.size(), 16 * 1048576);
  ASSERT_GT(expected, 0u);
  ASSERT_EQ(run(dir_ + "/auto.pcd " + dir_ + "/auto_tiled.ply -memory 16 -report " +
                    dir_ + "/auto_tiled.json",
                &log),
            0)
      << log;
  EXPECT_NE(log.find("tiles of at most " + std::to_string(expected)), std::string::npos)
      << log;
  json = slurpText(dir_ + "/auto_tiled.json");
  EXPECT_NE(json.find("\"tile_points\": " + std::to_string(expected) +
                      ", \"automatic_tiles\": true"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"boundary_loops\": 0,"), std::string::npos) << json;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/auto_tiled.ply", tiled), 0);
  EXPECT_EQ(tiled.polygons.size(), whole.polygons.size()); // closed: 2 V - 4

  // Not even tiles fit: a warning, and the smallest tiles.
  ASSERT_EQ(run(dir_ + "/auto.pcd " + dir_ + "/auto_small.ply -memory 1", &log), 0)
      << log;
  EXPECT_NE(
      log.find("even in tiles of " + std::to_string(pcl::cocone::MINIMUM_TILE_POINTS)),
      std::string::npos)
      << log;

  EXPECT_NE(run(dir_ + "/auto.pcd " + dir_ + "/bad.ply -memory -3", &log), 0);
  EXPECT_NE(log.find("-memory must be"), std::string::npos) << log;
  EXPECT_NE(
      run(dir_ + "/auto.pcd " + dir_ + "/bad.ply -memory 10 -tile_points 5000", &log),
      0);
  EXPECT_NE(log.find("-memory plans the tiles"), std::string::npos) << log;
  EXPECT_NE(run(dir_ + "/auto.pcd " + dir_ + "/bad.ply -tile_points many", &log), 0);
  EXPECT_NE(log.find("is not a number"), std::string::npos) << log;
  EXPECT_FALSE(exists(dir_ + "/bad.ply"));
}

TEST_F(Tool, OutOfCoreStreamsTheCloudAndTheMesh)
{
  // A torus of 20,000 points streamed through tiles on disk: the mesh of the tiles in
  // memory (the same tiles; the in-memory tool hands the library float offsets, so a
  // triangle or two may differ), closed, and the work files gone.
  cocone_test::SampleOptions o;
  o.n = 20000;
  o.even = false;
  const std::vector<Eigen::Vector3d> points = cocone_test::torus(o).points;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (const auto& p : points)
    cloud.push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  pcl::io::savePLYFileBinary(dir_ + "/torus.ply", cloud);
  std::filesystem::create_directory(dir_ + "/work");
  std::string log;
  ASSERT_EQ(run(dir_ + "/torus.ply " + dir_ +
                    "/ooc.ply -out_of_core -tile_points 2500 -threads 2 -work_dir " +
                    dir_ + "/work -report " + dir_ + "/ooc.json",
                &log),
            0)
      << log;
  EXPECT_NE(log.find("Out of core: tiles of at most 2500 points"), std::string::npos)
      << log;
  EXPECT_TRUE(std::filesystem::is_empty(dir_ + "/work"));
  pcl::PolygonMesh streamed, tiled;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/ooc.ply", streamed), 0);
  ASSERT_EQ(run(dir_ + "/torus.ply " + dir_ + "/tiled.ply -tile_points 2500", &log), 0)
      << log;
  ASSERT_EQ(pcl::io::loadPLYFile(dir_ + "/tiled.ply", tiled), 0);
  std::vector<pcl::cocone::Triangle> triangles;
  for (const auto& p : streamed.polygons) {
    ASSERT_EQ(p.vertices.size(), 3u);
    triangles.push_back({int(p.vertices[0]), int(p.vertices[1]), int(p.vertices[2])});
  }
  const std::size_t vertices = streamed.cloud.width * streamed.cloud.height;
  const auto topology = pcl::cocone::analyzeMesh(triangles, vertices);
  EXPECT_TRUE(topology.manifold());
  EXPECT_EQ(topology.euler, 0);
  EXPECT_EQ(topology.boundary_edges, 0u);
  EXPECT_EQ(vertices, points.size());
  EXPECT_NEAR(double(streamed.polygons.size()), double(tiled.polygons.size()), 2.0);
  const std::string json = slurpText(dir_ + "/ooc.json");
  EXPECT_NE(json.find("\"out_of_core\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"boundary_loops\": 0,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"components\": 1,\n  \"euler\": 0,"), std::string::npos)
      << json;
  EXPECT_NE(json.find("\"tiles\": {\"count\": 8,"), std::string::npos) << json;

  // What needs the cloud in memory, or a format that cannot be streamed: an error,
  // no output.
  EXPECT_NE(run(dir_ + "/torus.ply " + dir_ + "/bad.vtk -out_of_core -tile_points 2500",
                &log),
            0);
  EXPECT_NE(log.find("written as .ply"), std::string::npos) << log;
  EXPECT_NE(run(dir_ + "/torus.ply " + dir_ +
                    "/bad.ply -out_of_core -tile_points 2500 "
                    "-boundary " +
                    dir_ + "/b.pcd",
                &log),
            0);
  EXPECT_NE(log.find("not available out of core"), std::string::npos) << log;
  EXPECT_NE(run(dir_ + "/in.xyz " + dir_ + "/bad.ply -out_of_core", &log), 0);
  EXPECT_NE(log.find("-out_of_core"), std::string::npos) << log;
  EXPECT_NE(
      run(dir_ + "/torus.ply " + dir_ + "/bad.ply -out_of_core -tile_points 0", &log),
      0);
  EXPECT_NE(log.find("at least 1000"), std::string::npos) << log;
  EXPECT_FALSE(exists(dir_ + "/bad.ply"));
  EXPECT_FALSE(exists(dir_ + "/bad.vtk"));
}
