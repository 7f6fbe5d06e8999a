/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/out_of_core.h>
#include <pcl/surface/cocone/repair.h>
#include <pcl/surface/cocone/triangulation.h>

#include <Eigen/Geometry>

#include "caller_ids.h"
#include "disjoint_sets.h"
#include "parallel.h"
#include "stopwatch.h"
#include "tiles.h"
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <system_error>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

namespace pcl {
namespace cocone {

namespace {

namespace fs = std::filesystem;

/** Points read from the source at a time. */
constexpr std::size_t CHUNK_POINTS = std::size_t{1} << 16;
/** Bytes a tile's file buffers in memory before they are appended to it. */
constexpr std::size_t FILE_BUFFER = std::size_t{1} << 16;

/** An I/O failure: caught at the top, its message the run's error. */
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/** A point of a tile's file: its id and position. */
struct Record {
  std::int64_t id; // 64 bits: no padding written to disk
  double x, y, z;
};

/** Append \a size bytes to \a path. */
void
append(const fs::path& path, const char* data, std::size_t size)
{
  std::FILE* f = std::fopen(path.c_str(), "ab");
  if (!f)
    throw IoError("cannot write " + path.string() + ": " + std::strerror(errno));
  const bool ok = std::fwrite(data, 1, size, f) == size;
  if (std::fclose(f) != 0 || !ok)
    throw IoError("cannot write " + path.string() + " (disk full?)");
}

std::vector<char>
slurp(const fs::path& path)
{
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f)
    throw IoError("cannot read " + path.string() + ": " + std::strerror(errno));
  std::vector<char> bytes;
  char block[1 << 16];
  std::size_t got;
  while ((got = std::fread(block, 1, sizeof block, f)) > 0)
    bytes.insert(bytes.end(), block, block + got);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed)
    throw IoError("cannot read " + path.string());
  return bytes;
}

/** Records of many files, each buffered and appended when its buffer fills. */
class RecordFiles {
public:
  explicit RecordFiles(std::vector<fs::path> paths)
  : paths_(std::move(paths)), buffers_(paths_.size())
  {}

  void
  put(std::size_t file, const Record& r)
  {
    std::vector<char>& b = buffers_[file];
    const char* bytes = reinterpret_cast<const char*>(&r);
    b.insert(b.end(), bytes, bytes + sizeof r);
    if (b.size() >= FILE_BUFFER)
      flush(file);
  }

  void
  flush(std::size_t file)
  {
    append(paths_[file], buffers_[file].data(), buffers_[file].size());
    buffers_[file].clear();
  }

  void
  flushAll()
  {
    for (std::size_t f = 0; f < paths_.size(); ++f)
      flush(f);
  }

private:
  std::vector<fs::path> paths_;
  std::vector<std::vector<char>> buffers_;
};

std::vector<Record>
readRecords(const fs::path& path)
{
  if (!fs::exists(path))
    return {};
  const std::vector<char> bytes = slurp(path);
  std::vector<Record> out(bytes.size() / sizeof(Record));
  if (!out.empty())
    std::memcpy(out.data(), bytes.data(), out.size() * sizeof(Record));
  return out;
}

/** Plain values and vectors of them, to and from bytes. */
class Writer {
public:
  template <typename T>
  void
  value(const T& v)
  {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    const char* p = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof v);
  }

  template <typename T>
  void
  vector(const std::vector<T>& v)
  {
    value(static_cast<std::uint64_t>(v.size()));
    if (v.empty())
      return;
    const char* p = reinterpret_cast<const char*>(v.data());
    bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
  }

  std::vector<char> bytes;
};

class Reader {
public:
  explicit Reader(std::vector<char> bytes) : bytes_(std::move(bytes)) {}

  template <typename T>
  T
  value()
  {
    T v;
    take(&v, sizeof v);
    return v;
  }

  template <typename T>
  std::vector<T>
  vector()
  {
    const auto n = value<std::uint64_t>();
    if (n > (bytes_.size() - at_) / std::max<std::size_t>(sizeof(T), 1))
      throw IoError("a work file is truncated");
    std::vector<T> v(n);
    take(v.data(), n * sizeof(T));
    return v;
  }

private:
  void
  take(void* out, std::size_t size)
  {
    if (size > bytes_.size() - at_)
      throw IoError("a work file is truncated");
    if (size == 0)
      return;
    std::memcpy(out, bytes_.data() + at_, size);
    at_ += size;
  }

  std::vector<char> bytes_;
  std::size_t at_ = 0;
};

/** What the stitch reads of a tile besides its triangles. */
struct Labels {
  std::vector<int> core;                 ///< the core's ids, in order
  std::vector<int> representative;       ///< as TileResult
  std::vector<std::uint8_t> flags;       ///< as TileResult
  std::vector<float> noise;              ///< as TileResult
  std::vector<Eigen::Vector3d> position; ///< per representative, in core order
  std::vector<Eigen::Vector3d> normal;   ///< per representative
  std::vector<int> holes;                ///< filled holes' rims, each size-prefixed
  std::string degenerate;
  double ratio = 0.0, after = 0.0;
  bool smoothed = false;
  std::size_t points = 0;
  ReconstructionCounts counts;
  Timings timings;
};

/** The tile's files in the work directory. */
struct TileFiles {
  fs::path core, halo, labels, triangles, patches;
};

