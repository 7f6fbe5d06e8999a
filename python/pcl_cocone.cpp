/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Python bindings (the extension _pcl_cocone of the package pcl_cocone): the points
 * come in as a NumPy array, go to pcl::cocone::run() without the GIL, and the mesh,
 * the boundary and the report come back as NumPy arrays and a dict.
 */

#include <pcl/surface/cocone/pipeline.h>
#include <pcl/surface/cocone/tiling.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace py = pybind11;
namespace cocone = pcl::cocone;

namespace {

/** tile_points="auto", until the points are known (resolveTiles()). */
constexpr std::size_t AUTOMATIC_TILES = std::numeric_limits<std::size_t>::max();

/** tile_points="auto" made a size for \a points: as the command-line tool's
 * -tile_points auto, one piece if it fits the memory available, else the largest
 * tiles that do, as many at once as fit and there are threads. */
void
resolveTiles(cocone::TilingOptions& tiling,
             std::size_t points,
             const cocone::Parameters& parameters)
{
  if (tiling.tile_points != AUTOMATIC_TILES)
    return;
  const cocone::TilingOptions automatic =
      cocone::automaticTiling(points, cocone::availableMemory(), parameters.threads);
  tiling.tile_points = automatic.tile_points;
  tiling.tiles_in_flight = automatic.tiles_in_flight;
}

/** What reconstruct() and detect_boundary() return. */
struct Result {
  py::array triangles;        ///< (M, 3) int32, input indices
  py::array boundary_indices; ///< int32, ascending
  py::list border_loops;      ///< int32 arrays of input indices
  py::list filled_holes;      ///< int32 arrays: the rims of the holes closed
  py::array added_points;     ///< (K, 3) float64: vertices added inside them
  py::array normals;          ///< (N, 3) float64, NaN where not in the mesh
  py::array outlier_indices;  ///< int32, ascending
  py::array point_noise;      ///< (N,) float32, NaN where unknown
  py::dict report;
};

const char* const PARAMETER_NAMES =
    "ratio, spacing_factor, gap_angle, normal_angle, cocone_angle, boundary_detection, "
    "noise_handling, noise_threshold, smoothing_iterations, fill_undersampled_holes, "
    "hole_width, refine_filled_holes, threads, tile_points and halo_spacings (not for "
    "detect_boundary)";

/** A float parameter: a real number (not a bool, not a string). */
double
toDouble(const char* function, const std::string& name, const py::handle& value)
{
  PyObject* o = value.ptr();
  if (PyBool_Check(o) || PyUnicode_Check(o) || PyBytes_Check(o) || !PyNumber_Check(o))
    throw py::type_error(std::string(function) + "(): parameter '" + name +
                         "' must be a number, not " + std::string(Py_TYPE(o)->tp_name));
  const double d = PyFloat_AsDouble(o);
  if (d == -1.0 && PyErr_Occurred())
    throw py::error_already_set();
  return d;
}

void
requireValue(bool ok,
             const char* function,
             const std::string& name,
             const char* rule,
             double value)
{
  if (!ok)
    throw py::value_error(std::string(function) + "(): " + name + " must be " + rule +
                          " (got " + py::repr(py::float_(value)).cast<std::string>() +
                          ")");
}

/** A bool parameter: bool or numpy.bool_ (an int would hide a mistaken argument). */
bool
toBool(const char* function, const std::string& name, const py::handle& value)
{
  const py::object numpy_bool = py::module_::import("numpy").attr("bool_");
  if (!PyBool_Check(value.ptr()) && !py::isinstance(value, numpy_bool))
    throw py::type_error(std::string(function) + "(): parameter '" + name +
                         "' must be a bool, not " +
                         std::string(Py_TYPE(value.ptr())->tp_name));
  return PyObject_IsTrue(value.ptr()) == 1;
}

/** An int parameter (not a bool) in [low, INT_MAX]; \a rule says what it must be. */
int
toInt(const char* function,
      const std::string& name,
      const py::handle& value,
      long long low,
      const char* rule)
{
  if (PyBool_Check(value.ptr()) || !PyIndex_Check(value.ptr()))
    throw py::type_error(std::string(function) + "(): parameter '" + name +
                         "' must be an int, not " +
                         std::string(Py_TYPE(value.ptr())->tp_name));
  const py::object index =
      py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index)
    throw py::error_already_set();
  int overflow = 0;
  long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow != 0)
    v = overflow < 0 ? std::numeric_limits<long long>::min()
                     : std::numeric_limits<long long>::max();
  if (v < low || v > std::numeric_limits<int>::max())
    throw py::value_error(std::string(function) + "(): " + name + " must be " + rule +
                          ", got " + py::repr(value).cast<std::string>());
  return static_cast<int>(v);
}

/** The keyword arguments as cocone::Parameters, with the setters' rules
 * (include/pcl/surface/impl/cocone_boundary.hpp): an unknown name is a TypeError, a
 * value outside its range a ValueError. */
