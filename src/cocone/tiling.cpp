/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/hole_refinement.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/repair.h>
#include <pcl/surface/cocone/tiling.h>
#include <pcl/surface/cocone/triangulation.h>

#include <Eigen/Geometry>

#include "caller_ids.h"
#include "edge_sort.h"
#include "parallel.h"
#include "stopwatch.h"
#include "tiles.h"
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <new>
#include <set>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

namespace pcl {
namespace cocone {

namespace detail {

namespace {

/** Points sampled for a tile's spacing. */
constexpr std::size_t SPACING_SAMPLES = 512;

} // namespace

/** The median distance of the points of \a index to their nearest other point (a
 * distinct one), over an even sample of them; 0 if all coincide. A grid of cells
 * about twice the spacing a surface through the box would have; where most samples
 * find no neighbour within a cell, the cells grow. */
double
medianSpacing(const std::vector<Eigen::Vector3d>& P,
              const int* index,
              std::size_t n,
              const Box& box)
{
  Eigen::Vector3d e = box.hi - box.lo;
  std::sort(e.data(), e.data() + 3, std::greater<>());
  if (n < 2 || !(e[0] > 0.0))
    return 0.0;
  double cell = 2.0 * std::sqrt(std::max(e[0] * e[1], e[0] * e[0] * 1e-12) /
                                static_cast<double>(n));
  cell = std::max(cell, e[0] / double(1 << 20));
  const std::size_t samples = std::min(n, SPACING_SAMPLES);
  std::vector<std::pair<std::uint64_t, int>> keyed(n);
  std::vector<double> nearest(samples);
  for (int attempt = 0; attempt < 12; ++attempt, cell *= 4.0) {
    const auto coordinate = [&](const Eigen::Vector3d& p, int k) {
      return static_cast<std::int64_t>(std::floor((p[k] - box.lo[k]) / cell));
    };
    const auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
      return static_cast<std::uint64_t>(x) << 42 | static_cast<std::uint64_t>(y) << 21 |
             static_cast<std::uint64_t>(z);
    };
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d& p = P[index[i]];
      keyed[i] = {key(coordinate(p, 0), coordinate(p, 1), coordinate(p, 2)), index[i]};
    }
    std::sort(keyed.begin(), keyed.end());
    std::size_t found = 0;
    for (std::size_t s = 0; s < samples; ++s) {
      const Eigen::Vector3d& p = P[index[s * n / samples]];
      const std::int64_t c[3] = {coordinate(p, 0), coordinate(p, 1), coordinate(p, 2)};
      double best = std::numeric_limits<double>::infinity();
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const std::int64_t x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
            if (x < 0 || y < 0 || z < 0)
              continue;
            const std::uint64_t k = key(x, y, z);
            auto it =
                std::lower_bound(keyed.begin(),
                                 keyed.end(),
                                 std::make_pair(k, std::numeric_limits<int>::min()));
            for (; it != keyed.end() && it->first == k; ++it) {
              const double d = (P[it->second] - p).norm();
              if (d > 0.0 && d < best)
                best = d;
            }
          }
      // Within a cell of p every point is in the 27 cells: the nearest is exact.
      nearest[s] = best <= cell ? best : std::numeric_limits<double>::infinity();
      found += best <= cell;
    }
    if (2 * found > samples) {
      std::nth_element(nearest.begin(), nearest.begin() + samples / 2, nearest.end());
      return nearest[samples / 2];
    }
  }
  return 0.0;
}

void
add(ReconstructionCounts& a, const ReconstructionCounts& b)
{
  a.candidates += b.candidates;
  a.umbrella_failures += b.umbrella_failures;
  a.pruned += b.pruned;
  a.walk_components += b.walk_components;
  a.walked += b.walked;
  a.walk_conflicts += b.walk_conflicts;
  a.walk_reseeds += b.walk_reseeds;
  a.repair.nonmanifold_edge += b.repair.nonmanifold_edge;
  a.repair.nonmanifold_vertex += b.repair.nonmanifold_vertex;
  a.repair.orientation += b.repair.orientation;
  a.repair.flipped += b.repair.flipped;
  a.repair.filled += b.repair.filled;
  a.repair.ribbon += b.repair.ribbon;
  a.repair.speck += b.repair.speck;
  a.repair.peeled += b.repair.peeled;
  a.unmeshed_parts += b.unmeshed_parts;
  a.true_borders += b.true_borders;
  a.holes_filled += b.holes_filled;
  a.handles_cut += b.handles_cut;
  a.necks_cut += b.necks_cut;
  a.hole_triangles += b.hole_triangles;
}

void
add(Timings& a, const Timings& b)
{
  a.unique += b.unique;
  a.delaunay += b.delaunay;
  a.noise += b.noise;
  a.voronoi += b.voronoi;
  a.boundary += b.boundary;
  a.reconstruction += b.reconstruction;
}

double
median(std::vector<double> v)
{
  if (v.empty())
    return 0.0;
  const auto m = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), m, v.end());
  return *m;
}