void
writeResult(const TileFiles& files, const std::vector<int>& core, const TileResult& o)
{
  Writer t;
  t.vector(o.kept);
  t.vector(o.seen);
  append(files.triangles, t.bytes.data(), t.bytes.size());
  Writer w;
  w.vector(core);
  w.vector(o.representative);
  w.vector(o.flags);
  w.vector(o.noise);
  w.vector(o.position);
  w.vector(o.normal);
  std::vector<int> holes;
  for (const auto& rim : o.filled_holes) {
    holes.push_back(static_cast<int>(rim.size()));
    holes.insert(holes.end(), rim.begin(), rim.end());
  }
  w.vector(holes);
  w.vector(std::vector<char>(o.degenerate.begin(), o.degenerate.end()));
  w.value(o.ratio);
  w.value(o.noise_after_smoothing);
  w.value(static_cast<std::uint8_t>(o.smoothed));
  w.value(static_cast<std::uint64_t>(o.points));
  w.value(o.counts);
  w.value(o.timings);
  append(files.labels, w.bytes.data(), w.bytes.size());
}

Labels
readLabels(const TileFiles& files)
{
  Reader r(slurp(files.labels));
  Labels l;
  l.core = r.vector<int>();
  l.representative = r.vector<int>();
  l.flags = r.vector<std::uint8_t>();
  l.noise = r.vector<float>();
  l.position = r.vector<Eigen::Vector3d>();
  l.normal = r.vector<Eigen::Vector3d>();
  l.holes = r.vector<int>();
  const std::vector<char> degenerate = r.vector<char>();
  l.degenerate.assign(degenerate.begin(), degenerate.end());
  l.ratio = r.value<double>();
  l.after = r.value<double>();
  l.smoothed = r.value<std::uint8_t>() != 0;
  l.points = static_cast<std::size_t>(r.value<std::uint64_t>());
  l.counts = r.value<ReconstructionCounts>();
  l.timings = r.value<Timings>();
  return l;
}

/** A tile's kept triangles and the others of its mesh, over caller ids. */
std::pair<std::vector<Triangle>, std::vector<Triangle>>
readTriangles(const TileFiles& files)
{
  Reader r(slurp(files.triangles));
  std::vector<Triangle> kept = r.vector<Triangle>();
  std::vector<Triangle> seen = r.vector<Triangle>();
  return {std::move(kept), std::move(seen)};
}

/** The work directory, removed with its files when the run ends. */
class WorkDirectory {
public:
  explicit WorkDirectory(const std::string& parent)
  {
    static std::atomic<unsigned> runs{0};
    if (!fs::is_directory(parent))
      throw IoError("no directory " + parent);
    path_ = fs::path(parent) / ("cocone-tiles-" + std::to_string(::getpid()) + "-" +
                                std::to_string(runs++));
    std::error_code ec;
    if (!fs::create_directory(path_, ec) || ec)
      throw IoError("cannot create " + path_.string());
  }

  ~WorkDirectory()
  {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }

  WorkDirectory(const WorkDirectory&) = delete;
  WorkDirectory&
  operator=(const WorkDirectory&) = delete;

  TileFiles
  tile(std::size_t t) const
  {
    const std::string stem = "tile" + std::to_string(t);
    return {path_ / (stem + ".core"),
            path_ / (stem + ".halo"),
            path_ / (stem + ".labels"),
            path_ / (stem + ".triangles"),
            path_ / (stem + ".patches")};
  }

  /** Bytes the directory holds now. */
  std::size_t
  bytes() const
  {
    std::size_t total = 0;
    for (const auto& entry : fs::directory_iterator(path_))
      total += static_cast<std::size_t>(entry.file_size());
    return total;
  }

private:
  fs::path path_;
};

/** Per patch, the sums its component's orientation is decided from (repair.cpp's
 * orient(): the signed volume about the centroid of the triangles' corners). With S
 * the sum of det(a, b, c) and N that of (b - a) x (c - a), the volume about a centre
 * o is S - o . N, so the sums of the parts add up. */
struct VolumeSums {
  Eigen::Vector3d corners = Eigen::Vector3d::Zero();
  double triangles = 0.0;
  double S = 0.0;
  Eigen::Vector3d N = Eigen::Vector3d::Zero();

  void
  add(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c)
  {
    corners += a + b + c;
    triangles += 1.0;
    S += a.dot(b.cross(c));
    N += (b - a).cross(c - a);
  }

  void
  add(const VolumeSums& o, bool turned)
  {
    corners += o.corners;
    triangles += o.triangles;
    S += turned ? -o.S : o.S;
    N += turned ? -o.N : o.N;
  }

  bool
  negative() const
  {
    if (triangles == 0.0)
      return false;
    const Eigen::Vector3d centre = corners / (3.0 * triangles);
    return S - centre.dot(N) < 0.0;
  }
};

class OutOfCore {
public:
  OutOfCore(PointSource& source,
            const Parameters& parameters,
            const TilingOptions& tiling,
            const std::string& directory,
            MeshSink& sink,
            std::size_t sample_points)
  : source_(source)
  , parameters_(parameters)
  , tiling_(tiling)
  , work_(directory)
  , sink_(sink)
  , threads_(resolveThreads(parameters.threads))
  , sample_points_(sample_points)
  {}

  OutOfCoreResult
  run()
  {
    detail::Stopwatch clock;
    cut();
    halos();
    report_.tiling.cut_ms = clock.lap();
    reconstructTiles();
    report_.tiling.tiles_ms = clock.lap();
    labels();
    seams();
    band();
    report_.disk_bytes = std::max(report_.disk_bytes, work_.bytes()); // at its most
    orientComponents();
    write();
    report_.tiling.stitch_ms = clock.lap();
    return std::move(report_);
  }

private:
  // ---- The cut -------------------------------------------------------------------

