/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * pcl_cocone_reconstruction: reconstruct a mesh from a point cloud and report where
 * the cloud is undersampled.
 */

#include <pcl/common/io.h>
#include <pcl/common/time.h>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/triangulation.h>
#include <pcl/surface/cocone_boundary.h>
#include <pcl/point_types.h>

#include "cloud_io.h"
#include "screenshot.h"
#include "streaming_io.h"
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace pcl::console;

namespace {

struct Options {
  std::string input, output;
  double ratio = 0.0; // automatic
  double spacing_factor = 3.0;
  double gap_angle = pcl::cocone::Parameters().gap_angle;
  double normal_angle = M_PI / 6.0;
  double cocone_angle = 3.0 * M_PI / 8.0;
  bool boundary_detection = true;
  bool noise_handling = true;
  bool fill_holes = true;
  bool refine_holes = false;
  double hole_width = pcl::cocone::Parameters().hole_width;
  int threads = 1;
  std::size_t tile_points = 0; // one piece
  bool automatic_tiles = true; // tile_points from the memory
  double memory_mb = 0.0;      // planned for; 0: what the machine has available
  bool out_of_core = false;    // forced; otherwise chosen by the memory
  std::string work_dir;        // of an out-of-core run; "": the output's directory
  std::string boundary_file, outliers_file, normals_file, report_file, screenshot_file;
};

void
printHelp(const char* name)
{
  print_info(
      "Reconstruct a surface from a point cloud with the boundary-aware Co-cone\n"
      "(Dey & Giesen 2001): holes, open borders and sharp features are\n"
      "detected as undersampled; the mesh stays open where the sampled surface\n"
      "ends and closes the holes the surface goes on across (-no_fill: all open).\n\n");
  print_info("Syntax: %s INPUT OUTPUT [options]\n\n", name);
  print_info(
      "  INPUT   .pcd, .ply (a point cloud or a mesh's vertices), .obj, .off, "
      ".xyz/.txt\n"
      "          (x y z per line),\n"
      "          .conf (registered range scans, Stanford's format: the scans it lists, "
      "merged)\n"
      "  OUTPUT  .vtk (legacy, what pcl_viewer opens), .ply, .obj, .stl\n\n"
      "  -rho R            ratio of the flatness test; 0 (default) chooses it from "
      "the\n"
      "                    cloud; the paper uses 1.5; larger marks more points\n"
      "  -spacing_factor A undersampled if the Voronoi cell is wider than A local\n"
      "                    spacings (default 3; 0 = off)\n"
      "  -gap_angle G      rim point if its neighbours leave an angular gap above G\n"
      "                    radians (default 80 degrees; 0 = off; -spacing_factor 0\n"
      "                    -gap_angle 0 = the paper's test alone)\n"
      "  -theta T          normal angle in radians (default pi/6)\n"
      "  -cocone_angle A   co-cone angle in radians (default 3pi/8)\n"
      "  -no_boundary      plain Co-cone, no boundary detection\n"
      "  -no_denoise       no noise handling: no outliers set aside, the points\n"
      "                    used as given even when the cloud is noisy\n"
      "  -no_fill          leave the undersampled holes open (by default a border\n"
      "                    loop that triangles of the local spacing close is closed)\n"
      "  -hole_width W     an empty hole wider than W of its rim's triangles is a\n"
      "                    true border, never closed (default 2.5; 0 = any may close)\n"
      "  -refine_holes     refine and fair the patches of the holes closed: new\n"
      "                    vertices (after the input's points in the mesh), a\n"
      "                    smooth surface there\n"
      "  -threads N        number of threads, 0 = all cores (default 1)\n"
      "  -tile_points N    reconstruct in tiles of at most N points (at least 1000),\n"
      "                    one per thread at a time, stitched into one mesh: memory\n"
      "                    follows N; 0: one piece; auto (default): one piece if it\n"
      "                    fits the memory, else the largest tiles that do\n"
      "  -memory MB        the memory -tile_points auto plans for (default: what the\n"
      "                    machine has available, within the process' cgroup limit)\n"
      "  -out_of_core      stream the cloud (binary .ply or .pcd) into tiles on disk\n"
      "                    and the mesh (.ply) out: memory follows the tile, not the\n"
      "                    cloud. Chosen by -tile_points auto when the cloud does not\n"
      "                    fit in memory even in tiles; no\n"
      "                    -boundary, -outliers, -normals, -screenshot, -refine_holes\n"
      "  -work_dir DIR     where an out-of-core run keeps its files (default: the\n"
      "                    output's directory; about 100 bytes per point)\n"
      "  -boundary FILE    write the undersampled points as a .pcd with their input\n"
      "                    index in the field 'index'\n"
      "  -outliers FILE    write the outliers (in no triangle) as a .pcd with their\n"
      "                    input index in the field 'index'\n"
      "  -normals FILE     write the cloud with oriented normals as a .pcd\n"
      "  -report FILE      write a JSON report\n"
      "  -screenshot FILE  render mesh and boundary to a .png without a window\n"
      "  -v / -q           more / less output (-v: the noise level, whether the\n"
      "                    points were smoothed, the outliers)\n\n"
      "The mesh keeps every field of the input cloud; unless the input has colours,\n"
      "undersampled points are coloured red, so 'pcl_viewer OUTPUT.vtk' shows them.\n"
      "Outliers are set aside and noisy clouds are smoothed before the decisions\n"
      "(the mesh keeps the input positions) unless -no_denoise is given.\n");
}

/** Outputs written so far: a failure removes them, so no run leaves half its files. */
std::vector<std::string> written;

[[noreturn]] void
fail(const std::string& message)
{
  print_error("Error: %s\n", message.c_str());
  for (const auto& f : written)
    std::remove(f.c_str());
  std::exit(1);
}

double
parseNumber(int argc, char** argv, const char* option, double fallback)
{
  std::string text;
  if (parse_argument(argc, argv, option, text) < 0)
    return fallback;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(v))
    fail(std::string("option ") + option + ": '" + text + "' is not a number");
  return v;
}