std::vector<std::vector<int>>
distinctHoles(std::vector<std::pair<bool, std::vector<int>>> candidates)
{
  std::sort(candidates.begin(), candidates.end());
  std::vector<std::vector<int>> holes;
  std::set<int> taken;
  for (auto& candidate : candidates) {
    std::vector<int>& rim = candidate.second;
    if (std::any_of(rim.begin(), rim.end(), [&](int id) { return taken.count(id); }))
      continue;
    taken.insert(rim.begin(), rim.end());
    holes.push_back(std::move(rim));
  }
  detail::sortLoops(holes);
  return holes;
}

std::vector<std::uint8_t>
turnPatches(const EdgeIncidences& incidences,
            const std::vector<int>& patch,
            std::size_t patches)
{
  std::vector<std::array<int, 3>> votes; // patch, patch, 1 if they agree
  for (std::size_t e = 0; e < incidences.edges.size(); ++e) {
    if (incidences.count(e) != 2)
      continue;
    const std::size_t i = incidences.first[e];
    const int a = patch[incidences.triangle[i]], b = patch[incidences.triangle[i + 1]];
    if (a != b)
      votes.push_back({std::min(a, b),
                       std::max(a, b),
                       incidences.forward[i] != incidences.forward[i + 1]});
  }
  std::sort(votes.begin(), votes.end());
  struct Pair {
    int a, b;
    long agree, disagree;
  };
  std::vector<Pair> pairs;
  for (const auto& v : votes) {
    if (pairs.empty() || pairs.back().a != v[0] || pairs.back().b != v[1])
      pairs.push_back({v[0], v[1], 0, 0});
    (v[2] ? pairs.back().agree : pairs.back().disagree) += 1;
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) {
    return std::abs(x.agree - x.disagree) > std::abs(y.agree - y.disagree);
  });
  ConcurrentParitySets sets(patches, 1);
  for (const Pair& p : pairs)
    if (p.agree != p.disagree)
      sets.unite(p.a, p.b, p.disagree > p.agree ? 1 : 0);
  std::vector<std::uint8_t> turn(patches, 0);
  for (std::size_t c = 0; c < patches; ++c)
    turn[c] = static_cast<std::uint8_t>(sets.find(static_cast<int>(c)).parity);
  return turn;
}

void
turnNormal(Eigen::Vector3d& normal, const Eigen::Vector3d& facing, bool recompute)
{
  if (facing.squaredNorm() == 0.0)
    normal = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  else if (recompute || !normal.allFinite())
    normal = facing.normalized();
  else if (normal.dot(facing) < 0.0)
    normal = -normal;
}

} // namespace detail