  /** Pass 1: the size, the box and the sample; the splits on the sample. */
  void
  cut()
  {
    std::string error;
    std::vector<Eigen::Vector3d> chunk, sample;
    std::size_t stride = 1, finite = 0, n = 0;
    if (!source_.rewind(error))
      throw IoError(error);
    for (;;) {
      if (!source_.read(chunk, CHUNK_POINTS, error))
        throw IoError(error);
      if (chunk.empty())
        break;
      for (const auto& p : chunk) {
        ++n;
        if (!p.allFinite())
          continue;
        all_.extend(p);
        if (finite++ % stride == 0)
          sample.push_back(p);
        if (sample.size() > sample_points_) { // halve: every other one stays
          for (std::size_t i = 0; 2 * i < sample.size(); ++i)
            sample[i] = sample[2 * i];
          sample.resize((sample.size() + 1) / 2);
          stride *= 2;
        }
      }
    }
    if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw IoError(std::to_string(n) + " points: ids are int, at most 2^31 - 1");
    report_.points = n;
    report_.finite = finite;
    offset_ =
        finite ? Eigen::Vector3d(0.5 * (all_.lo + all_.hi)) : Eigen::Vector3d::Zero();
    std::vector<int> index(sample.size());
    for (std::size_t i = 0; i < index.size(); ++i)
      index[i] = static_cast<int>(i);
    // On all the points (stride 1) these are runTiled()'s splits.
    const std::size_t leaf = std::max<std::size_t>(1, tiling_.tile_points / stride);
    sample_ = std::move(sample);
    tiles_ = std::make_unique<detail::Tiles>(sample_, std::move(index), leaf);
    count_ = tiles_->size();
    report_.tiling.tiles = count_;
  }

  /** Pass 2: each finite point to its tile's core file; then each tile's halo, the
   * points of the other cores within the reach of its core's box, from their files
   * in the order of the tiles (runTiled()'s halo, in its order). */
  void
  halos()
  {
    std::string error;
    std::vector<fs::path> cores(count_), halo(count_);
    for (std::size_t t = 0; t < count_; ++t) {
      cores[t] = work_.tile(t).core;
      halo[t] = work_.tile(t).halo;
    }
    boxes_.assign(count_, detail::Box());
    core_size_.assign(count_, 0);
    point_tile_.assign(report_.points, -1);
    {
      RecordFiles files(cores);
      std::vector<Eigen::Vector3d> chunk;
      if (!source_.rewind(error))
        throw IoError(error);
      std::size_t id = 0;
      for (;;) {
        if (!source_.read(chunk, CHUNK_POINTS, error))
          throw IoError(error);
        if (chunk.empty())
          break;
        for (const auto& p : chunk) {
          if (id >= report_.points)
            throw IoError("the source gave more points on its second pass");
          if (p.allFinite()) {
            const std::size_t t = tiles_->locate(p);
            files.put(t, {static_cast<std::int64_t>(id), p.x(), p.y(), p.z()});
            boxes_[t].extend(p);
            point_tile_[id] = static_cast<int>(t);
            ++core_size_[t];
          }
          ++id;
        }
      }
      if (id != report_.points)
        throw IoError("the source gave fewer points on its second pass");
      files.flushAll();
    }
    tiles_.reset();
    std::vector<Eigen::Vector3d>().swap(sample_);
    // Each core's spacing sets its reach.
    std::vector<double> reach(count_, 0.0);
    for (std::size_t t = 0; t < count_; ++t) {
      const std::vector<Record> core = readRecords(cores[t]);
      std::vector<Eigen::Vector3d> P(core.size());
      std::vector<int> index(core.size());
      for (std::size_t i = 0; i < core.size(); ++i) {
        P[i] = {core[i].x, core[i].y, core[i].z};
        index[i] = static_cast<int>(i);
      }
      reach[t] = tiling_.halo_spacings *
                 detail::medianSpacing(P, index.data(), P.size(), boxes_[t]);
    }
    RecordFiles files(halo);
    for (std::size_t u = 0; u < count_; ++u) {
      std::vector<std::size_t> near;
      for (std::size_t t = 0; t < count_; ++t)
        if (t != u && boxes_[t].distance(boxes_[u]) <= reach[t])
          near.push_back(t);
      if (near.empty())
        continue;
      for (const Record& r : readRecords(cores[u])) {
        const Eigen::Vector3d p(r.x, r.y, r.z);
        for (const std::size_t t : near)
          if (boxes_[t].distance(p) <= reach[t]) {
            files.put(t, r);
            ++report_.tiling.halo_points;
          }
      }
    }
    files.flushAll();
    report_.disk_bytes = std::max(report_.disk_bytes, work_.bytes());
  }

  // ---- The tiles -----------------------------------------------------------------

  void
  reconstructTiles()
  {
    const int in_flight = static_cast<int>(std::min<std::size_t>(
        tiling_.tiles_in_flight > 0 ? tiling_.tiles_in_flight : threads_, count_));
    Parameters tile_parameters = parameters_;
    tile_parameters.threads = static_cast<unsigned>(std::max(1, threads_ / in_flight));
    // A tile that fails (out of memory, a file that cannot be read or written) ends
    // the run with its error.
    detail::forEachTask(count_, in_flight, [&](std::size_t t) {
      const TileFiles files = work_.tile(t);
      std::vector<Record> records = readRecords(files.core);
      const std::vector<Record> halo = readRecords(files.halo);
      records.insert(records.end(), halo.begin(), halo.end());
      std::vector<Eigen::Vector3d> points(records.size());
      std::vector<int> ids(records.size());
      for (std::size_t i = 0; i < records.size(); ++i) {
        points[i] = {records[i].x, records[i].y, records[i].z};
        ids[i] = static_cast<int>(records[i].id);
      }
      const std::vector<int> core(
          ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(core_size_[t]));
      std::vector<Record>().swap(records);
      const TileResult o =
          reconstructTile(std::move(points), ids, core_size_[t], tile_parameters);
      if (!o.error.empty())
        throw IoError("tile " + std::to_string(t) + ": " + o.error);
      writeResult(files, core, o);
      fs::remove(files.core);
      fs::remove(files.halo);
    });
  }