Options
parseOptions(int argc, char** argv)
{
  Options o;
  std::vector<std::string> positional;
  // Options that take a value; everything else starting with '-' is a switch.
  const char* with_value[] = {"-rho",
                              "-spacing_factor",
                              "-hole_width",
                              "-gap_angle",
                              "-theta",
                              "-cocone_angle",
                              "-threads",
                              "-tile_points",
                              "-memory",
                              "-work_dir",
                              "-boundary",
                              "-outliers",
                              "-normals",
                              "-report",
                              "-screenshot"};
  const char* switches[] = {"-no_boundary",
                            "-no_denoise",
                            "-no_fill",
                            "-refine_holes",
                            "-out_of_core",
                            "-v",
                            "-q",
                            "-h",
                            "--help"};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    bool known = false;
    for (const char* w : with_value)
      if (a == w) {
        known = true;
        if (++i >= argc)
          fail("option " + a + " needs a value");
      }
    for (const char* s : switches)
      known = known || a == s;
    if (known)
      continue;
    if (a.size() > 1 && a[0] == '-' && !std::isdigit(static_cast<unsigned char>(a[1])))
      fail("unknown option '" + a + "'");
    positional.push_back(a);
  }
  if (positional.size() != 2)
    fail("expected INPUT and OUTPUT (see -h)");
  o.input = positional[0];
  o.output = positional[1];

  o.ratio = parseNumber(argc, argv, "-rho", o.ratio);
  if (!(o.ratio >= 0.0))
    fail("-rho must be positive (or 0 for automatic)");
  o.spacing_factor = parseNumber(argc, argv, "-spacing_factor", o.spacing_factor);
  if (!(o.spacing_factor >= 0.0))
    fail("-spacing_factor must be >= 0");
  o.gap_angle = parseNumber(argc, argv, "-gap_angle", o.gap_angle);
  if (!(o.gap_angle >= 0.0 && o.gap_angle < M_PI))
    fail("-gap_angle must be in [0, pi)");
  o.normal_angle = parseNumber(argc, argv, "-theta", o.normal_angle);
  if (!(o.normal_angle > 0.0 && o.normal_angle <= M_PI / 2.0))
    fail("-theta must be in (0, pi/2]");
  o.cocone_angle = parseNumber(argc, argv, "-cocone_angle", o.cocone_angle);
  if (!(o.cocone_angle > 0.0 && o.cocone_angle < M_PI / 2.0))
    fail("-cocone_angle must be in (0, pi/2)");
  const double threads = parseNumber(argc, argv, "-threads", 1.0);
  if (threads < 0.0 || threads != std::floor(threads) || threads > 4096)
    fail("-threads must be a whole number >= 0");
  o.threads = static_cast<int>(threads);
  std::string tiles;
  parse_argument(argc, argv, "-tile_points", tiles);
  o.automatic_tiles = tiles.empty() || tiles == "auto";
  if (!o.automatic_tiles) {
    const double tile_points = parseNumber(argc, argv, "-tile_points", 0.0);
    if (tile_points != std::floor(tile_points) || tile_points > 2e9 ||
        (tile_points != 0.0 &&
         tile_points < static_cast<double>(pcl::cocone::MINIMUM_TILE_POINTS)))
      fail("-tile_points must be auto, 0 (one piece) or a whole number of at least " +
           std::to_string(pcl::cocone::MINIMUM_TILE_POINTS));
    o.tile_points = static_cast<std::size_t>(tile_points);
  }
  o.memory_mb = parseNumber(argc, argv, "-memory", 0.0);
  if (!(o.memory_mb >= 0.0) || o.memory_mb > 1e12)
    fail("-memory must be a number of megabytes >= 0 (0: what is available)");
  if (o.memory_mb > 0.0 && !o.automatic_tiles)
    fail("-memory plans the tiles of -tile_points auto; drop it or -tile_points");
  o.boundary_detection = !find_switch(argc, argv, "-no_boundary");
  o.noise_handling = !find_switch(argc, argv, "-no_denoise");
  o.fill_holes = !find_switch(argc, argv, "-no_fill");
  o.refine_holes = find_switch(argc, argv, "-refine_holes");
  o.hole_width = parseNumber(argc, argv, "-hole_width", o.hole_width);
  if (!(o.hole_width >= 0.0))
    fail("-hole_width must be >= 0");
  o.out_of_core = find_switch(argc, argv, "-out_of_core");
  parse_argument(argc, argv, "-work_dir", o.work_dir);
  parse_argument(argc, argv, "-boundary", o.boundary_file);
  parse_argument(argc, argv, "-outliers", o.outliers_file);
  parse_argument(argc, argv, "-normals", o.normals_file);
  parse_argument(argc, argv, "-report", o.report_file);
  parse_argument(argc, argv, "-screenshot", o.screenshot_file);

  if (!cocone_app::isInputFormat(cocone_app::extension(o.input)))
    fail("unknown input format '" + o.input +
         "' (use .pcd, .ply, .obj, .off, .xyz or .txt)");
  if (!cocone_app::isMeshFormat(cocone_app::extension(o.output)))
    fail("unknown output format '" + o.output + "' (use .vtk, .ply, .obj or .stl)");
  if (!o.boundary_file.empty() && cocone_app::extension(o.boundary_file) != "pcd")
    fail("-boundary must name a .pcd file");
  if (!o.outliers_file.empty() && cocone_app::extension(o.outliers_file) != "pcd")
    fail("-outliers must name a .pcd file");
  if (!o.normals_file.empty() && cocone_app::extension(o.normals_file) != "pcd")
    fail("-normals must name a .pcd file");
  if (!o.screenshot_file.empty() && cocone_app::extension(o.screenshot_file) != "png")
    fail("-screenshot must name a .png file");
  std::string error;
  for (const auto* f : {&o.output,
                        &o.boundary_file,
                        &o.outliers_file,
                        &o.normals_file,
                        &o.report_file,
                        &o.screenshot_file})
    if (!f->empty() && !cocone_app::checkWritable(*f, error))
      fail(error);
  return o;
}