cocone::Parameters
parseParameters(const char* function,
                const py::kwargs& kwargs,
                cocone::TilingOptions* tiling = nullptr)
{
  cocone::Parameters p;
  for (const auto& item : kwargs) {
    const std::string name = py::str(item.first);
    const py::handle value = item.second;
    if (name == "ratio") {
      p.ratio = toDouble(function, name, value);
      requireValue(std::isfinite(p.ratio) && p.ratio >= 0.0,
                   function,
                   name,
                   "finite and positive, or 0 for automatic",
                   p.ratio);
    }
    else if (name == "spacing_factor") {
      p.spacing_factor = toDouble(function, name, value);
      requireValue(std::isfinite(p.spacing_factor) && p.spacing_factor >= 0.0,
                   function,
                   name,
                   "finite and >= 0 (0: off)",
                   p.spacing_factor);
    }
    else if (name == "gap_angle") {
      p.gap_angle = toDouble(function, name, value);
      requireValue(p.gap_angle >= 0.0 && p.gap_angle < M_PI,
                   function,
                   name,
                   "in [0, pi) radians (0: off)",
                   p.gap_angle);
    }
    else if (name == "normal_angle") {
      p.normal_angle = toDouble(function, name, value);
      requireValue(p.normal_angle > 0.0 && p.normal_angle <= M_PI / 2.0,
                   function,
                   name,
                   "in (0, pi/2] radians",
                   p.normal_angle);
    }
    else if (name == "cocone_angle") {
      p.cocone_angle = toDouble(function, name, value);
      requireValue(p.cocone_angle > 0.0 && p.cocone_angle < M_PI / 2.0,
                   function,
                   name,
                   "in (0, pi/2) radians",
                   p.cocone_angle);
    }
    else if (name == "boundary_detection")
      p.boundary_detection = toBool(function, name, value);
    else if (name == "noise_handling")
      p.noise_handling = toBool(function, name, value);
    else if (name == "fill_undersampled_holes")
      p.fill_undersampled_holes = toBool(function, name, value);
    else if (name == "refine_filled_holes")
      p.refine_filled_holes = toBool(function, name, value);
    else if (name == "hole_width") {
      p.hole_width = toDouble(function, name, value);
      requireValue(std::isfinite(p.hole_width) && p.hole_width >= 0.0,
                   function,
                   name,
                   ">= 0",
                   p.hole_width);
    }
    else if (name == "noise_threshold") {
      p.noise_threshold = toDouble(function, name, value);
      requireValue(std::isfinite(p.noise_threshold) && p.noise_threshold >= 0.0,
                   function,
                   name,
                   "finite and >= 0",
                   p.noise_threshold);
    }
    else if (name == "smoothing_iterations")
      p.smoothing_iterations = toInt(function, name, value, 1, ">= 1");
    else if (name == "threads")
      p.threads = static_cast<unsigned int>(
          toInt(function, name, value, 0, ">= 0 (0: all processors)"));
    else if (name == "tile_points" && tiling && py::isinstance<py::str>(value) &&
             value.cast<std::string>() == "auto")
      tiling->tile_points = AUTOMATIC_TILES; // resolved once the points are known
    else if (name == "tile_points" && tiling) {
      const int points =
          toInt(function, name, value, 0, ">= 0 (0: one piece) or \"auto\"");
      requireValue(
          points == 0 ||
              static_cast<std::size_t>(points) >= cocone::MINIMUM_TILE_POINTS,
          function,
          name,
          ("0 (one piece) or at least " + std::to_string(cocone::MINIMUM_TILE_POINTS))
              .c_str(),
          static_cast<double>(points));
      tiling->tile_points = static_cast<std::size_t>(points);
    }
    else if (name == "halo_spacings" && tiling) {
      tiling->halo_spacings = toDouble(function, name, value);
      requireValue(std::isfinite(tiling->halo_spacings) && tiling->halo_spacings >= 0.0,
                   function,
                   name,
                   "finite and >= 0",
                   tiling->halo_spacings);
    }
    else
      throw py::type_error(std::string(function) +
                           "() got an unexpected keyword argument '" + name +
                           "' (parameters: " + PARAMETER_NAMES + ")");
  }
  return p;
}

/** The points as a NumPy array of shape (N, 3) and native float64 or float32, read
 * in place: any other real dtype is converted to float64 first (one copy). */
py::array
pointArray(const char* function, const py::object& points)
{
  py::array array = py::array::ensure(points);
  if (!array)
    throw py::type_error(std::string(function) +
                         "(): points must be an array of shape (N, 3), not " +
                         std::string(Py_TYPE(points.ptr())->tp_name));
  const py::dtype dtype = array.dtype();
  const char kind = dtype.kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(std::string(function) +
                         "(): points must be real numbers (float64 or float32), got "
                         "dtype " +
                         py::str(py::object(dtype)).cast<std::string>());
  if (array.ndim() != 2 || array.shape(1) != 3)
    throw py::value_error(std::string(function) +
                          "(): points must be an array of shape (N, 3), got " +
                          py::str(py::object(array.attr("shape"))).cast<std::string>());
  if (array.shape(0) > std::numeric_limits<int>::max())
    throw py::value_error(std::string(function) + "(): more than 2^31 - 1 points");
  const bool native = dtype.attr("isnative").cast<bool>();
  if (kind == 'f' && native && (dtype.itemsize() == 8 || dtype.itemsize() == 4))
    return array;
  return array.attr("astype")("float64"); // integers, float16, long double, swapped
}

/** The one copy of the points: straight from the array's buffer (any strides) into
 * the vector run() takes. */