  // ---- The stitch ----------------------------------------------------------------

  /** The labels of every point from its core's tile; the vertices numbered tile
   * after tile, in core order. */
  void
  labels()
  {
    vertex_.assign(report_.points, -1);
    tile_vertex_begin_.assign(count_ + 1, 0);
    std::vector<double> ratios, after;
    std::vector<float> levels;
    std::vector<std::pair<bool, std::vector<int>>> filled;
    bool any_mesh = false;
    int next = 0;
    for (std::size_t t = 0; t < count_; ++t) {
      tile_vertex_begin_[t] = static_cast<std::size_t>(next);
      const Labels l = readLabels(work_.tile(t));
      for (std::size_t i = 0; i < l.core.size(); ++i) {
        const int id = l.core[i], rep = l.representative[i];
        if (rep == -2) {
          vertex_[id] = -2;
          report_.outlier_indices.push_back(id);
          continue;
        }
        vertex_[id] = rep == id ? next++ : -3 - rep; // a duplicate: its rep's, below
        if (l.flags[i])
          report_.boundary_indices.push_back(id);
        if (!l.noise.empty() && std::isfinite(l.noise[i]))
          levels.push_back(l.noise[i]);
      }
      report_.tiling.largest_tile = std::max(report_.tiling.largest_tile, l.points);
      report_.tiling.degenerate_tiles += !l.degenerate.empty();
      any_mesh = any_mesh || l.degenerate.empty();
      if (l.degenerate.empty())
        ratios.push_back(l.ratio);
      if (l.after > 0.0)
        after.push_back(l.after);
      report_.smoothed = report_.smoothed || l.smoothed;
      detail::add(report_.counts, l.counts);
      for (std::size_t i = 0; i < l.holes.size(); i += 1 + l.holes[i]) {
        std::vector<int> rim(l.holes.begin() + static_cast<std::ptrdiff_t>(i + 1),
                             l.holes.begin() +
                                 static_cast<std::ptrdiff_t>(i + 1 + l.holes[i]));
        const bool owner = point_tile_[rim[0]] == static_cast<int>(t);
        filled.push_back({!owner, std::move(rim)});
      }
    }
    if (!any_mesh)
      throw IoError("no tile gives a mesh (the points are degenerate)");
    tile_vertex_begin_[count_] = static_cast<std::size_t>(next);
    nv_ = static_cast<std::size_t>(next);
    for (int& v : vertex_)
      if (v <= -3)
        v = vertex_[-3 - v];
    std::sort(report_.outlier_indices.begin(), report_.outlier_indices.end());
    std::sort(report_.boundary_indices.begin(), report_.boundary_indices.end());
    report_.ratio = detail::median(ratios);
    if (!levels.empty()) {
      const auto m = levels.begin() + static_cast<std::ptrdiff_t>(levels.size() / 2);
      std::nth_element(levels.begin(), m, levels.end());
      report_.noise_level = *m;
    }
    report_.holes_filled = detail::distinctHoles(std::move(filled)).size();
    report_.counts.holes_filled = report_.holes_filled;
    report_.vertices = nv_;
  }

  std::size_t
  tileOfVertex(int v) const
  {
    return static_cast<std::size_t>(std::upper_bound(tile_vertex_begin_.begin(),
                                                     tile_vertex_begin_.end(),
                                                     static_cast<std::size_t>(v)) -
                                    tile_vertex_begin_.begin() - 1);
  }

  /** Tile \a t's kept triangles over vertex numbers (those with an outlier vertex
   * left out), and its other triangles, ascending. */
  void
  mapped(std::size_t t,
         std::vector<Triangle>& kept,
         std::vector<Triangle>* seen = nullptr,
         std::size_t* dropped = nullptr) const
  {
    auto lists = readTriangles(work_.tile(t));
    kept.clear();
    for (const Triangle& tri : lists.first) {
      const Triangle v{vertex_[tri[0]], vertex_[tri[1]], vertex_[tri[2]]};
      if (v[0] >= 0 && v[1] >= 0 && v[2] >= 0)
        kept.push_back(v);
      else if (dropped)
        ++*dropped;
    }
    if (seen)
      for (const Triangle& tri : lists.second) {
        Triangle v{vertex_[tri[0]], vertex_[tri[1]], vertex_[tri[2]]};
        if (v[0] >= 0 && v[1] >= 0 && v[2] >= 0) {
          std::sort(v.begin(), v.end());
          seen->push_back(v);
        }
      }
  }

  /** The seams: V0, the vertices of the triangles with vertices in two cores (every
   * edge two tiles share and every vertex whose star they share is among them), and
   * V1, the vertices of the triangles at V0. The band is the triangles at V1: the
   * stars of V1 are whole in it. */
  void
  seams()
  {
    ring_.assign(nv_, 0);
    std::vector<Triangle> kept;
    for (std::size_t t = 0; t < count_; ++t) {
      mapped(t, kept, nullptr, &report_.tiling.seam_dropped);
      const std::size_t lo = tile_vertex_begin_[t], hi = tile_vertex_begin_[t + 1];
      for (const Triangle& v : kept)
        if (std::any_of(v.begin(), v.end(), [&](int x) {
              return static_cast<std::size_t>(x) < lo ||
                     static_cast<std::size_t>(x) >= hi;
            }))
          for (const int x : v)
            ring_[x] |= V0;
    }
    for (std::size_t t = 0; t < count_; ++t) {
      mapped(t, kept);
      for (const Triangle& v : kept)
        if ((ring_[v[0]] | ring_[v[1]] | ring_[v[2]]) & V0)
          for (const int x : v)
            ring_[x] |= V1;
    }
  }