std::string
jsonList(const std::vector<int>& v)
{
  std::ostringstream s;
  s << '[';
  for (std::size_t i = 0; i < v.size(); ++i)
    s << (i ? "," : "") << v[i];
  s << ']';
  return s.str();
}

std::string
jsonString(const std::string& text)
{
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\')
      out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      out += buf;
      continue;
    }
    out += c;
  }
  return out + "\"";
}

/** Reconstruct out of core: the cloud streamed from \a source into tiles on disk in
 * the work directory, the mesh streamed to the output .ply; writes the report. */
int
reconstructOutOfCore(const Options& o,
                     pcl::cocone::PointSource& source,
                     const pcl::cocone::TilingOptions& tiling)
{
  if (cocone_app::extension(o.output) != "ply")
    fail("out of core the mesh is written as .ply (got '" + o.output + "')");
  for (const auto* f :
       {&o.boundary_file, &o.outliers_file, &o.normals_file, &o.screenshot_file})
    if (!f->empty())
      fail("-boundary, -outliers, -normals and -screenshot need the cloud in memory: "
           "not available out of core (the report lists the boundary and outlier "
           "indices)");
  if (o.refine_holes)
    fail("-refine_holes is not available out of core");
  std::string directory = o.work_dir;
  if (directory.empty()) {
    const auto slash = o.output.find_last_of('/');
    directory = slash == std::string::npos ? "." : o.output.substr(0, slash + 1);
  }
  pcl::cocone::Parameters p;
  p.ratio = o.ratio;
  p.spacing_factor = o.spacing_factor;
  p.gap_angle = o.gap_angle;
  p.normal_angle = o.normal_angle;
  p.cocone_angle = o.cocone_angle;
  p.boundary_detection = o.boundary_detection;
  p.noise_handling = o.noise_handling;
  p.fill_undersampled_holes = o.fill_holes;
  p.hole_width = o.hole_width;
  p.threads = static_cast<unsigned>(o.threads);
  print_info("Out of core: tiles of at most %zu points, %u at a time, files in %s.\n",
             tiling.tile_points,
             tiling.tiles_in_flight > 0
                 ? tiling.tiles_in_flight
                 : static_cast<unsigned>(pcl::cocone::resolveThreads(p.threads)),
             directory.c_str());
  pcl::StopWatch total;
  cocone_app::PlyMeshWriter writer(o.output);
  const pcl::cocone::OutOfCoreResult r =
      pcl::cocone::runOutOfCore(source, p, tiling, directory, writer);
  if (!r.error.empty())
    fail(r.error);
  written.push_back(o.output);
  const double total_ms = total.getTime();
  print_info("%zu points in %zu tiles (%zu halo points): %zu triangles, %zu "
             "components, Euler characteristic %ld, %zu border loops, %zu undersampled "
             "points, %zu undersampled holes closed; cut %.0f "
             "ms, tiles %.0f ms, stitch and write %.0f ms; work files at most %.0f "
             "MB.\n",
             r.points,
             r.tiling.tiles,
             r.tiling.halo_points,
             r.triangles,
             r.components,
             r.euler,
             r.border_loops.size(),
             r.boundary_indices.size(),
             r.holes_filled,
             r.tiling.cut_ms,
             r.tiling.tiles_ms,
             r.tiling.stitch_ms,
             double(r.disk_bytes) / 1048576.0);
  if (o.noise_handling)
    print_debug("Noise level %.3f (about sigma in sample spacings), %s; %zu "
                "outliers.\n",
                r.noise_level,
                r.smoothed ? "smoothed in some tiles" : "not smoothed",
                r.outlier_indices.size());
  if (!o.report_file.empty()) {
    std::vector<int> border;
    for (const auto& loop : r.border_loops)
      border.insert(border.end(), loop.begin(), loop.end());
    std::sort(border.begin(), border.end());
    std::ostringstream out;
    out.precision(17);
    out << "{\n  \"input\": " << jsonString(o.input) << ",\n  \"points\": " << r.points
        << ",\n  \"finite_points\": " << r.finite
        << ",\n  \"unique_points\": " << r.vertices
        << ",\n  \"parameters\": {\"ratio\": " << r.ratio
        << ", \"gap_angle\": " << o.gap_angle
        << ", \"normal_angle\": " << o.normal_angle
        << ", \"cocone_angle\": " << o.cocone_angle
        << ", \"boundary_detection\": " << (o.boundary_detection ? "true" : "false")
        << ", \"noise_handling\": " << (o.noise_handling ? "true" : "false")
        << ", \"fill_undersampled_holes\": " << (o.fill_holes ? "true" : "false")
        << ", \"hole_width\": " << o.hole_width
        << ", \"refine_filled_holes\": false, \"tile_points\": " << tiling.tile_points
        << ", \"automatic_tiles\": " << (o.automatic_tiles ? "true" : "false")
        << ", \"out_of_core\": true, \"tiles_in_flight\": " << tiling.tiles_in_flight
        << ", \"threads\": " << o.threads
        << "},\n  \"noise\": {\"level\": " << r.noise_level
        << ", \"smoothed\": " << (r.smoothed ? "true" : "false")
        << "},\n  \"outliers\": " << r.outlier_indices.size()
        << ",\n  \"outlier_indices\": " << jsonList(r.outlier_indices)
        << ",\n  \"unmeshed_part_triangles\": " << r.counts.unmeshed_parts
        << ",\n  \"true_borders\": " << r.counts.true_borders
        << ",\n  \"holes_filled\": " << r.holes_filled
        << ",\n  \"hole_triangles\": " << r.counts.hole_triangles
        << ",\n  \"handles_cut\": " << r.counts.handles_cut
        << ",\n  \"necks_cut\": " << r.counts.necks_cut
        << ",\n  \"added_points\": 0,\n  \"triangles\": " << r.triangles
        << ",\n  \"components\": " << r.components << ",\n  \"euler\": " << r.euler
        << ",\n  \"boundary_loops\": " << r.border_loops.size()
        << ",\n  \"boundary_indices\": " << jsonList(r.boundary_indices)
        << ",\n  \"border_indices\": " << jsonList(border)
        << ",\n  \"tiles\": {\"count\": " << r.tiling.tiles
        << ", \"halo_points\": " << r.tiling.halo_points
        << ", \"largest\": " << r.tiling.largest_tile
        << ", \"patches_flipped\": " << r.tiling.patches_flipped
        << ", \"seam_filled\": " << r.tiling.seam_filled
        << ", \"work_mb\": " << double(r.disk_bytes) / 1048576.0
        << "},\n  \"timings_ms\": {\"cut\": " << r.tiling.cut_ms
        << ", \"tiles\": " << r.tiling.tiles_ms
        << ", \"stitch\": " << r.tiling.stitch_ms << ", \"total\": " << total_ms
        << "}\n}\n";
    std::string error;
    if (!cocone_app::writeText(o.report_file, out.str(), error))
      fail(error);
  }
  return 0;
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc < 2 || find_switch(argc, argv, "-h") || find_switch(argc, argv, "--help")) {
    printHelp(argv[0]);
    return argc < 2 ? 1 : 0;
  }
  if (find_switch(argc, argv, "-v"))
    setVerbosityLevel(L_DEBUG);
  else if (find_switch(argc, argv, "-q"))
    setVerbosityLevel(L_ERROR);
  const Options o = parseOptions(argc, argv);
  // Off-screen rendering needs an X server: run again under a virtual one.
  if (!o.screenshot_file.empty() && !std::getenv("DISPLAY") &&
      !std::getenv("COCONE_UNDER_XVFB"))
    cocone_app::reexecUnderXvfb(argc, argv);

  // A cloud that does not fit in memory, even in tiles of a million points, is
  // streamed through files (a binary .ply or .pcd; others are read whole).
  {
    std::string why;
    std::size_t count = 0;
    std::unique_ptr<pcl::cocone::PointSource> stream =
        cocone_app::openPointStream(o.input, count, why);
    if (o.out_of_core && !stream)
      fail("-out_of_core: " + why);
    if (stream && (o.out_of_core || o.automatic_tiles)) {
      const std::size_t budget = o.memory_mb > 0.0
                                     ? static_cast<std::size_t>(o.memory_mb * 1048576.0)
                                     : pcl::cocone::availableMemory();
      const unsigned threads = static_cast<unsigned>(o.threads);
      bool fits = true, in_memory_fits = true;
      pcl::cocone::TilingOptions tiling =
          pcl::cocone::automaticOutOfCoreTiling(count, budget, threads, &fits);
      pcl::cocone::automaticTiling(count, budget, threads, &in_memory_fits);
      // In memory while it fits, in tiles if need be (no disk traffic, every output
      // available); otherwise out of core, unless an output needs the cloud.
      const bool memory_outputs = cocone_app::extension(o.output) != "ply" ||
                                  !o.boundary_file.empty() ||
                                  !o.outliers_file.empty() || !o.normals_file.empty() ||
                                  !o.screenshot_file.empty() || o.refine_holes;
      const bool streamed =
          o.out_of_core || (budget > 0 && !in_memory_fits && !memory_outputs);
      if (streamed && o.automatic_tiles && !fits)
        print_warn("Warning: %zu points likely need more than %.0f MB even in tiles of "
                   "%zu points out of core.\n",
                   count,
                   budget / 1048576.0,
                   tiling.tile_points);
      if (streamed) {
        if (!o.automatic_tiles) {
          tiling.tile_points = o.tile_points;
          tiling.tiles_in_flight = 0;
        }
        if (tiling.tile_points < pcl::cocone::MINIMUM_TILE_POINTS)
          fail("-out_of_core needs tiles of at least " +
               std::to_string(pcl::cocone::MINIMUM_TILE_POINTS) + " points");
        return reconstructOutOfCore(o, *stream, tiling);
      }
    }
  }

  pcl::StopWatch total;
  pcl::StopWatch watch;
  std::string error;
  pcl::PCLPointCloud2 blob;
  if (!cocone_app::readCloud(o.input, blob, error))
    fail(error);
  std::vector<Eigen::Vector3d> xyz;
  if (!cocone_app::extractXYZ(blob, xyz, error))
    fail("'" + o.input + "': " + error);
  const double load_ms = watch.getTime();
  print_info(
      "Loaded %zu points from %s in %.0f ms.\n", xyz.size(), o.input.c_str(), load_ms);

  // Subtract a common offset in double precision before the library's float points:
  // georeferenced coordinates keep their precision. The output keeps the input's own
  // fields and values.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  std::size_t finite = 0;
  for (const auto& p : xyz)
    if (p.allFinite()) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      ++finite;
    }
  const Eigen::Vector3d offset =
      finite ? Eigen::Vector3d(0.5 * (lo + hi)) : Eigen::Vector3d::Zero();
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->resize(xyz.size());
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    const Eigen::Vector3d q = xyz[i] - offset;
    (*cloud)[i].getVector3fMap() = q.cast<float>();
  }
  cloud->width = blob.width;
  cloud->height = blob.height;
  cloud->is_dense = finite == xyz.size();

  // The tiles: one piece if it fits the memory, else the largest tiles that do (as
  // many at once as fit and there are threads; the mesh does not depend on that).
  std::size_t tile_points = o.tile_points;
  unsigned tiles_in_flight = 0; // one per thread
  if (o.automatic_tiles) {
    const std::size_t budget = o.memory_mb > 0.0
                                   ? static_cast<std::size_t>(o.memory_mb * 1048576.0)
                                   : pcl::cocone::availableMemory();
    bool fits = true;
    const pcl::cocone::TilingOptions tiling = pcl::cocone::automaticTiling(
        finite, budget, static_cast<unsigned>(o.threads), &fits);
    tile_points = tiling.tile_points;
    tiles_in_flight = tiling.tiles_in_flight;
    if (tile_points > 0)
      print_info("%zu points do not fit %.0f MB in one piece: tiles of at most %zu "
                 "points, %u at a time.\n",
                 finite,
                 budget / 1048576.0,
                 tile_points,
                 tiles_in_flight);
    if (!fits)
      print_warn("Warning: %zu points likely need more than %.0f MB even in tiles of "
                 "%zu points (the cloud and the stitched mesh are held in memory).\n",
                 finite,
                 budget / 1048576.0,
                 tile_points);
  }

  pcl::CoConeBoundary<pcl::PointXYZ> cocone;
  cocone.setInputCloud(cloud);
  cocone.setRatio(o.ratio);
  cocone.setSpacingFactor(o.spacing_factor);
  cocone.setGapAngle(o.gap_angle);
  cocone.setNormalAngle(o.normal_angle);
  cocone.setCoconeAngle(o.cocone_angle);
  cocone.setBoundaryDetection(o.boundary_detection);
  cocone.setNoiseHandling(o.noise_handling);
  cocone.setFillUndersampledHoles(o.fill_holes);
  cocone.setMaxHoleWidth(o.hole_width);
  cocone.setRefineFilledHoles(o.refine_holes);
  cocone.setNumberOfThreads(static_cast<unsigned>(o.threads));
  cocone.setTilePoints(tile_points);
  cocone.setTilesInFlight(tiles_in_flight);
  pcl::PointCloud<pcl::PointXYZ> points; // the input, then any added vertices
  std::vector<pcl::Vertices> polygons;
  cocone.reconstruct(points, polygons);
  if (cocone.getNumberOfUniquePoints() == 0)
    fail("no reconstruction: the cloud has fewer than 4 distinct finite points or "
         "they are collinear");
  const auto& t = cocone.getTimings();
  print_info("Delaunay %.0f ms, Voronoi %.0f ms, noise %.0f ms, boundary %.0f ms "
             "(rho %.2f), reconstruction %.0f ms.\n",
             t.unique + t.delaunay,
             t.voronoi,
             t.noise,
             t.boundary,
             cocone.getUsedRatio(),
             t.reconstruction);

  pcl::PointIndices boundary;
  cocone.getBoundaryPointIndices(boundary);
  pcl::PointIndices outliers;
  cocone.getOutlierIndices(outliers);
  if (o.noise_handling)
    print_debug("Noise level %.3f (about sigma in sample spacings), %s; %zu "
                "outliers.\n",
                cocone.getNoiseLevel(),
                cocone.isSmoothed() ? "smoothed" : "not smoothed",
                outliers.indices.size());
  else
    print_debug("Noise handling off (-no_denoise).\n");
  std::vector<pcl::Vertices> loops, filled;
  cocone.getBoundaryLoops(loops);
  cocone.getFilledHoles(filled);
  std::vector<int> filled_sizes;
  for (const auto& rim : filled)
    filled_sizes.push_back(static_cast<int>(rim.vertices.size()));

  pcl::PolygonMesh mesh;
  mesh.header = blob.header;
  mesh.cloud = blob;
  const std::size_t n = xyz.size();
  // The vertices -refine_holes added follow the input's points.
  std::vector<Eigen::Vector3d> added;
  for (std::size_t i = n; i < points.size(); ++i)
    added.push_back(points[i].getVector3fMap().cast<double>() + offset);
  cocone_app::appendPoints(mesh.cloud, added);
  if (!cocone_app::hasColour(blob)) {
    // Undersampled points red, the rest light grey: pcl_viewer shades the triangles
    // around the boundary points.
    std::vector<std::uint32_t> rgb(n + added.size(), 0xffc8c8c8u);
    for (const int i : boundary.indices)
      rgb[i] = 0xffc81e1eu;
    std::vector<std::uint32_t> bits(rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) {
      float f;
      std::memcpy(&f, &rgb[i], 4);
      std::memcpy(&bits[i], &f, 4);
    }
    cocone_app::appendField(mesh.cloud, "rgb", pcl::PCLPointField::FLOAT32, bits);
  }

  // Components and border vertices for the report.
  std::vector<pcl::cocone::Triangle> tris;
  tris.reserve(polygons.size());
  for (const auto& p : polygons)
    tris.push_back({p.vertices[0], p.vertices[1], p.vertices[2]});
  std::size_t components = 0;
  pcl::cocone::triangleComponents(tris, &components);
  const std::vector<int> border = pcl::cocone::borderVertices(tris);
  std::vector<pcl::cocone::Triangle>().swap(tris);
  const std::size_t triangles = polygons.size();
  mesh.polygons = std::move(polygons); // not copied: a mesh's polygons weigh
  print_info("%zu triangles, %zu components, %zu border loops, %zu undersampled "
             "points, %zu undersampled holes closed.\n",
             triangles,
             components,
             loops.size(),
             boundary.indices.size(),
             filled.size());

  watch.reset();
  if (!cocone_app::writeMesh(o.output, mesh, error))
    fail(error);
  written.push_back(o.output);
  if (!o.boundary_file.empty()) {
    pcl::PCLPointCloud2 points;
    pcl::copyPointCloud(blob, boundary.indices, points);
    std::vector<std::uint32_t> index(boundary.indices.begin(), boundary.indices.end());
    cocone_app::appendField(points, "index", pcl::PCLPointField::UINT32, index);
    if (!cocone_app::writeCloud(o.boundary_file, points, error))
      fail(error);
    written.push_back(o.boundary_file);
  }
  if (!o.outliers_file.empty()) {
    pcl::PCLPointCloud2 points;
    pcl::copyPointCloud(blob, outliers.indices, points);
    std::vector<std::uint32_t> index(outliers.indices.begin(), outliers.indices.end());
    cocone_app::appendField(points, "index", pcl::PCLPointField::UINT32, index);
    if (!cocone_app::writeCloud(o.outliers_file, points, error))
      fail(error);
    written.push_back(o.outliers_file);
  }
  if (!o.normals_file.empty()) {
    pcl::PointCloud<pcl::Normal> normals;
    cocone.getPointNormals(normals);
    pcl::PCLPointCloud2 out = blob;
    std::vector<float> c[3];
    for (const auto& nrm : normals)
      for (int k = 0; k < 3; ++k)
        c[k].push_back(nrm.normal[k]);
    cocone_app::setFloatField(out, "normal_x", c[0]);
    cocone_app::setFloatField(out, "normal_y", c[1]);
    cocone_app::setFloatField(out, "normal_z", c[2]);
    if (!cocone_app::writeCloud(o.normals_file, out, error))
      fail(error);
    written.push_back(o.normals_file);
  }
  if (!o.screenshot_file.empty() &&
      !cocone_app::renderScreenshot(
          mesh, blob, boundary.indices, o.screenshot_file, error))
    fail(error);
  if (!o.screenshot_file.empty())
    written.push_back(o.screenshot_file);
  const double save_ms = watch.getTime();
  const double total_ms = total.getTime();
  print_info(
      "Wrote %s in %.0f ms; total %.0f ms.\n", o.output.c_str(), save_ms, total_ms);

  if (!o.report_file.empty()) {
    std::ostringstream r;
    r.precision(17);
    r << "{\n  \"input\": " << jsonString(o.input) << ",\n  \"points\": " << n
      << ",\n  \"finite_points\": " << finite
      << ",\n  \"unique_points\": " << cocone.getNumberOfUniquePoints()
      << ",\n  \"parameters\": {\"ratio\": " << cocone.getUsedRatio()
      << ", \"gap_angle\": " << o.gap_angle << ", \"normal_angle\": " << o.normal_angle
      << ", \"cocone_angle\": " << o.cocone_angle
      << ", \"boundary_detection\": " << (o.boundary_detection ? "true" : "false")
      << ", \"noise_handling\": " << (o.noise_handling ? "true" : "false")
      << ", \"fill_undersampled_holes\": " << (o.fill_holes ? "true" : "false")
      << ", \"hole_width\": " << o.hole_width
      << ", \"refine_filled_holes\": " << (o.refine_holes ? "true" : "false")
      << ", \"tile_points\": " << tile_points
      << ", \"automatic_tiles\": " << (o.automatic_tiles ? "true" : "false")
      << ", \"threads\": " << o.threads
      << "},\n  \"noise\": {\"level\": " << cocone.getNoiseLevel()
      << ", \"after_smoothing\": " << cocone.getNoiseLevelAfterSmoothing()
      << ", \"smoothed\": " << (cocone.isSmoothed() ? "true" : "false")
      << "},\n  \"outliers\": " << outliers.indices.size()
      << ",\n  \"outlier_indices\": " << jsonList(outliers.indices)
      << ",\n  \"unmeshed_part_triangles\": "
      << cocone.getReconstructionCounts().unmeshed_parts
      << ",\n  \"true_borders\": " << cocone.getReconstructionCounts().true_borders
      << ",\n  \"holes_filled\": " << filled.size()
      << ",\n  \"filled_hole_sizes\": " << jsonList(filled_sizes)
      << ",\n  \"hole_triangles\": " << cocone.getReconstructionCounts().hole_triangles
      << ",\n  \"handles_cut\": " << cocone.getReconstructionCounts().handles_cut
      << ",\n  \"necks_cut\": " << cocone.getReconstructionCounts().necks_cut
      << ",\n  \"added_points\": " << added.size()
      << ",\n  \"triangles\": " << triangles << ",\n  \"components\": " << components
      << ",\n  \"boundary_loops\": " << loops.size()
      << ",\n  \"boundary_indices\": " << jsonList(boundary.indices)
      << ",\n  \"border_indices\": " << jsonList(border) << ",\n  \"timings_ms\": {"
      << "\"load\": " << load_ms << ", \"delaunay\": " << t.unique + t.delaunay
      << ", \"voronoi\": " << t.voronoi << ", \"noise\": " << t.noise
      << ", \"boundary\": " << t.boundary
      << ", \"reconstruction\": " << t.reconstruction << ", \"total\": " << total_ms
      << ", \"save\": " << save_ms << "}\n}\n";
    if (!cocone_app::writeText(o.report_file, r.str(), error))
      fail(error);
  }
  return 0;
}