template <typename T>
std::vector<Eigen::Vector3d>
readPoints(const py::array& array)
{
  const auto n = static_cast<std::size_t>(array.shape(0));
  const auto s0 = array.strides(0), s1 = array.strides(1);
  const char* base = static_cast<const char*>(array.data());
  std::vector<Eigen::Vector3d> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* row = base + static_cast<py::ssize_t>(i) * s0;
    T xyz[3];
    for (int k = 0; k < 3; ++k) // memcpy: the buffer need not be aligned
      std::memcpy(&xyz[k], row + k * s1, sizeof(T));
    points[i] = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
  }
  return points;
}

/** A NumPy array that owns \a v's storage (no copy). */
template <typename T>
py::array_t<T>
ownedArray(std::vector<T>&& v, std::vector<py::ssize_t> shape)
{
  auto* owner = new std::vector<T>(std::move(v));
  py::capsule capsule(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(std::move(shape), owner->data(), capsule);
}

py::array_t<int>
indexArray(std::vector<int>&& v)
{
  const auto n = static_cast<py::ssize_t>(v.size());
  return ownedArray(std::move(v), {n});
}

// OUTLIERS: the outliers are added to cocone::Result by another change
// (Result::outlier_indices, the caller ids of the points set aside, ascending). Until
// the core has them, outlier_indices is an empty array; once the field exists it is
// taken from there, with nothing else to change here.
template <typename R, typename = void>
struct HasOutliers : std::false_type {};
template <typename R>
struct HasOutliers<R, std::void_t<decltype(std::declval<R&>().outlier_indices)>>
: std::true_type {};

template <typename R>
std::vector<int>
takeOutliers(R& result)
{
  if constexpr (HasOutliers<R>::value)
    return std::vector<int>(std::move(result.outlier_indices));
  else
    return {};
}

py::dict
parametersDict(const cocone::Parameters& p, const cocone::TilingOptions& tiling = {})
{
  py::dict d;
  d["ratio"] = p.ratio;
  d["spacing_factor"] = p.spacing_factor;
  d["gap_angle"] = p.gap_angle;
  d["normal_angle"] = p.normal_angle;
  d["cocone_angle"] = p.cocone_angle;
  d["boundary_detection"] = p.boundary_detection;
  d["noise_handling"] = p.noise_handling;
  d["fill_undersampled_holes"] = p.fill_undersampled_holes;
  d["refine_filled_holes"] = p.refine_filled_holes;
  d["hole_width"] = p.hole_width;
  d["noise_threshold"] = p.noise_threshold;
  d["smoothing_iterations"] = p.smoothing_iterations;
  d["threads"] = p.threads;
  d["tile_points"] = tiling.tile_points;
  d["halo_spacings"] = tiling.halo_spacings;
  return d;
}

/** The points of \a points (see pointArray()) as the vector run() takes; call without
 * the GIL. */
std::vector<Eigen::Vector3d>
readPointArray(const py::array& array)
{
  return array.dtype().itemsize() == 4 ? readPoints<float>(array)
                                       : readPoints<double>(array);
}

py::dict
tilingDict(const cocone::TilingReport& t)
{
  py::dict d;
  d["tiles"] = t.tiles;
  d["halo_points"] = t.halo_points;
  d["largest_tile"] = t.largest_tile;
  d["patches"] = t.patches;
  d["patches_flipped"] = t.patches_flipped;
  d["seam_dropped"] = t.seam_dropped;
  d["seam_filled"] = t.seam_filled;
  d["degenerate_tiles"] = t.degenerate_tiles;
  d["cut_ms"] = t.cut_ms;
  d["tiles_ms"] = t.tiles_ms;
  d["stitch_ms"] = t.stitch_ms;
  return d;
}

/** The Python Result of \a r, a run over \a n points; \a tiling_report if the
 * run was tiled. */
Result
toPython(cocone::Result& r,
         std::size_t n,
         cocone::Stages stages,
         const cocone::Parameters& parameters,
         const cocone::TilingOptions& tiling,
         const cocone::TilingReport* tiling_report,
         double input_ms,
         double run_ms)
{
  Result out;
  // Normals per input point: its vertex's, NaN for points not in the mesh and for the
  // points that are not finite (or set aside).
  const double nan = std::numeric_limits<double>::quiet_NaN();
  py::array_t<double> normals({static_cast<py::ssize_t>(n), py::ssize_t(3)});
  {
    double* dst = normals.mutable_data();
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < n; ++i) {
      const int v = r.vertex_of_input[i];
      const bool known = v >= 0 && static_cast<std::size_t>(v) < r.normals.size();
      for (int k = 0; k < 3; ++k)
        dst[3 * i + k] = known ? r.normals[v][k] : nan;
    }
  }
  std::size_t finite = 0;
  for (const int v : r.vertex_of_input)
    finite += v != -1;

  const std::size_t triangle_count = r.polygons.size();
  const std::size_t boundary_count = r.boundary_indices.size();
  const std::size_t loop_count = r.border_loops.size();
  static_assert(sizeof(cocone::Triangle) == 3 * sizeof(int), "a triangle is 3 ints");
  std::vector<int> corners(3 * triangle_count);
  if (triangle_count > 0)
    std::memcpy(corners.data(), r.polygons.data(), corners.size() * sizeof(int));
  std::vector<cocone::Triangle>().swap(r.polygons);
  out.triangles = ownedArray(
      std::move(corners), {static_cast<py::ssize_t>(triangle_count), py::ssize_t(3)});
  out.boundary_indices = indexArray(std::move(r.boundary_indices));
  for (auto& loop : r.border_loops)
    out.border_loops.append(indexArray(std::move(loop)));
  // The vertices refineFilledHoles() added: points n, n + 1, ... of the triangles.
  std::vector<double> added;
  for (std::size_t v = r.positions.size() - r.added_vertices; v < r.positions.size();
       ++v)
    for (int k = 0; k < 3; ++k)
      added.push_back(r.positions[v][k] + r.offset[k]);
  out.added_points = ownedArray(
      std::move(added), {static_cast<py::ssize_t>(r.added_vertices), py::ssize_t(3)});
  py::list filled_sizes;
  for (auto& rim : r.filled_holes) {
    filled_sizes.append(rim.size());
    out.filled_holes.append(indexArray(std::move(rim)));
  }
  out.normals = normals;
  std::vector<int> outliers = takeOutliers(r);
  const std::size_t outlier_count = outliers.size();
  out.outlier_indices = indexArray(std::move(outliers));
  // The noise level per input point; the core leaves it empty without noise handling
  // (and where it could not read it): NaN then.
  if (r.point_noise.size() != n)
    r.point_noise.assign(n, std::numeric_limits<float>::quiet_NaN());
  out.point_noise = ownedArray(std::move(r.point_noise), {static_cast<py::ssize_t>(n)});

  const cocone::Timings& t = r.timings;
  py::dict timings;
  timings["input"] = input_ms; // reading the array
  timings["unique"] = t.unique;
  timings["delaunay"] = t.delaunay;
  timings["voronoi"] = t.voronoi;
  timings["noise"] = t.noise;
  timings["boundary"] = t.boundary;
  timings["reconstruction"] = t.reconstruction;
  timings["run"] = run_ms; // all of cocone::run()

  const cocone::ReconstructionCounts& c = r.counts;
  py::dict repair;
  repair["nonmanifold_edge"] = c.repair.nonmanifold_edge;
  repair["nonmanifold_vertex"] = c.repair.nonmanifold_vertex;
  repair["orientation"] = c.repair.orientation;
  repair["flipped"] = c.repair.flipped;
  repair["filled"] = c.repair.filled;
  repair["ribbon"] = c.repair.ribbon;
  repair["speck"] = c.repair.speck;
  repair["peeled"] = c.repair.peeled;
  py::dict counts;
  counts["candidates"] = c.candidates;
  counts["umbrella_failures"] = c.umbrella_failures;
  counts["pruned"] = c.pruned;
  counts["walk_components"] = c.walk_components;
  counts["walked"] = c.walked;
  counts["walk_conflicts"] = c.walk_conflicts;
  counts["walk_reseeds"] = c.walk_reseeds;
  counts["repair"] = repair;
  counts["unmeshed_parts"] = c.unmeshed_parts;
  counts["true_borders"] = c.true_borders;
  counts["holes_filled"] = c.holes_filled;
  counts["hole_triangles"] = c.hole_triangles;
  counts["handles_cut"] = c.handles_cut;
  counts["necks_cut"] = c.necks_cut;

  py::dict& report = out.report;
  report["stages"] = stages == cocone::Stages::RECONSTRUCTION ? "reconstruction"
                                                              : "boundary_detection";
  report["points"] = n;
  report["finite_points"] = finite;
  report["unique_points"] = r.vertices;
  report["triangles"] = triangle_count;
  report["boundary_points"] = boundary_count;
  report["border_loops"] = loop_count;
  report["holes_filled"] = py::len(filled_sizes);
  report["filled_hole_sizes"] = filled_sizes;
  report["added_points"] = r.added_vertices;
  report["outliers"] = outlier_count;
  report["noise_level"] = r.noise_level; // about sigma in sample spacings
  report["noise_after_smoothing"] = r.noise_after_smoothing;
  report["smoothed"] = r.smoothed;
  report["ratio"] = r.ratio; // the one used: the automatic one when ratio is 0
  report["parameters"] = parametersDict(parameters, tiling);
  report["timings_ms"] = timings;
  report["counts"] = counts;
  if (tiling_report)
    report["tiling"] = tilingDict(*tiling_report);
  return out;
}