  bool
  inBand(const Triangle& v) const
  {
    return ((ring_[v[0]] | ring_[v[1]] | ring_[v[2]]) & V1) != 0;
  }

  /** Tile \a t's patches (the components of its kept triangles), numbered from
   * its first; the border half-edges of its triangles outside the band (among
   * those) go to outside_halves_. The triangles are renumbered densely first, the
   * core's vertices and then the few beyond it, as the incidences' tables are as
   * long as the largest vertex number (the whole cloud's: 64 tiles of 100M points
   * took minutes). */
  std::vector<int>
  tilePatches(std::size_t t, const std::vector<Triangle>& kept, std::size_t& count)
  {
    const int lo = static_cast<int>(tile_vertex_begin_[t]),
              hi = static_cast<int>(tile_vertex_begin_[t + 1]);
    std::vector<int> beyond;
    for (const Triangle& v : kept)
      for (const int x : v)
        if (x < lo || x >= hi)
          beyond.push_back(x);
    std::sort(beyond.begin(), beyond.end());
    beyond.erase(std::unique(beyond.begin(), beyond.end()), beyond.end());
    const auto dense = [&](int x) {
      return x >= lo && x < hi
                 ? x - lo
                 : hi - lo +
                       static_cast<int>(
                           std::lower_bound(beyond.begin(), beyond.end(), x) -
                           beyond.begin());
    };
    const auto global = [&](int x) {
      return x < hi - lo ? x + lo : beyond[static_cast<std::size_t>(x - (hi - lo))];
    };
    std::vector<Triangle> renumbered(kept.size());
    for (std::size_t i = 0; i < kept.size(); ++i)
      for (int k = 0; k < 3; ++k)
        renumbered[i][k] = dense(kept[i][k]);
    const EdgeIncidences inc(renumbered, threads_);
    std::vector<int> patch = triangleComponents(inc, kept.size(), &count);
    for (int& p : patch)
      p += static_cast<int>(patch_begin_[t]);
    for (std::size_t e = 0; e < inc.edges.size(); ++e) {
      std::size_t outside = 0, last = 0;
      for (std::size_t i = inc.first[e]; i < inc.first[e + 1]; ++i)
        if (!inBand(kept[inc.triangle[i]])) {
          ++outside;
          last = i;
        }
      if (outside == 1)
        outside_halves_.push_back({global(inc.edges[e][0]),
                                   global(inc.edges[e][1]),
                                   inc.forward[last],
                                   patch[inc.triangle[last]]});
    }
    return patch;
  }