namespace {

using detail::add;
using detail::Box;
using detail::distinctHoles;
using detail::forEachTask;
using detail::median;
using detail::medianSpacing;
using detail::SEAM_HOLE_EDGES;
using detail::tileBytes;
using detail::Tiles;

/** The position in the points of each caller id. */
class IdIndex {
public:
  /** False (with \a error) if the ids are not distinct. \a count: the number of
   * points, which are their own ids when \a ids is empty. */
  bool
  build(const std::vector<int>& ids, std::size_t count, std::string& error)
  {
    ids_ = &ids;
    count_ = count;
    if (ids.empty())
      return true;
    const auto [lo, hi] = std::minmax_element(ids.begin(), ids.end());
    low_ = *lo;
    const auto range = static_cast<std::uint64_t>(static_cast<std::int64_t>(*hi) - *lo);
    if (range < 4 * static_cast<std::uint64_t>(ids.size()) + 1024) {
      dense_.assign(range + 1, -1);
      for (std::size_t i = 0; i < ids.size(); ++i) {
        int& slot = dense_[static_cast<std::size_t>(ids[i] - low_)];
        if (slot >= 0) {
          error = "the ids are not distinct (" + std::to_string(ids[i]) + " twice)";
          return false;
        }
        slot = static_cast<int>(i);
      }
      return true;
    }
    sorted_.reserve(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      sorted_.emplace_back(ids[i], static_cast<int>(i));
    std::sort(sorted_.begin(), sorted_.end());
    for (std::size_t i = 1; i < sorted_.size(); ++i)
      if (sorted_[i].first == sorted_[i - 1].first) {
        error =
            "the ids are not distinct (" + std::to_string(sorted_[i].first) + " twice)";
        return false;
      }
    return true;
  }

  /** The ids it was built with (empty: the positions). */
  const std::vector<int>&
  all() const
  {
    return *ids_;
  }

  int
  id(std::size_t position) const
  {
    return ids_->empty() ? static_cast<int>(position) : (*ids_)[position];
  }

  /** The position of \a id (one of the ids). */
  int
  position(int id) const
  {
    if (ids_->empty())
      return id;
    if (!dense_.empty())
      return dense_[static_cast<std::size_t>(static_cast<std::int64_t>(id) - low_)];
    const auto it =
        std::lower_bound(sorted_.begin(),
                         sorted_.end(),
                         std::make_pair(id, std::numeric_limits<int>::min()));
    return it->second;
  }

  /** Whether \a id is one of the ids. */
  bool
  contains(int id) const
  {
    if (ids_->empty())
      return id >= 0 && static_cast<std::size_t>(id) < count_;
    if (!dense_.empty()) {
      const std::int64_t k = static_cast<std::int64_t>(id) - low_;
      return k >= 0 && static_cast<std::size_t>(k) < dense_.size() &&
             dense_[static_cast<std::size_t>(k)] >= 0;
    }
    const auto it =
        std::lower_bound(sorted_.begin(),
                         sorted_.end(),
                         std::make_pair(id, std::numeric_limits<int>::min()));
    return it != sorted_.end() && it->first == id;
  }

private:
  const std::vector<int>* ids_ = nullptr;
  std::size_t count_ = 0;
  int low_ = 0;
  std::vector<int> dense_;
  std::vector<std::pair<int, int>> sorted_;
};

/** The stitch of stitchTiles(), on checked input. */
Result
stitch(TilePlan& plan,
       std::vector<TileResult>& outputs,
       const Parameters& parameters,
       const IdIndex& ids,
       TilingReport& report)
{
  Result result;
  detail::Stopwatch clock;
  const std::size_t n = plan.points;
  const std::size_t count = plan.tiles();
  const int threads = resolveThreads(parameters.threads);
  result.vertex_of_input.assign(n, -1);
  report.tiles = count;
  report.cut_ms = plan.cut_ms;
  std::vector<std::vector<int>>().swap(plan.halo);
  // No tile with a mesh: as run() on the whole would, no result.
  if (std::all_of(outputs.begin(), outputs.end(), [](const TileResult& o) {
        return !o.degenerate.empty();
      })) {
    result.error = outputs[0].degenerate;
    result.vertex_of_input.clear();
    return result;
  }

  // Labels per point from the tile of its core; vertices numbered in the order of
  // their representatives' positions.
  std::vector<int> representative_of(n, -1);
  std::vector<std::uint8_t> flags(n, 0);
  std::vector<int> slot(n, -1); // of a representative: its index in its tile's lists
  const bool noise = parameters.noise_handling;
  if (noise)
    result.point_noise.assign(n, std::numeric_limits<float>::quiet_NaN());
  std::vector<double> ratios, after;
  // The holes the tiles closed (caller ids), each marked whether another tile owns
  // its rim's lowest id.
  std::vector<std::pair<bool, std::vector<int>>> filled;
  for (std::size_t t = 0; t < count; ++t) {
    TileResult& o = outputs[t];
    const std::size_t core_size = plan.coreSize(t);
    int k = 0;
    for (std::size_t i = 0; i < core_size; ++i) {
      const int p = plan.order[plan.core_begin[t] + i];
      representative_of[p] = o.representative[i];
      flags[p] = o.flags[i];
      if (o.representative[i] == ids.id(static_cast<std::size_t>(p)))
        slot[p] = k++;
      if (noise && !o.noise.empty())
        result.point_noise[p] = o.noise[i];
    }
    std::vector<int>().swap(o.representative);
    std::vector<std::uint8_t>().swap(o.flags);
    std::vector<float>().swap(o.noise);
    report.halo_points += o.points - core_size;
    report.largest_tile = std::max(report.largest_tile, o.points);
    report.degenerate_tiles += !o.degenerate.empty();
    if (o.degenerate.empty())
      ratios.push_back(o.ratio);
    if (o.noise_after_smoothing > 0.0)
      after.push_back(o.noise_after_smoothing);
    result.smoothed = result.smoothed || o.smoothed;
    for (auto& rim : o.filled_holes) {
      const bool owner =
          plan.point_tile[static_cast<std::size_t>(ids.position(rim[0]))] ==
          static_cast<int>(t);
      filled.push_back({!owner, std::move(rim)});
    }
    std::vector<std::vector<int>>().swap(o.filled_holes);
    add(result.counts, o.counts);
    add(result.timings, o.timings);
  }
  result.ratio = median(ratios);
  result.noise_after_smoothing = median(after);
  if (noise) {
    std::vector<double> levels;
    for (const float l : result.point_noise)
      if (std::isfinite(l))
        levels.push_back(l);
    result.noise_level = median(levels);
  }
  result.offset = plan.offset;
  std::vector<int> vertex_tile;
  for (std::size_t p = 0; p < n; ++p)
    if (slot[p] >= 0) {
      const auto& o = outputs[plan.point_tile[p]];
      result.representative.push_back(ids.id(p));
      result.positions.push_back(o.position[slot[p]] - result.offset);
      result.normals.push_back(o.normal[slot[p]]);
      result.boundary.push_back(flags[p] & 1);
      result.umbrella_failed.push_back((flags[p] >> 1) & 1);
      slot[p] = static_cast<int>(result.representative.size() - 1);
    }
  for (auto& o : outputs) {
    std::vector<Eigen::Vector3d>().swap(o.position);
    std::vector<Eigen::Vector3d>().swap(o.normal);
  }
  const std::size_t nv = result.representative.size();
  result.vertices = nv;
  for (std::size_t p = 0; p < n; ++p) {
    const int rep = representative_of[p];
    if (rep == -2) {
      result.vertex_of_input[p] = -2;
      result.outlier_indices.push_back(ids.id(p));
    }
    else if (rep >= 0) {
      result.vertex_of_input[p] = slot[ids.position(rep)];
      if (flags[p])
        result.boundary_indices.push_back(ids.id(p));
    }
  }
  std::sort(result.outlier_indices.begin(), result.outlier_indices.end());
  std::sort(result.boundary_indices.begin(), result.boundary_indices.end());
  std::vector<int>().swap(representative_of);
  std::vector<int>().swap(slot);
  std::vector<std::uint8_t>().swap(flags);
  std::vector<int>().swap(plan.order);

  // The kept triangles over vertex ids; their patches; the tiles' other triangles.
  const auto vertex = [&](int id) { return result.vertex_of_input[ids.position(id)]; };
  std::vector<Triangle>& triangles = result.triangles;
  std::vector<int> tile_of_triangle, patch;
  std::vector<Triangle> seen;
  std::size_t patches = 0;
  for (std::size_t t = 0; t < count; ++t) {
    TileResult& o = outputs[t];
    std::vector<Triangle> mine;
    mine.reserve(o.kept.size());
    for (const Triangle& tri : o.kept) {
      const Triangle v{vertex(tri[0]), vertex(tri[1]), vertex(tri[2])};
      if (v[0] < 0 || v[1] < 0 || v[2] < 0)
        ++report.seam_dropped;
      else
        mine.push_back(v);
    }
    std::vector<Triangle>().swap(o.kept);
    std::size_t components = 0;
    const std::vector<int> component = triangleComponents(mine, &components);
    triangles.insert(triangles.end(), mine.begin(), mine.end());
    tile_of_triangle.insert(tile_of_triangle.end(), mine.size(), static_cast<int>(t));
    for (const int c : component)
      patch.push_back(static_cast<int>(patches) + c);
    patches += components;
    for (const Triangle& tri : o.seen) {
      Triangle v{vertex(tri[0]), vertex(tri[1]), vertex(tri[2])};
      if (v[0] >= 0 && v[1] >= 0 && v[2] >= 0) {
        std::sort(v.begin(), v.end());
        seen.push_back(v);
      }
    }
    std::vector<Triangle>().swap(o.seen);
  }
  std::vector<TileResult>().swap(outputs);
  report.patches = patches;

  // Patches turned over to agree with their neighbours: per pair of patches the
  // shared edges vote, the pairs with the clearest vote first (the first pair that
  // joins two sets decides them).
  EdgeIncidences incidences(triangles, threads);
  {
    const std::vector<std::uint8_t> turn =
        detail::turnPatches(incidences, patch, patches);
    std::vector<std::uint8_t> turned(triangles.size(), 0);
    for (std::size_t c = 0; c < patches; ++c)
      report.patches_flipped += turn[c];
    for (std::size_t t = 0; t < triangles.size(); ++t)
      if (turn[patch[t]]) {
        std::swap(triangles[t][1], triangles[t][2]);
        turned[t] = 1;
      }
    for (std::size_t i = 0; i < incidences.triangle.size(); ++i)
      incidences.forward[i] ^= turned[incidences.triangle[i]];
  }
  std::vector<int>().swap(patch);

  // One oriented manifold: the repair of the stitched mesh, then the seam holes.
  const std::vector<Triangle> before = triangles;
  repairManifold(result.positions, triangles, report.stitch, threads, &incidences);
  // Which tile kept each triangle left: the repair keeps their order. The ones it
  // dropped may close a seam hole again, as may the tiles' triangles others kept.
  const auto ascending = [](Triangle t) {
    std::sort(t.begin(), t.end());
    return t;
  };
  std::vector<int> kept_by(triangles.size(), -1);
  for (std::size_t i = 0, j = 0; i < before.size(); ++i)
    if (j < triangles.size() && ascending(before[i]) == ascending(triangles[j]))
      kept_by[j++] = tile_of_triangle[i];
    else
      seen.push_back(ascending(before[i]));
  std::vector<int>().swap(tile_of_triangle);
  std::sort(seen.begin(), seen.end());
  seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
  // A seam hole of three edges whose triangle no tile made is closed by that
  // triangle (closesSeamHole()).
  const auto core_of = [&](int v) {
    return plan.point_tile[ids.position(result.representative[v])];
  };
  const auto tile_of = [&](int t) { return kept_by[t]; };
  report.seam_filled = fillHoles(
      result.positions,
      triangles,
      [&](const Triangle& t) {
        return std::binary_search(seen.begin(), seen.end(), t) ||
               detail::closesSeamHole(incidences, t, core_of, tile_of);
      },
      SEAM_HOLE_EDGES,
      &incidences);
  kept_by.resize(triangles.size(), -1);
  result.border_loops = boundaryLoops(incidences, nv);
  incidences = EdgeIncidences();
  std::vector<Triangle>().swap(seen);

  // A canonical order, as run() gives.
  struct Kept {
    Triangle t;
    int tile;
  };
  std::vector<Kept> order(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    Triangle& v = triangles[t];
    std::rotate(v.begin(), std::min_element(v.begin(), v.end()), v.end());
    order[t] = {v, kept_by[t]};
  }
  detail::sortByVertexIds(
      order, nv, [](const Kept& k) { return k.t; }, threads);
  report.triangle_tile.resize(order.size());
  for (std::size_t t = 0; t < order.size(); ++t) {
    triangles[t] = order[t].t;
    report.triangle_tile[t] = order[t].tile;
  }

  // Normals against the stitched mesh, as run() turns them.
  std::vector<Eigen::Vector3d> facing(nv, Eigen::Vector3d::Zero());
  for (const auto& t : triangles) {
    const auto& P = result.positions;
    const Eigen::Vector3d a = (P[t[1]] - P[t[0]]).cross(P[t[2]] - P[t[0]]);
    for (const int v : t)
      facing[v] += a;
  }
  for (std::size_t v = 0; v < nv; ++v)
    detail::turnNormal(
        result.normals[v], facing[v], result.boundary[v] || result.umbrella_failed[v]);

  report.point_tile = std::move(plan.point_tile);
  detail::meshToCallerIds(result);
  result.filled_holes = distinctHoles(std::move(filled));
  result.counts.holes_filled = result.filled_holes.size();
  // Refined on the stitched mesh, so that the added vertices are numbered once.
  const int first_added = detail::firstAddedId(ids.all(), n);
  if (parameters.refine_filled_holes && first_added >= 0)
    refineFilledHoles(result, first_added);
  report.stitch_ms = clock.lap();
  result.timings.unique += report.cut_ms;
  result.timings.reconstruction += report.stitch_ms;
  return result;
}

} // namespace

std::size_t
availableMemory()
{
  const auto read_number = [](const char* path, std::size_t& value) {
    std::ifstream in(path);
    std::string text;
    if (!(in >> text) || text.empty() ||
        !std::all_of(
            text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return false; // absent, or "max": no limit
    value = static_cast<std::size_t>(std::stoull(text));
    return true;
  };
  std::size_t available = 0;
  {
    std::ifstream meminfo("/proc/meminfo");
    std::string key;
    std::size_t kb = 0;
    std::string unit;
    while (meminfo >> key >> kb >> unit)
      if (key == "MemAvailable:") {
        available = kb * 1024;
        break;
      }
  }
#ifdef _SC_PHYS_PAGES
  if (available == 0) {
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    if (pages > 0 && size > 0)
      available = static_cast<std::size_t>(pages) * static_cast<std::size_t>(size);
  }
#endif
  // A container's limit: what the group may still take.
  std::size_t limit = 0, used = 0;
  if ((read_number("/sys/fs/cgroup/memory.max", limit) &&
       read_number("/sys/fs/cgroup/memory.current", used)) ||
      (read_number("/sys/fs/cgroup/memory/memory.limit_in_bytes", limit) &&
       read_number("/sys/fs/cgroup/memory/memory.usage_in_bytes", used))) {
    const std::size_t room = limit > used ? limit - used : 0;
    available = available == 0 ? room : std::min(available, room);
  }
  // What the process holds counts towards its peak.
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0, resident = 0;
  const long page = sysconf(_SC_PAGESIZE);
  if (available > 0 && (statm >> pages >> resident) && page > 0)
    available += resident * static_cast<std::size_t>(page);
  return available;
}

namespace {} // namespace

namespace detail {

double
tileBytes(double core)
{
  return 1.25 * static_cast<double>(ONE_PIECE_BYTES_PER_POINT) * core;
}

std::size_t
seriesTilePoints(double core)
{
  // Down to the series (Renard's R10), in whole points.
  static const int series[] = {100, 125, 160, 200, 250, 320, 400, 500, 630, 800};
  double decade = 1.0;
  while (decade * 10.0 <= core)
    decade *= 10.0;
  std::size_t tile = MINIMUM_TILE_POINTS;
  for (const int step : series) {
    const double candidate = std::floor(decade * step / 100.0);
    if (candidate <= core && candidate >= static_cast<double>(MINIMUM_TILE_POINTS))
      tile = static_cast<std::size_t>(candidate);
  }
  return tile;
}

} // namespace detail

std::size_t
automaticTilePoints(std::size_t points, std::size_t memory, bool* fits)
{
  if (fits)
    *fits = true;
  const double budget = static_cast<double>(memory);
  const double n = static_cast<double>(points);
  if (memory == 0 || n * ONE_PIECE_BYTES_PER_POINT <= budget)
    return 0;
  const double core = (budget - n * TILED_BYTES_PER_POINT) / tileBytes(1.0);
  if (!(core >= static_cast<double>(MINIMUM_TILE_POINTS))) {
    if (fits)
      *fits = false;
    return MINIMUM_TILE_POINTS;
  }
  return detail::seriesTilePoints(core);
}

unsigned int
automaticTilesInFlight(std::size_t points,
                       std::size_t memory,
                       std::size_t tile_points,
                       unsigned int threads)
{
  if (tile_points == 0)
    return std::max(1u, threads);
  const double room =
      static_cast<double>(memory) - static_cast<double>(points) * TILED_BYTES_PER_POINT;
  const double fit = std::floor(room / tileBytes(static_cast<double>(tile_points)));
  return static_cast<unsigned>(
      std::max(1.0, std::min(fit, static_cast<double>(std::max(1u, threads)))));
}

TilingOptions
automaticTiling(std::size_t points,
                std::size_t memory,
                unsigned int threads,
                bool* fits)
{
  TilingOptions tiling;
  tiling.tile_points = automaticTilePoints(points, memory, fits);
  if (tiling.tile_points > 0)
    tiling.tiles_in_flight = automaticTilesInFlight(
        points,
        memory,
        tiling.tile_points,
        threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency()));
  return tiling;
}

std::vector<int>
TilePlan::tilePoints(std::size_t tile) const
{
  std::vector<int> members(
      order.begin() + static_cast<std::ptrdiff_t>(core_begin[tile]),
      order.begin() + static_cast<std::ptrdiff_t>(core_begin[tile + 1]));
  members.insert(members.end(), halo[tile].begin(), halo[tile].end());
  return members;
}

TilePlan
planTiles(const std::vector<Eigen::Vector3d>& points,
          const Parameters& parameters,
          const TilingOptions& tiling,
          const std::vector<int>& ids)
{
  TilePlan plan;
  detail::Stopwatch clock;
  const std::size_t n = points.size();
  plan.points = n;
  if (!ids.empty() && ids.size() != n) {
    plan.error = "ids has " + std::to_string(ids.size()) + " entries for " +
                 std::to_string(n) + " points";
    return plan;
  }
  if (tiling.tile_points > 0 && tiling.tile_points < MINIMUM_TILE_POINTS) {
    plan.error = "tile_points must be 0 (one piece) or at least " +
                 std::to_string(MINIMUM_TILE_POINTS) + " (got " +
                 std::to_string(tiling.tile_points) + ")";
    return plan;
  }
  if (!(tiling.halo_spacings >= 0.0) || !std::isfinite(tiling.halo_spacings)) {
    plan.error = "halo_spacings must be finite and >= 0";
    return plan;
  }
  try {
    IdIndex index;
    if (!index.build(ids, n, plan.error))
      return plan;
    std::vector<int> finite;
    Box all;
    for (std::size_t i = 0; i < n; ++i)
      if (points[i].allFinite()) {
        finite.push_back(static_cast<int>(i));
        all.extend(points[i]);
      }
    if (!finite.empty())
      plan.offset = 0.5 * (all.lo + all.hi);
    plan.point_tile.assign(n, -1);
    if (tiling.tile_points == 0 || finite.size() <= tiling.tile_points) {
      plan.one_piece = true;
      for (const int p : finite)
        plan.point_tile[p] = 0;
      plan.core_begin = {0, finite.size()};
      plan.order = std::move(finite);
      plan.halo.resize(1);
      plan.cut_ms = clock.lap();
      return plan;
    }
    Tiles tiles(points, std::move(finite), tiling.tile_points);
    const std::size_t count = tiles.size();
    plan.core_begin.resize(count + 1);
    for (std::size_t t = 0; t < count; ++t) {
      plan.core_begin[t] = tiles.core(t).begin;
      for (std::size_t i = tiles.core(t).begin; i < tiles.core(t).end; ++i)
        plan.point_tile[tiles.order()[i]] = static_cast<int>(t);
    }
    plan.core_begin[count] = tiles.order().size();
    // The halo of each tile: the points within its reach, which is measured on its
    // own core's spacing.
    plan.halo.resize(count);
    const int threads = resolveThreads(parameters.threads);
    forEachTask(count,
                static_cast<int>(std::min<std::size_t>(threads, count)),
                [&](std::size_t t) {
                  const auto& core = tiles.core(t);
                  const double reach = tiling.halo_spacings *
                                       medianSpacing(points,
                                                     tiles.order().data() + core.begin,
                                                     core.end - core.begin,
                                                     core.box);
                  plan.halo[t] = tiles.halo(t, reach);
                });
    plan.order = tiles.takeOrder();
    plan.cut_ms = clock.lap();
  }
  catch (const std::bad_alloc&) {
    plan = TilePlan();
    plan.points = n;
    plan.error = "out of memory for " + std::to_string(n) + " points";
  }
  catch (const std::system_error& e) { // no thread could be started
    plan = TilePlan();
    plan.points = n;
    plan.error = std::string("system error: ") + e.what();
  }
  return plan;
}

TileResult
reconstructTile(const TilePlan& plan,
                std::size_t tile,
                const std::vector<Eigen::Vector3d>& points,
                const Parameters& parameters,
                const std::vector<int>& ids)
{
  TileResult out;
  if (!plan.error.empty())
    out.error = "the plan failed: " + plan.error;
  else if (tile >= plan.tiles())
    out.error = "no tile " + std::to_string(tile) + " in a plan of " +
                std::to_string(plan.tiles());
  else if (points.size() != plan.points || (!ids.empty() && ids.size() != plan.points))
    out.error = "the points or ids are not those of the plan";
  if (!out.error.empty())
    return out;
  try {
    std::vector<Eigen::Vector3d> local;
    std::vector<int> local_ids;
    {
      const std::vector<int> members = plan.tilePoints(tile);
      local.reserve(members.size());
      local_ids.reserve(members.size());
      for (const int p : members) {
        local.push_back(points[p]);
        local_ids.push_back(ids.empty() ? p : ids[p]);
      }
    }
    return reconstructTile(
        std::move(local), local_ids, plan.coreSize(tile), parameters);
  }
  catch (const std::bad_alloc&) {
    out.error = "out of memory";
  }
  return out;
}

TileResult
reconstructTile(std::vector<Eigen::Vector3d> points,
                const std::vector<int>& ids,
                std::size_t core_points,
                const Parameters& parameters)
{
  TileResult out;
  try {
    if (ids.size() != points.size()) {
      out.error = "ids has " + std::to_string(ids.size()) + " entries for " +
                  std::to_string(points.size()) + " points";
      return out;
    }
    if (core_points > points.size()) {
      out.error = "core_points " + std::to_string(core_points) + " of " +
                  std::to_string(points.size()) + " points";
      return out;
    }
    for (std::size_t i = 0; i < points.size(); ++i)
      if (!points[i].allFinite()) {
        out.error = "tile point " + std::to_string(i) + " is not finite";
        return out;
      }
    IdIndex index;
    if (!index.build(ids, points.size(), out.error))
      return out;
    out.points = points.size();
    // What the stitch needs of the core: a degenerate tile's positions are its own,
    // and the ownership rule asks whether a triangle's lowest id is in the core.
    const std::vector<Eigen::Vector3d> core_positions(
        points.begin(), points.begin() + static_cast<std::ptrdiff_t>(core_points));
    std::vector<int> core_ids(ids.begin(),
                              ids.begin() + static_cast<std::ptrdiff_t>(core_points));
    std::sort(core_ids.begin(), core_ids.end());

    Parameters core_statistics = parameters; // the core comes first: it alone counts
    core_statistics.statistics_points = core_points;
    core_statistics.refine_filled_holes = false; // after the stitch
    Result r = run(std::move(points), core_statistics, Stages::RECONSTRUCTION, ids);
    if (!r.error.empty() && r.vertex_of_input.size() != ids.size()) {
      out.error = r.error; // out of memory, no thread: nothing to go on with
      return out;
    }
    out.degenerate = r.error;
    out.ratio = r.ratio;
    out.noise_after_smoothing = r.noise_after_smoothing;
    out.smoothed = r.smoothed;
    out.counts = r.counts;
    out.timings = r.timings;

    // The representative of each vertex: its lowest caller id, as run() chooses.
    std::vector<int> representative(r.vertices, std::numeric_limits<int>::max());
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (r.vertex_of_input[i] >= 0)
        representative[r.vertex_of_input[i]] =
            std::min(representative[r.vertex_of_input[i]], ids[i]);
    out.representative.resize(core_points);
    out.flags.resize(core_points);
    const bool noise = r.point_noise.size() == ids.size();
    if (noise)
      out.noise.assign(r.point_noise.begin(),
                       r.point_noise.begin() +
                           static_cast<std::ptrdiff_t>(core_points));
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = 0; i < core_points; ++i) {
      const int v = r.vertex_of_input[i];
      if (v < 0) {
        out.representative[i] = -2; // finite, so an outlier
        continue;
      }
      out.representative[i] = representative[v];
      out.flags[i] = !out.degenerate.empty()
                         ? 1
                         : static_cast<std::uint8_t>((r.boundary[v] ? 1 : 0) |
                                                     (r.umbrella_failed[v] ? 2 : 0));
      if (representative[v] != ids[i])
        continue;
      if (!out.degenerate.empty()) {
        out.position.push_back(core_positions[i]);
        out.normal.push_back(Eigen::Vector3d::Constant(nan));
        continue;
      }
      out.position.push_back(r.positions[v] + r.offset);
      out.normal.push_back(r.normals[v]);
    }

    // The ownership rule: the tile whose core holds the lowest id keeps the triangle.
    for (const Triangle& tri : r.polygons) {
      const int lowest = std::min({tri[0], tri[1], tri[2]});
      if (std::binary_search(core_ids.begin(), core_ids.end(), lowest))
        out.kept.push_back(tri);
      else {
        Triangle sorted = tri;
        std::sort(sorted.begin(), sorted.end());
        out.seen.push_back(sorted);
      }
    }
    for (auto& hole : r.filled_holes)
      if (std::any_of(hole.begin(), hole.end(), [&](int id) {
            return std::binary_search(core_ids.begin(), core_ids.end(), id);
          }))
        out.filled_holes.push_back(std::move(hole));
  }
  catch (const std::bad_alloc&) {
    out = TileResult();
    out.error = "out of memory";
  }
  catch (const std::exception& e) {
    out = TileResult();
    out.error = e.what();
  }
  return out;
}

Result
stitchTiles(TilePlan plan,
            std::vector<TileResult> results,
            const Parameters& parameters,
            const std::vector<int>& ids,
            TilingReport* report)
{
  TilingReport local;
  TilingReport& rep = report ? *report : local;
  rep = TilingReport();
  Result failed;
  const std::size_t count = plan.tiles();
  if (!plan.error.empty()) {
    failed.error = "the plan failed: " + plan.error;
    return failed;
  }
  if (count == 0 || results.size() != count) {
    failed.error = std::to_string(results.size()) + " tile results for a plan of " +
                   std::to_string(count) + " tiles";
    return failed;
  }
  if (!ids.empty() && ids.size() != plan.points) {
    failed.error = "ids has " + std::to_string(ids.size()) + " entries for " +
                   std::to_string(plan.points) + " points";
    return failed;
  }
  for (std::size_t t = 0; t < count; ++t)
    if (!results[t].error.empty()) {
      failed.error = "tile " + std::to_string(t) + ": " + results[t].error;
      return failed;
    }
  try {
    IdIndex index;
    if (!index.build(ids, plan.points, failed.error))
      return failed;
    // Results from elsewhere are checked against the plan: a wrong one is an error,
    // not a crash.
    for (std::size_t t = 0; t < count; ++t) {
      const TileResult& o = results[t];
      const std::size_t core = plan.coreSize(t);
      std::size_t representatives = 0;
      bool fits = o.representative.size() == core && o.flags.size() == core &&
                  (o.noise.empty() || o.noise.size() == core);
      for (std::size_t i = 0; fits && i < core; ++i) {
        const int rep_id = o.representative[i];
        fits = rep_id == -2 || index.contains(rep_id);
        representatives += rep_id == index.id(plan.order[plan.core_begin[t] + i]);
      }
      fits = fits && o.position.size() == representatives &&
             o.normal.size() == representatives;
      for (const auto* list : {&o.kept, &o.seen})
        for (std::size_t i = 0; fits && i < list->size(); ++i)
          for (const int id : (*list)[i])
            fits = fits && index.contains(id);
      if (!fits) {
        failed.error = "the result of tile " + std::to_string(t) +
                       " does not fit the plan (made from other points or ids?)";
        return failed;
      }
    }
    return stitch(plan, results, parameters, index, rep);
  }
  catch (const std::bad_alloc&) {
    failed.error = "out of memory for " + std::to_string(plan.points) + " points";
  }
  catch (const std::system_error& e) { // no thread could be started
    failed.error = std::string("system error: ") + e.what();
  }
  rep = TilingReport();
  return failed;
}

Result
runTiled(std::vector<Eigen::Vector3d> points,
         const Parameters& parameters,
         const TilingOptions& tiling,
         const std::vector<int>& ids,
         TilingReport* report)
{
  TilingReport local;
  TilingReport& rep = report ? *report : local;
  rep = TilingReport();
  Result failed;
  TilePlan plan = planTiles(points, parameters, tiling, ids);
  if (!plan.error.empty()) {
    failed.error = plan.error;
    return failed;
  }
  const std::size_t count = plan.tiles(), n = points.size();
  try {
    if (plan.one_piece) {
      Result r = run(std::move(points), parameters, Stages::RECONSTRUCTION, ids);
      rep.tiles = 1;
      rep.largest_tile = plan.order.size();
      rep.point_tile = std::move(plan.point_tile);
      rep.triangle_tile.assign(r.polygons.size(), 0);
      return r;
    }
    // The tiles, a few at a time: each holds its triangulation while it runs.
    detail::Stopwatch clock;
    const int threads = resolveThreads(parameters.threads);
    const int in_flight = static_cast<int>(std::min<std::size_t>(
        tiling.tiles_in_flight > 0 ? tiling.tiles_in_flight : threads, count));
    Parameters tile_parameters = parameters;
    tile_parameters.threads = static_cast<unsigned>(std::max(1, threads / in_flight));
    std::vector<TileResult> results(count);
    forEachTask(count, in_flight, [&](std::size_t t) {
      results[t] = reconstructTile(plan, t, points, tile_parameters, ids);
    });
    const double tiles_ms = clock.lap();
    std::vector<Eigen::Vector3d>().swap(points);
    Result r = stitchTiles(std::move(plan), std::move(results), parameters, ids, &rep);
    if (r.error.empty())
      rep.tiles_ms = tiles_ms;
    return r;
  }
  catch (const std::bad_alloc&) {
    failed.error = "out of memory for " + std::to_string(n) + " points";
  }
  catch (const std::system_error& e) { // no thread could be started
    failed.error = std::string("system error: ") + e.what();
  }
  rep = TilingReport();
  return failed;
}

} // namespace cocone
} // namespace pcl