Result
runPipeline(const char* function,
            const py::object& points,
            const py::kwargs& kwargs,
            cocone::Stages stages)
{
  cocone::TilingOptions tiling;
  const cocone::Parameters parameters = parseParameters(
      function, kwargs, stages == cocone::Stages::RECONSTRUCTION ? &tiling : nullptr);
  const py::array array = pointArray(function, points);
  const auto n = static_cast<std::size_t>(array.shape(0));

  cocone::Result r;
  cocone::TilingReport tiling_report;
  double input_ms = 0.0, run_ms = 0.0;
  {
    // The array stays referenced (by `array`) while the GIL is released; nothing here
    // touches a Python object.
    py::gil_scoped_release release;
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    std::vector<Eigen::Vector3d> xyz = readPointArray(array);
    resolveTiles(tiling, xyz.size(), parameters);
    const auto t1 = Clock::now();
    r = tiling.tile_points > 0
            ? cocone::runTiled(std::move(xyz), parameters, tiling, {}, &tiling_report)
            : cocone::run(std::move(xyz), parameters, stages);
    const auto t2 = Clock::now();
    input_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    run_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  }
  if (!r.error.empty())
    throw std::runtime_error(std::string(function) + "(): " + r.error);
  return toPython(r,
                  n,
                  stages,
                  parameters,
                  tiling,
                  tiling.tile_points > 0 ? &tiling_report : nullptr,
                  input_ms,
                  run_ms);
}