  /** The band stitched in memory as runTiled() stitches the whole; the rest summed
   * per patch for the components' orientation. */
  void
  band()
  {
    std::vector<Triangle> kept, seen, triangles;
    std::vector<int> band_patch;
    patch_begin_.assign(count_ + 1, 0);
    for (std::size_t t = 0; t < count_; ++t) {
      mapped(t, kept, &seen);
      std::size_t patches = 0;
      const std::vector<int> patch = tilePatches(t, kept, patches);
      patch_begin_[t + 1] = patch_begin_[t] + patches;
      {
        Writer w; // for write()
        w.vector(patch);
        append(work_.tile(t).patches, w.bytes.data(), w.bytes.size());
      }
      sums_.resize(patch_begin_[t + 1]);
      const Labels l = readLabels(work_.tile(t));
      const auto at = [&](int v) -> Eigen::Vector3d {
        return l.position[static_cast<std::size_t>(v) - tile_vertex_begin_[t]] -
               offset_;
      };
      for (std::size_t i = 0; i < kept.size(); ++i) {
        const Triangle& v = kept[i];
        if (inBand(v)) {
          triangles.push_back(v);
          band_patch.push_back(patch[i]);
        }
        else {
          sums_[patch[i]].add(at(v[0]), at(v[1]), at(v[2]));
          ++outside_;
        }
      }
    }
    const std::size_t patches = patch_begin_[count_];
    report_.tiling.patches = patches;
    seen.erase(std::remove_if(seen.begin(),
                              seen.end(),
                              [&](const Triangle& v) {
                                return !(ring_[v[0]] & ring_[v[1]] & ring_[v[2]] & V1);
                              }),
               seen.end());

    // The band's vertices, numbered locally, with their positions.
    for (const Triangle& v : triangles)
      band_vertex_.insert(band_vertex_.end(), v.begin(), v.end());
    std::sort(band_vertex_.begin(), band_vertex_.end());
    band_vertex_.erase(std::unique(band_vertex_.begin(), band_vertex_.end()),
                       band_vertex_.end());
    const auto local = [&](int v) {
      return static_cast<int>(
          std::lower_bound(band_vertex_.begin(), band_vertex_.end(), v) -
          band_vertex_.begin());
    };
    std::vector<Eigen::Vector3d> P(band_vertex_.size());
    {
      std::size_t k = 0;
      for (std::size_t t = 0; t < count_ && k < band_vertex_.size(); ++t) {
        if (static_cast<std::size_t>(band_vertex_[k]) >= tile_vertex_begin_[t + 1])
          continue;
        const Labels l = readLabels(work_.tile(t));
        for (; k < band_vertex_.size() &&
               static_cast<std::size_t>(band_vertex_[k]) < tile_vertex_begin_[t + 1];
             ++k)
          P[k] = l.position[static_cast<std::size_t>(band_vertex_[k]) -
                            tile_vertex_begin_[t]] -
                 offset_;
      }
    }
    for (Triangle& v : triangles)
      for (int& x : v)
        x = local(x);
    for (Triangle& v : seen)
      for (int& x : v)
        x = local(x);
    std::vector<std::uint8_t> inner(band_vertex_.size(), 0); // V1: whole stars
    for (std::size_t k = 0; k < band_vertex_.size(); ++k)
      inner[k] = (ring_[band_vertex_[k]] & V1) != 0;

    // Patches turned to agree across the seams (every edge two patches share is in
    // the band).
    EdgeIncidences incidences(triangles, threads_);
    turn_ = detail::turnPatches(incidences, band_patch, patches);
    for (std::size_t c = 0; c < patches; ++c)
      report_.tiling.patches_flipped += turn_[c];
    for (std::size_t i = 0; i < triangles.size(); ++i)
      if (turn_[band_patch[i]])
        std::swap(triangles[i][1], triangles[i][2]);
    incidences = EdgeIncidences(triangles, threads_);

    // The repair: it keeps the order of the triangles it leaves. Its last step turns
    // each component of the band to face outward as if the band were the whole;
    // the components are turned below, on the whole, so a band component it turned
    // is turned back.
    const std::vector<Triangle> before = triangles;
    repairManifold(P, triangles, report_.tiling.stitch, threads_, &incidences, &inner);
    const auto ascending = [](Triangle t) {
      std::sort(t.begin(), t.end());
      return t;
    };
    std::vector<int> patch_of(triangles.size(), -1);
    std::vector<std::uint8_t> turned(triangles.size(), 0);
    for (std::size_t i = 0, j = 0; i < before.size(); ++i)
      if (j < triangles.size() && ascending(before[i]) == ascending(triangles[j])) {
        patch_of[j] = band_patch[i];
        turned[j] = before[i] != triangles[j];
        ++j;
      }
      else
        seen.push_back(ascending(before[i]));
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    {
      std::size_t components = 0;
      const std::vector<int> component = triangleComponents(triangles, &components);
      std::vector<long> vote(components, 0);
      for (std::size_t i = 0; i < triangles.size(); ++i)
        vote[component[i]] += turned[i] ? 1 : -1;
      for (std::size_t i = 0; i < triangles.size(); ++i)
        if (vote[component[i]] > 0)
          std::swap(triangles[i][1], triangles[i][2]);
    }
    incidences = EdgeIncidences(triangles, threads_);

    // The seam holes, closed with the tiles' triangles.
    const auto core_of = [&](int x) { return tileOfVertex(band_vertex_[x]); };
    const auto tile_of = [&](int t) {
      return static_cast<int>(std::upper_bound(patch_begin_.begin(),
                                               patch_begin_.end(),
                                               static_cast<std::size_t>(patch_of[t])) -
                              patch_begin_.begin()) -
             1;
    };
    report_.tiling.seam_filled = fillHoles(
        P,
        triangles,
        [&](const Triangle& t) {
          // The band's cut edge runs between vertices outside V1 (the edges at a V1
          // vertex have their whole stars): a patch across it would cover the
          // triangles beyond, which are not in the band.
          if ((!inner[t[0]] && !inner[t[1]]) || (!inner[t[1]] && !inner[t[2]]) ||
              (!inner[t[0]] && !inner[t[2]]))
            return false;
          return std::binary_search(seen.begin(), seen.end(), t) ||
                 detail::closesSeamHole(incidences, t, core_of, tile_of);
        },
        detail::SEAM_HOLE_EDGES,
        &incidences);
    patch_of.resize(triangles.size(), -1);
    band_ = std::move(triangles);
    band_patch_ = std::move(patch_of);
    band_positions_ = std::move(P);
  }

  /** The components of the whole, each turned to face outward. */
  void
  orientComponents()
  {
    const std::size_t patches = patch_begin_[count_];
    detail::DisjointSets sets(patches);
    std::size_t components = 0;
    band_component_ = triangleComponents(band_, &components);
    std::vector<int> anchor(components, -1);
    for (std::size_t i = 0; i < band_.size(); ++i) {
      const int p = band_patch_[i];
      if (p < 0)
        continue;
      int& a = anchor[band_component_[i]];
      if (a < 0)
        a = p;
      else
        sets.unite(a, p);
    }
    std::vector<VolumeSums> total(patches);
    for (std::size_t p = 0; p < patches; ++p)
      total[sets.find(static_cast<int>(p))].add(sums_[p], turn_[p] != 0);
    const auto& P = band_positions_;
    std::vector<VolumeSums> loose(components); // band components of no patch
    for (std::size_t i = 0; i < band_.size(); ++i) {
      const Triangle& v = band_[i];
      const int a = anchor[band_component_[i]];
      (a >= 0 ? total[sets.find(a)] : loose[band_component_[i]])
          .add(P[v[0]], P[v[1]], P[v[2]]);
    }
    face_.assign(patches, 0);
    for (std::size_t p = 0; p < patches; ++p)
      face_[p] = static_cast<std::uint8_t>(
          turn_[p] ^
          static_cast<std::uint8_t>(total[sets.find(static_cast<int>(p))].negative()));
    for (std::size_t i = 0; i < band_.size(); ++i) {
      const int a = anchor[band_component_[i]];
      if (a >= 0 ? total[sets.find(a)].negative()
                 : loose[band_component_[i]].negative())
        std::swap(band_[i][1], band_[i][2]);
    }
    // The components: the sets of patches with a triangle, and the band's pieces of
    // none.
    for (std::size_t p = 0; p < patches; ++p)
      report_.components += total[p].triangles > 0.0; // a root with triangles
    for (std::size_t c = 0; c < components; ++c)
      report_.components += anchor[c] < 0;
  }

  // ---- The output ----------------------------------------------------------------

