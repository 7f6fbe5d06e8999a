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
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace py = pybind11;
namespace cocone = pcl::cocone;

namespace {

/** What reconstruct() and detect_boundary() return. */
struct Result {
  py::array triangles;        ///< (M, 3) int32, input indices
  py::array boundary_indices; ///< int32, ascending
  py::list border_loops;      ///< int32 arrays of input indices
  py::array normals;          ///< (N, 3) float64, NaN where not in the mesh
  py::array outlier_indices;  ///< int32, ascending
  py::array point_noise;      ///< (N,) float32, NaN where unknown
  py::dict report;
};

const char* const PARAMETER_NAMES =
    "ratio, spacing_factor, gap_angle, normal_angle, cocone_angle, boundary_detection, "
    "noise_handling, noise_threshold, smoothing_iterations, fill_undersampled_holes, "
    "threads, tile_points (reconstruct only)";

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
    else if (name == "tile_points" && tiling) {
      const int points = toInt(function, name, value, 0, ">= 0 (0: one piece)");
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
  d["noise_threshold"] = p.noise_threshold;
  d["smoothing_iterations"] = p.smoothing_iterations;
  d["threads"] = p.threads;
  d["tile_points"] = tiling.tile_points;
  return d;
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
  const bool single = array.dtype().itemsize() == 4;
  const auto n = static_cast<std::size_t>(array.shape(0));

  cocone::Result r;
  double input_ms = 0.0, run_ms = 0.0;
  {
    // The array stays referenced (by `array`) while the GIL is released; nothing here
    // touches a Python object.
    py::gil_scoped_release release;
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    std::vector<Eigen::Vector3d> xyz =
        single ? readPoints<float>(array) : readPoints<double>(array);
    const auto t1 = Clock::now();
    r = tiling.tile_points > 0 ? cocone::runTiled(std::move(xyz), parameters, tiling)
                               : cocone::run(std::move(xyz), parameters, stages);
    const auto t2 = Clock::now();
    input_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    run_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  }
  if (!r.error.empty())
    throw std::runtime_error(std::string(function) + "(): " + r.error);

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
  py::dict counts;
  counts["candidates"] = c.candidates;
  counts["umbrella_failures"] = c.umbrella_failures;
  counts["pruned"] = c.pruned;
  counts["walk_components"] = c.walk_components;
  counts["walked"] = c.walked;
  counts["walk_conflicts"] = c.walk_conflicts;
  counts["walk_reseeds"] = c.walk_reseeds;
  counts["repair"] = repair;
  counts["holes_filled"] = c.holes_filled;
  counts["hole_triangles"] = c.hole_triangles;

  py::dict& report = out.report;
  report["stages"] = stages == cocone::Stages::RECONSTRUCTION ? "reconstruction"
                                                              : "boundary_detection";
  report["points"] = n;
  report["finite_points"] = finite;
  report["unique_points"] = r.vertices;
  report["triangles"] = triangle_count;
  report["boundary_points"] = boundary_count;
  report["border_loops"] = loop_count;
  report["outliers"] = outlier_count;
  report["noise_level"] = r.noise_level; // about sigma in sample spacings
  report["noise_after_smoothing"] = r.noise_after_smoothing;
  report["smoothed"] = r.smoothed;
  report["ratio"] = r.ratio; // the one used: the automatic one when ratio is 0
  report["parameters"] = parametersDict(parameters, tiling);
  report["timings_ms"] = timings;
  report["counts"] = counts;
  return out;
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
      "that triangles of the local spacing close are closed; default True), threads, "
      "tile_points (in tiles of at most this many points, stitched; default 0: one "
      "piece). "
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
  m.def(
      "default_parameters",
      []() { return parametersDict(cocone::Parameters()); },
      "The parameters' default values.");
}