// Tiles: the phases of runTiled() (include/pcl/surface/cocone/tiling.h), so that the
// tiles can run in other processes (pcl_cocone.tiled runs them on a Dask cluster).

static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "a position is 3 doubles");

/** Call \a f(name, field) for every count of \a c (the names of the report's). */
template <typename Counts, typename F>
void
eachCount(Counts& c, const F& f)
{
  f("candidates", c.candidates);
  f("umbrella_failures", c.umbrella_failures);
  f("pruned", c.pruned);
  f("walk_components", c.walk_components);
  f("walked", c.walked);
  f("walk_conflicts", c.walk_conflicts);
  f("walk_reseeds", c.walk_reseeds);
  f("repair.nonmanifold_edge", c.repair.nonmanifold_edge);
  f("repair.nonmanifold_vertex", c.repair.nonmanifold_vertex);
  f("repair.orientation", c.repair.orientation);
  f("repair.flipped", c.repair.flipped);
  f("repair.filled", c.repair.filled);
  f("repair.ribbon", c.repair.ribbon);
  f("repair.speck", c.repair.speck);
  f("repair.peeled", c.repair.peeled);
  f("unmeshed_parts", c.unmeshed_parts);
  f("true_borders", c.true_borders);
  f("holes_filled", c.holes_filled);
  f("hole_triangles", c.hole_triangles);
  f("handles_cut", c.handles_cut);
  f("necks_cut", c.necks_cut);
}

template <typename Timings, typename F>
void
eachTiming(Timings& t, const F& f)
{
  f("unique", t.unique);
  f("delaunay", t.delaunay);
  f("noise", t.noise);
  f("voronoi", t.voronoi);
  f("boundary", t.boundary);
  f("reconstruction", t.reconstruction);
}

/** A copy of \a v as an array of \a columns columns of \a S (rows of \a T). NumPy
 * owns the copy, so that Dask's serialization sends it like any array (it cannot
 * pickle the capsule of ownedArray()). */
template <typename S, typename T>
py::array_t<S>
copyArray(const std::vector<T>& v, py::ssize_t columns)
{
  static_assert(sizeof(T) % sizeof(S) == 0, "rows of whole values");
  const auto size = static_cast<py::ssize_t>(v.size() * sizeof(T) / sizeof(S));
  py::array_t<S> array = columns == 1 ? py::array_t<S>(std::vector<py::ssize_t>{size})
                                      : py::array_t<S>({size / columns, columns});
  if (size > 0)
    std::memcpy(
        array.mutable_data(), v.data(), static_cast<std::size_t>(size) * sizeof(S));
  return array;
}

/** The tile result as a dict of plain values and NumPy arrays (what it pickles to). */
py::dict
tileToDict(const cocone::TileResult& o)
{
  py::dict d;
  d["error"] = o.error;
  d["degenerate"] = o.degenerate;
  d["points"] = o.points;
  d["representative"] = copyArray<int>(o.representative, 1);
  d["flags"] = copyArray<std::uint8_t>(o.flags, 1);
  d["noise"] = copyArray<float>(o.noise, 1);
  d["position"] = copyArray<double>(o.position, 3);
  d["normal"] = copyArray<double>(o.normal, 3);
  d["kept"] = copyArray<int>(o.kept, 3);
  d["seen"] = copyArray<int>(o.seen, 3);
  py::list filled;
  for (const auto& rim : o.filled_holes)
    filled.append(copyArray<int>(rim, 1));
  d["filled_holes"] = filled;
  d["ratio"] = o.ratio;
  d["noise_after_smoothing"] = o.noise_after_smoothing;
  d["smoothed"] = o.smoothed;
  py::dict counts, timings;
  eachCount(o.counts, [&](const char* name, std::size_t v) { counts[name] = v; });
  eachTiming(o.timings, [&](const char* name, double v) { timings[name] = v; });
  d["counts"] = counts;
  d["timings_ms"] = timings;
  return d;
}

/** The array \a d[name] of \a columns columns (1: one dimension) as rows of \a T. */
template <typename S, typename T>
std::vector<T>
arrayField(const py::dict& d, const char* name, py::ssize_t columns)
{
  const char* kind = std::is_floating_point_v<S> ? "real" : "integer";
  const py::array array = py::array::ensure(d[name]);
  const bool right_kind =
      array && (std::is_floating_point_v<S>
                    ? array.dtype().kind() == 'f'
                    : (array.dtype().kind() == 'i' || array.dtype().kind() == 'u'));
  const bool right_shape =
      array && (columns == 1 ? array.ndim() == 1
                             : array.ndim() == 2 && array.shape(1) == columns);
  if (!right_kind || !right_shape)
    throw py::value_error("TileResult.from_dict(): '" + std::string(name) +
                          "' must be an array of " + kind + "s with " +
                          std::to_string(columns) + " column(s)");
  const auto converted =
      py::array_t<S, py::array::c_style | py::array::forcecast>::ensure(array);
  std::vector<T> v(static_cast<std::size_t>(converted.size()) * sizeof(S) / sizeof(T));
  if (!v.empty())
    std::memcpy(static_cast<void*>(v.data()), converted.data(), v.size() * sizeof(T));
  return v;
}