  /** Tile \a t's kept triangles outside the band, each turned as its patch faces. */
  std::vector<Triangle>
  outsideTriangles(std::size_t t) const
  {
    std::vector<Triangle> kept;
    mapped(t, kept);
    const std::vector<int> patch = Reader(slurp(work_.tile(t).patches)).vector<int>();
    std::vector<Triangle> out;
    out.reserve(kept.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
      Triangle v = kept[i];
      if (inBand(v))
        continue;
      if (face_[patch[i]])
        std::swap(v[1], v[2]);
      out.push_back(v);
    }
    return out;
  }

  void
  write()
  {
    std::string error;
    const std::size_t total = outside_ + band_.size();
    report_.triangles = total;
    if (!sink_.begin(nv_, total, error))
      throw IoError(error);
    // Facing per band vertex (its band triangles), for the normals.
    std::vector<Eigen::Vector3d> band_facing(band_vertex_.size(),
                                             Eigen::Vector3d::Zero());
    for (const Triangle& v : band_) {
      const auto& P = band_positions_;
      const Eigen::Vector3d a = (P[v[1]] - P[v[0]]).cross(P[v[2]] - P[v[0]]);
      for (const int x : v)
        band_facing[x] += a;
    }
    // Border half-edges: the band's and those of the rest, which cancel where they
    // meet at the band's cut edge.
    std::vector<std::array<int, 3>> halves; // low, high, from low to high
    const auto half = [&](int a, int b) {
      halves.push_back({std::min(a, b), std::max(a, b), a < b});
    };
    {
      const EdgeIncidences inc(band_);
      for (std::size_t e = 0; e < inc.edges.size(); ++e)
        if (inc.count(e) == 1) {
          const bool fwd = inc.forward[inc.first[e]];
          const int a = band_vertex_[inc.edges[e][0]],
                    b = band_vertex_[inc.edges[e][1]];
          fwd ? half(a, b) : half(b, a);
        }
    }
    for (const auto& h : outside_halves_) // as the triangle runs it, once turned
      (h[2] != 0) != (face_[h[3]] != 0) ? half(h[0], h[1]) : half(h[1], h[0]);
    std::vector<std::array<int, 4>>().swap(outside_halves_);
    // The band's vertices in a triangle, for the Euler characteristic.
    std::vector<int> band_used;
    for (const Triangle& v : band_)
      for (const int x : v)
        band_used.push_back(band_vertex_[x]);
    std::sort(band_used.begin(), band_used.end());
    band_used.erase(std::unique(band_used.begin(), band_used.end()), band_used.end());
    std::size_t used = band_used.size();
    std::vector<Eigen::Vector3d> positions, normals;
    for (std::size_t t = 0; t < count_; ++t) {
      const Labels l = readLabels(work_.tile(t));
      const std::vector<Triangle> out = outsideTriangles(t);
      const std::size_t lo = tile_vertex_begin_[t];
      std::vector<Eigen::Vector3d> facing(tile_vertex_begin_[t + 1] - lo,
                                          Eigen::Vector3d::Zero());
      std::vector<std::uint8_t> in_triangle(facing.size(), 0); // and not in the band's
      for (const Triangle& v : out) {
        const auto at = [&](int x) -> const Eigen::Vector3d& {
          return l.position[static_cast<std::size_t>(x) - lo];
        };
        const Eigen::Vector3d a = (at(v[1]) - at(v[0])).cross(at(v[2]) - at(v[0]));
        for (const int x : v) {
          facing[static_cast<std::size_t>(x) - lo] += a;
          in_triangle[static_cast<std::size_t>(x) - lo] = 1;
        }
      }
      // The vertices of the tile, with their normals against the stitched mesh.
      positions.clear();
      normals.clear();
      const std::size_t first_id = vertex_id_.size();
      std::size_t k = 0;
      for (std::size_t i = 0; i < l.core.size(); ++i) {
        if (l.representative[i] != l.core[i])
          continue;
        const int v = static_cast<int>(lo + k);
        Eigen::Vector3d f = facing[k];
        const auto b = std::lower_bound(band_vertex_.begin(), band_vertex_.end(), v);
        if (b != band_vertex_.end() && *b == v)
          f += band_facing[static_cast<std::size_t>(b - band_vertex_.begin())];
        used += in_triangle[k] &&
                !std::binary_search(band_used.begin(), band_used.end(), v);
        Eigen::Vector3d normal = l.normal[k];
        detail::turnNormal(normal, f, (l.flags[i] & 3) != 0);
        positions.push_back(l.position[k]);
        normals.push_back(normal);
        vertex_id_.push_back(l.core[i]);
        ++k;
      }
      const std::vector<int> ids(
          vertex_id_.begin() + static_cast<std::ptrdiff_t>(first_id), vertex_id_.end());
      if (!sink_.addVertices(positions, normals, ids, error))
        throw IoError(error);
    }
    // The triangles: each tile's outside the band, then the band's.
    for (std::size_t t = 0; t < count_; ++t)
      if (!sink_.addTriangles(outsideTriangles(t), error))
        throw IoError(error);
    std::vector<Triangle> out;
    for (const Triangle& v : band_)
      out.push_back({band_vertex_[v[0]], band_vertex_[v[1]], band_vertex_[v[2]]});
    if (!out.empty() && !sink_.addTriangles(out, error))
      throw IoError(error);
    if (!sink_.end(error))
      throw IoError(error);
    const std::size_t border_edges = loops(std::move(halves));
    const auto vertices = static_cast<long>(used);
    const auto faces = static_cast<long>(total);
    report_.euler =
        vertices - (3 * faces + static_cast<long>(border_edges)) / 2 + faces;
  }