cocone::TileResult
tileFromDict(const py::dict& d)
{
  for (const char* key : {"error",
                          "degenerate",
                          "points",
                          "representative",
                          "flags",
                          "noise",
                          "position",
                          "normal",
                          "kept",
                          "seen",
                          "filled_holes",
                          "ratio",
                          "noise_after_smoothing",
                          "smoothed",
                          "counts",
                          "timings_ms"})
    if (!d.contains(key))
      throw py::value_error(std::string("TileResult.from_dict(): no '") + key + "'");
  cocone::TileResult o;
  o.error = d["error"].cast<std::string>();
  o.degenerate = d["degenerate"].cast<std::string>();
  o.points = d["points"].cast<std::size_t>();
  o.representative = arrayField<int, int>(d, "representative", 1);
  o.flags = arrayField<std::uint8_t, std::uint8_t>(d, "flags", 1);
  o.noise = arrayField<float, float>(d, "noise", 1);
  o.position = arrayField<double, Eigen::Vector3d>(d, "position", 3);
  o.normal = arrayField<double, Eigen::Vector3d>(d, "normal", 3);
  o.kept = arrayField<int, cocone::Triangle>(d, "kept", 3);
  o.seen = arrayField<int, cocone::Triangle>(d, "seen", 3);
  if (!py::isinstance<py::list>(d["filled_holes"]))
    throw py::value_error("TileResult.from_dict(): 'filled_holes' must be a list");
  for (const auto& rim : d["filled_holes"].cast<py::list>()) {
    py::dict one; // each rim checked as the other arrays are
    one["filled_holes"] = rim;
    o.filled_holes.push_back(arrayField<int, int>(one, "filled_holes", 1));
  }
  o.ratio = d["ratio"].cast<double>();
  o.noise_after_smoothing = d["noise_after_smoothing"].cast<double>();
  o.smoothed = d["smoothed"].cast<bool>();
  const py::dict counts = d["counts"], timings = d["timings_ms"];
  eachCount(o.counts, [&](const char* name, std::size_t& v) {
    if (counts.contains(name))
      v = counts[name].cast<std::size_t>();
  });
  eachTiming(o.timings, [&](const char* name, double& v) {
    if (timings.contains(name))
      v = timings[name].cast<double>();
  });
  return o;
}

/** Caller ids: integers that fit an int, one per point. */
std::vector<int>
idVector(const char* function, const py::object& ids, std::size_t n)
{
  const py::array array = py::array::ensure(ids);
  if (!array || (array.dtype().kind() != 'i' && array.dtype().kind() != 'u') ||
      array.ndim() != 1)
    throw py::type_error(std::string(function) +
                         "(): ids must be a one-dimensional array of integers");
  if (static_cast<std::size_t>(array.shape(0)) != n)
    throw py::value_error(std::string(function) +
                          "(): " + std::to_string(array.shape(0)) + " ids for " +
                          std::to_string(n) + " points");
  const auto wide =
      py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(array);
  std::vector<int> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const long long v = wide.data()[i];
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      throw py::value_error(std::string(function) + "(): id " + std::to_string(v) +
                            " does not fit in 32 bits");
    out[i] = static_cast<int>(v);
  }
  return out;
}

cocone::TilePlan
planTiles(const py::object& points, const py::kwargs& kwargs)
{
  cocone::TilingOptions tiling;
  const cocone::Parameters parameters = parseParameters("plan_tiles", kwargs, &tiling);
  const py::array array = pointArray("plan_tiles", points);
  cocone::TilePlan plan;
  {
    py::gil_scoped_release release;
    std::vector<Eigen::Vector3d> xyz = readPointArray(array);
    resolveTiles(tiling, xyz.size(), parameters);
    plan = cocone::planTiles(xyz, parameters, tiling);
  }
  if (!plan.error.empty())
    throw std::runtime_error("plan_tiles(): " + plan.error);
  return plan;
}

cocone::TileResult
reconstructTile(const py::object& points,
                const py::object& ids,
                py::ssize_t core_points,
                const py::kwargs& kwargs)
{
  cocone::TilingOptions unused; // the same keywords as plan_tiles() take
  const cocone::Parameters parameters =
      parseParameters("reconstruct_tile", kwargs, &unused);
  const py::array array = pointArray("reconstruct_tile", points);
  const auto n = static_cast<std::size_t>(array.shape(0));
  const std::vector<int> id_list = idVector("reconstruct_tile", ids, n);
  if (core_points < 0 || static_cast<std::size_t>(core_points) > n)
    throw py::value_error("reconstruct_tile(): core_points must be in [0, " +
                          std::to_string(n) + "], got " + std::to_string(core_points));
  cocone::TileResult result;
  {
    py::gil_scoped_release release;
    result = cocone::reconstructTile(readPointArray(array),
                                     id_list,
                                     static_cast<std::size_t>(core_points),
                                     parameters);
  }
  if (!result.error.empty())
    throw std::runtime_error("reconstruct_tile(): " + result.error);
  return result;
}