  /** The border loops from the border half-edges of the band and of the rest (an
   * edge of the band's cut edge is a border half-edge of both, and is none); returns
   * the number of border edges. */
  std::size_t
  loops(std::vector<std::array<int, 3>> halves)
  {
    std::sort(halves.begin(), halves.end());
    std::vector<std::pair<int, int>> next; // a -> b
    for (std::size_t i = 0; i < halves.size();) {
      std::size_t j = i;
      while (j < halves.size() && halves[j][0] == halves[i][0] &&
             halves[j][1] == halves[i][1])
        ++j;
      if (j - i == 1) {
        const auto& h = halves[i];
        next.push_back(h[2] ? std::make_pair(h[0], h[1]) : std::make_pair(h[1], h[0]));
      }
      i = j;
    }
    std::sort(next.begin(), next.end());
    std::vector<std::uint8_t> used(next.size(), 0);
    for (std::size_t s = 0; s < next.size(); ++s) {
      if (used[s])
        continue;
      std::vector<int> loop;
      std::size_t e = s;
      while (!used[e]) {
        used[e] = 1;
        loop.push_back(vertex_id_[static_cast<std::size_t>(next[e].first)]);
        const auto it = std::lower_bound(
            next.begin(), next.end(), std::make_pair(next[e].second, -1));
        if (it == next.end() || it->first != next[e].second)
          break;
        e = static_cast<std::size_t>(it - next.begin());
      }
      report_.border_loops.push_back(std::move(loop));
    }
    detail::sortLoops(report_.border_loops);
    return next.size();
  }

  static constexpr std::uint8_t V0 = 1, V1 = 2;

  PointSource& source_;
  const Parameters& parameters_;
  const TilingOptions& tiling_;
  WorkDirectory work_;
  MeshSink& sink_;
  int threads_;
  std::size_t sample_points_;
  OutOfCoreResult report_;

  detail::Box all_;
  Eigen::Vector3d offset_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> sample_;
  std::unique_ptr<detail::Tiles> tiles_;
  std::size_t count_ = 0;
  std::vector<detail::Box> boxes_;
  std::vector<std::size_t> core_size_;
  std::vector<int> point_tile_; ///< per id
  std::vector<int> vertex_;     ///< per id: its vertex, -1 not finite, -2 outlier
  std::vector<std::size_t> tile_vertex_begin_;
  std::size_t nv_ = 0;
  std::vector<std::uint8_t> ring_; ///< per vertex: V0, V1 bits
  std::vector<std::size_t> patch_begin_;
  std::vector<VolumeSums> sums_; ///< per patch, its triangles outside the band
  std::size_t outside_ = 0;      ///< triangles outside the band
  /** Border half-edges among the triangles outside the band: low, high vertex,
   * whether its triangle runs low to high before its patch is turned, the patch. */
  std::vector<std::array<int, 4>> outside_halves_;
  std::vector<std::uint8_t> turn_, face_;
  std::vector<int> band_vertex_; ///< the band's vertices, ascending
  std::vector<Eigen::Vector3d> band_positions_;
  std::vector<Triangle> band_;
  std::vector<int> band_patch_, band_component_;
  std::vector<int> vertex_id_; ///< per vertex: its representative's id
};

} // namespace

TilingOptions
automaticOutOfCoreTiling(std::size_t points,
                         std::size_t memory,
                         unsigned int threads,
                         bool* fits)
{
  if (fits)
    *fits = true;
  const unsigned int workers =
      threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
  if (memory == 0) { // unknown: tiles of a million points, a gigabyte or two each
    TilingOptions tiling;
    tiling.tile_points = 1000000;
    tiling.tiles_in_flight = workers;
    return tiling;
  }
  const double room = static_cast<double>(memory) -
                      static_cast<double>(points) * OUT_OF_CORE_BYTES_PER_POINT;
  TilingOptions tiling;
  for (unsigned int in_flight = workers; in_flight >= 1; --in_flight) {
    const double core = room / (in_flight * detail::tileBytes(1.0));
    if (core >= static_cast<double>(MINIMUM_TILE_POINTS) || in_flight == 1) {
      tiling.tile_points = detail::seriesTilePoints(core);
      tiling.tiles_in_flight = in_flight;
      if (fits && !(core >= static_cast<double>(MINIMUM_TILE_POINTS)))
        *fits = false;
      break;
    }
  }
  return tiling;
}

OutOfCoreResult
runOutOfCore(PointSource& source,
             const Parameters& parameters,
             const TilingOptions& tiling,
             const std::string& directory,
             MeshSink& sink,
             std::size_t sample_points)
{
  OutOfCoreResult failed;
  if (sample_points < MINIMUM_TILE_POINTS) {
    failed.error =
        "sample_points must be at least " + std::to_string(MINIMUM_TILE_POINTS);
    return failed;
  }
  if (tiling.tile_points < MINIMUM_TILE_POINTS) {
    failed.error = "tile_points must be at least " +
                   std::to_string(MINIMUM_TILE_POINTS) + " (got " +
                   std::to_string(tiling.tile_points) + ")";
    return failed;
  }
  if (!(tiling.halo_spacings >= 0.0) || !std::isfinite(tiling.halo_spacings)) {
    failed.error = "halo_spacings must be finite and >= 0";
    return failed;
  }
  if (parameters.refine_filled_holes) {
    failed.error = "refining the filled holes is not available out of core";
    return failed;
  }
  try {
    OutOfCore run(source, parameters, tiling, directory, sink, sample_points);
    return run.run();
  }
  catch (const std::bad_alloc&) {
    failed.error = "out of memory";
  }
  catch (const std::exception& e) {
    failed.error = e.what();
  }
  return failed;
}

} // namespace cocone
} // namespace pcl