Result
stitchTiles(const cocone::TilePlan& plan,
            const py::sequence& results,
            const py::kwargs& kwargs)
{
  cocone::TilingOptions tiling;
  const cocone::Parameters parameters =
      parseParameters("stitch_tiles", kwargs, &tiling);
  std::vector<const cocone::TileResult*> held; // alive: `results` holds them
  for (const auto item : results) {
    if (!py::isinstance<cocone::TileResult>(item))
      throw py::type_error("stitch_tiles(): results must be TileResult objects, not " +
                           std::string(Py_TYPE(item.ptr())->tp_name));
    held.push_back(&item.cast<const cocone::TileResult&>());
  }
  cocone::Result r;
  cocone::TilingReport report;
  double run_ms = 0.0;
  {
    py::gil_scoped_release release;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<cocone::TileResult> copies;
    copies.reserve(held.size());
    for (const auto* h : held)
      copies.push_back(*h);
    r = cocone::stitchTiles(plan, std::move(copies), parameters, {}, &report);
    run_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
            .count();
  }
  if (!r.error.empty())
    throw std::runtime_error("stitch_tiles(): " + r.error);
  return toPython(r,
                  plan.points,
                  cocone::Stages::RECONSTRUCTION,
                  parameters,
                  tiling,
                  &report,
                  0.0,
                  run_ms);
}

} // namespace

PYBIND11_MODULE(_pcl_cocone, m)
{
  m.doc() = "Boundary-aware Co-cone surface reconstruction (pcl_cocone_boundary).";

  py::class_<Result>(m, "Result", "What reconstruct() and detect_boundary() return.")
      .def_readonly("triangles",
                    &Result::triangles,
                    "(M, 3) int32: the oriented triangles, as indices of the input "
                    "points (empty after detect_boundary()).")
      .def_readonly("boundary_indices",
                    &Result::boundary_indices,
                    "int32, ascending: the input indices of the undersampled points "
                    "(after reconstruct(), with the umbrella failures).")
      .def_readonly("border_loops",
                    &Result::border_loops,
                    "list of int32 arrays: the mesh's borders as closed loops of "
                    "input indices.")
      .def_readonly("filled_holes",
                    &Result::filled_holes,
                    "list of int32 arrays: the undersampled holes closed, each the "
                    "border loop it had before, as input indices (its size in "
                    "edges is its length).")
      .def_readonly("added_points",
                    &Result::added_points,
                    "(K, 3) float64: the vertices refine_filled_holes added inside "
                    "the holes closed; triangles index them as N, N + 1, ...")
      .def_readonly("normals",
                    &Result::normals,
                    "(N, 3) float64: oriented unit normal per input point, NaN where "
                    "the point is not in the mesh.")
      .def_readonly("outlier_indices",
                    &Result::outlier_indices,
                    "int32, ascending: the input indices of the points set aside as "
                    "outliers.")
      .def_readonly("point_noise",
                    &Result::point_noise,
                    "(N,) float32: the noise level of each input point (about sigma "
                    "in sample spacings), NaN where the point is not finite or "
                    "without noise handling.")
      .def_property_readonly(
          "noise_level",
          [](const Result& r) { return r.report["noise_level"]; },
          "float: the noise level of the cloud, the median of point_noise (about "
          "sigma in sample spacings; 0 without noise handling).")
      .def_property_readonly(
          "smoothed",
          [](const Result& r) { return r.report["smoothed"]; },
          "bool: the decisions were taken on smoothed points (a noisy cloud).")
      .def_readonly("report",
                    &Result::report,
                    "dict: counts, the ratio used, the parameters and per-stage "
                    "timings in milliseconds.")
      .def("__repr__", [](const Result& r) {
        return "<pcl_cocone.Result: " +
               std::to_string(r.report["triangles"].cast<std::size_t>()) +
               " triangles, " +
               std::to_string(r.report["boundary_points"].cast<std::size_t>()) +
               " boundary points, " + std::to_string(py::len(r.border_loops)) +
               " border loops>";
      });

  m.def(
      "reconstruct",
      [](const py::object& points, const py::kwargs& kwargs) {
        return runPipeline(
            "reconstruct", points, kwargs, cocone::Stages::RECONSTRUCTION);
      },
      py::arg("points"),
      "reconstruct(points, **parameters) -> Result\n\n"
      "Reconstruct the well-sampled surface of (N, 3) points (float64 or float32, "
      "read in place) and find the undersampled ones. Parameters: ratio, "
      "spacing_factor, gap_angle, normal_angle, cocone_angle, boundary_detection, "
      "noise_handling (outliers set aside, noisy clouds smoothed; default True), "
      "noise_threshold, smoothing_iterations, fill_undersampled_holes (border loops "
      "that triangles of the local spacing close are closed; default True), "
      "hole_width (an empty hole wider than this many of its rim's triangles is a "
      "true border, never closed; default 2.5), refine_filled_holes (the patches "
      "of the holes closed refined and faired: new vertices, added_points; "
      "default False), threads, "
      "tile_points (in tiles of at most this many points, stitched; default 0: one "
      "piece; \"auto\": one piece if it fits the memory available, else the "
      "largest tiles that do, as the command-line tool), halo_spacings (the tiles' "
      "halo in spacings, default 8). "
      "Runs without the GIL.");
  m.def(
      "detect_boundary",
      [](const py::object& points, const py::kwargs& kwargs) {
        return runPipeline(
            "detect_boundary", points, kwargs, cocone::Stages::BOUNDARY_DETECTION);
      },
      py::arg("points"),
      "detect_boundary(points, **parameters) -> Result\n\n"
      "Stages 1-3 only: the undersampled points of (N, 3) points, no mesh "
      "(triangles and border_loops empty, normals NaN). Same parameters as "
      "reconstruct().");
  py::class_<cocone::TilePlan>(
      m,
      "TilePlan",
      "How plan_tiles() cut a cloud: each tile's core and halo, as indices of the "
      "points.")
      .def_property_readonly("tiles", &cocone::TilePlan::tiles, "Number of tiles.")
      .def_readonly("one_piece",
                    &cocone::TilePlan::one_piece,
                    "The cloud fits one tile: reconstruct() with the same tile_points "
                    "runs it in one piece, which the phases do not reproduce exactly.")
      .def_readonly("points", &cocone::TilePlan::points, "Number of points planned.")
      .def_readonly("cut_ms", &cocone::TilePlan::cut_ms, "Time of the plan (ms).")
      .def_property_readonly(
          "point_tile",
          [](const cocone::TilePlan& p) { return copyArray<int>(p.point_tile, 1); },
          "(N,) int32: the tile whose core holds each point, -1 if it is not finite.")
      .def(
          "core_size",
          [](const cocone::TilePlan& p, std::size_t t) {
            if (t >= p.tiles())
              throw py::index_error("no tile " + std::to_string(t));
            return p.coreSize(t);
          },
          py::arg("tile"),
          "Number of points in the core of a tile.")
      .def(
          "tile_points",
          [](const cocone::TilePlan& p, std::size_t t) {
            if (t >= p.tiles())
              throw py::index_error("no tile " + std::to_string(t));
            return copyArray<int>(p.tilePoints(t), 1);
          },
          py::arg("tile"),
          "int32: the indices of a tile's points, its core (core_size) first, then "
          "its halo: what reconstruct_tile() takes.")
      .def("__repr__", [](const cocone::TilePlan& p) {
        return "<pcl_cocone.TilePlan: " + std::to_string(p.tiles()) + " tiles of " +
               std::to_string(p.points) + " points>";
      });

  py::class_<cocone::TileResult>(
      m,
      "TileResult",
      "What reconstruct_tile() returns and stitch_tiles() takes: plain arrays, "
      "picklable (to_dict(), from_dict()) so that a worker process can send it back.")
      .def_readonly("degenerate",
                    &cocone::TileResult::degenerate,
                    "Why the tile's points give no mesh; empty if they do.")
      .def_readonly(
          "points", &cocone::TileResult::points, "Points of the tile (core and halo).")
      .def_property_readonly(
          "kept",
          [](const cocone::TileResult& o) { return o.kept.size(); },
          "Number of triangles the tile keeps.")
      .def_property_readonly(
          "timings_ms",
          [](const cocone::TileResult& o) {
            py::dict timings;
            eachTiming(o.timings,
                       [&](const char* name, double v) { timings[name] = v; });
            return timings;
          },
          "dict: the tile's time per stage in milliseconds.")
      .def("to_dict",
           &tileToDict,
           "The fields as a dict of plain values and NumPy arrays (copies).")
      .def_static("from_dict",
                  &tileFromDict,
                  py::arg("fields"),
                  "A TileResult from the dict to_dict() gives; ValueError if a field "
                  "is missing or of the wrong shape.")
      .def(py::pickle([](const cocone::TileResult& o) { return tileToDict(o); },
                      [](const py::dict& d) { return tileFromDict(d); }))
      .def("__repr__", [](const cocone::TileResult& o) {
        return "<pcl_cocone.TileResult: " + std::to_string(o.points) + " points, " +
               std::to_string(o.kept.size()) + " kept triangles>";
      });

  m.def("plan_tiles",
        &planTiles,
        py::arg("points"),
        "plan_tiles(points, **parameters) -> TilePlan\n\n"
        "Cut (N, 3) points into tiles of at most tile_points points in the core, "
        "with a halo of halo_spacings spacings (the first phase of reconstruct() with "
        "tile_points). Uses tile_points, halo_spacings and threads of the parameters. "
        "Runs without the GIL.");
  m.def("reconstruct_tile",
        &reconstructTile,
        py::arg("points"),
        py::arg("ids"),
        py::arg("core_points"),
        "reconstruct_tile(points, ids, core_points, **parameters) -> TileResult\n\n"
        "Reconstruct one tile from its own points (points[plan.tile_points(t)], the "
        "core first), their ids (plan.tile_points(t)) and the size of the core. The "
        "result depends on nothing else: not on the process, the threads or how "
        "often it runs. RuntimeError if it fails. Runs without the GIL.");
  m.def("stitch_tiles",
        &stitchTiles,
        py::arg("plan"),
        py::arg("results"),
        "stitch_tiles(plan, results, **parameters) -> Result\n\n"
        "Stitch one TileResult per tile, in the order of the tiles, into the Result "
        "reconstruct(points, tile_points=...) gives (with the same parameters as the "
        "tiles). RuntimeError if a result does not fit the plan. Runs without the "
        "GIL.");
  m.def(
      "default_parameters",
      []() { return parametersDict(cocone::Parameters()); },
      "The parameters' default values.");
}
