/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

// Bit-identical samples on every platform also need a * b + c left unfused: in C++
// GCC fuses by default wherever the target has FMA (aarch64, x86-64-v3). Placed
// before the includes so that the inlined Eigen code follows it too. (An explicit
// -ffp-contract=fast still wins with Clang.)
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#include <Eigen/Geometry>

#include <support/surfaces.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <random>
#include <stdexcept>
#include <utility>

namespace cocone_test {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kLn2 = 0.69314718055994530942;

/* IEEE 754 rounds +, -, *, / and sqrt identically everywhere, libm functions may
 * differ by an ulp between platforms, and one flipped Poisson-disk decision changes
 * the rest of the sample. So the samplers avoid libm: directions come from rejection
 * in a cube or square, and the logarithm (Gaussian noise) and the cosines (circles,
 * cap rims) are computed here. */
double
portableLog(double x)
{
  int e = 0;
  double m = std::frexp(x, &e); // exact: x = m 2^e, m in [0.5, 1)
  if (m < 0.70710678118654752440) {
    m *= 2.0;
    --e;
  }
  // log m = 2 atanh z with |z| <= 0.172: 20 terms are far below an ulp.
  const double z = (m - 1.0) / (m + 1.0);
  const double z2 = z * z;
  double term = z, sum = 0.0;
  for (int k = 1; k <= 41; k += 2) {
    sum += term / k;
    term *= z2;
  }
  return 2.0 * sum + e * kLn2;
}

/** (cos x, sin x) by Taylor series after an exact reduction to [-pi, pi]: slower
 *  than libm, but the same on every platform (to about 1e-15). */
Eigen::Vector2d
portableCosSin(double x)
{
  x = std::remainder(x, 2.0 * kPi);
  double c = 0.0, s = 0.0, term = 1.0; // term = +-x^k / k!
  for (int k = 0; k < 40; k += 2) {
    c += term;
    term *= x / (k + 1);
    s += term;
    term *= -x / (k + 2);
  }
  return {c, s};
}

/* Eigen sums reductions in an order that depends on its vectorisation (SSE, NEON,
 * none), so everything that decides a sample uses these fixed-order ones. */
double
dot3(const Eigen::Vector3d& a, const Eigen::Vector3d& b)
{
  return a.x() * b.x() + a.y() * b.y() + a.z() * b.z();
}

double
sq3(const Eigen::Vector3d& a)
{
  return dot3(a, a);
}

double
sq2(const Eigen::Vector2d& a)
{
  return a.x() * a.x() + a.y() * a.y();
}

Eigen::Vector3d
unit3(const Eigen::Vector3d& a)
{
  return a / std::sqrt(sq3(a));
}

class Rng {
public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  /** Uniform in [0, 1) from the top 53 bits of one raw output. */
  double
  uniform01()
  {
    return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0);
  }

  double
  uniform(double a, double b)
  {
    return a + (b - a) * uniform01();
  }

  /** Standard normal: Box-Muller in Marsaglia's polar form (no sin / cos). */
  double
  normal()
  {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform01() - 1.0;
      v = 2.0 * uniform01() - 1.0;
      s = u * u + v * v;
    }
    while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * portableLog(s) / s);
    spare_ = v * f;
    has_spare_ = true;
    return u * f;
  }

  /** Uniform on the unit sphere: rejection in the cube, then normalise. */
  Eigen::Vector3d
  unitVector()
  {
    for (;;) {
      // Separate statements: the order of evaluation of arguments is unspecified.
      const double x = uniform(-1, 1);
      const double y = uniform(-1, 1);
      const double z = uniform(-1, 1);
      const Eigen::Vector3d v(x, y, z);
      const double s = sq3(v);
      if (s <= 1.0 && s > 1e-6)
        return v / std::sqrt(s);
    }
  }

  /** Uniform on the unit circle: (cos t, sin t) without trigonometry. */
  Eigen::Vector2d
  unitCircle()
  {
    for (;;) {
      const double x = uniform(-1, 1);
      const double y = uniform(-1, 1);
      const Eigen::Vector2d v(x, y);
      const double s = sq2(v);
      if (s <= 1.0 && s > 1e-6)
        return v / std::sqrt(s);
    }
  }

private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// ---------------------------------------------------------------------------------
// Surfaces as the samplers see them

struct Site {
  Eigen::Vector3d p;
  Eigen::Vector3d n;
  int component = 0;
};

using Distance = std::function<double(const Eigen::Vector3d&)>;

/** One smooth piece of a boundary loop, traversed from t0 to t1. */
struct CurvePiece {
  std::function<Eigen::Vector3d(double)> at;
  double t0 = 0.0, t1 = 0.0;
};
using Loop = std::vector<CurvePiece>;

/** One connected surface: an area-uniform site generator and its ground truth. */
struct Part {
  std::function<Site(Rng&)> draw;
  double area = 0.0;
  double x_lo = 0.0, x_hi = 0.0; // x extent: the density gradient runs along it
  Distance distance;
  std::vector<Loop> loops;
  int euler = 2;
};

Part
translated(Part part, const Eigen::Vector3d& offset)
{
  const auto draw = part.draw;
  part.draw = [draw, offset](Rng& rng) {
    Site s = draw(rng);
    s.p += offset;
    return s;
  };
  const auto distance = part.distance;
  part.distance = [distance, offset](const Eigen::Vector3d& q) {
    return distance(q - offset);
  };
  for (auto& loop : part.loops)
    for (auto& piece : loop) {
      const auto at = piece.at;
      piece.at = [at, offset](double t) -> Eigen::Vector3d { return at(t) + offset; };
    }
  part.x_lo += offset.x();
  part.x_hi += offset.x();
  return part;
}

Eigen::Vector3d
onCircle(const Eigen::Vector3d& centre,
         const Eigen::Vector3d& e1,
         const Eigen::Vector3d& e2,
         double radius,
         double t)
{
  const Eigen::Vector2d cs = portableCosSin(t);
  return centre + radius * (cs.x() * e1 + cs.y() * e2);
}

/** A full circle as a one-piece loop. */
Loop
circleLoop(const Eigen::Vector3d& centre,
           const Eigen::Vector3d& e1,
           const Eigen::Vector3d& e2,
           double radius)
{
  CurvePiece piece;
  piece.at = [=](double t) { return onCircle(centre, e1, e2, radius, t); };
  piece.t0 = 0.0;
  piece.t1 = 2.0 * kPi;
  return {piece};
}

// ---------------------------------------------------------------------------------
// Uniform hash grid

class PointGrid {
public:
  PointGrid(const std::vector<Eigen::Vector3d>& points, double cell) : cell_(cell)
  {
    std::vector<std::pair<std::uint64_t, int>> keyed(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d& p = points[i];
      keyed[i] = {key(coord(p.x()), coord(p.y()), coord(p.z())), static_cast<int>(i)};
    }
    // Sorting by cell keeps each cell's points contiguous (and cache friendly).
    std::sort(keyed.begin(), keyed.end());
    sorted_.reserve(points.size());
    index_.reserve(points.size());
    for (std::size_t a = 0; a < keyed.size(); ++a) {
      if (a == 0 || keyed[a].first != keyed[a - 1].first) {
        const Eigen::Vector3d& p = points[keyed[a].second];
        cells_.push_back(
            {coord(p.x()), coord(p.y()), coord(p.z()), static_cast<int>(a), 0});
      }
      cells_.back().end = static_cast<int>(a + 1);
      sorted_.push_back(points[keyed[a].second]);
      index_.push_back(keyed[a].second);
    }
    // Open addressing with linear probing, load <= 1/2: far fewer cache misses than
    // std::unordered_map, and the lookups dominate the run time.
    std::size_t capacity = 16;
    while (capacity < 2 * cells_.size())
      capacity *= 2;
    mask_ = capacity - 1;
    slot_key_.assign(capacity, kEmpty);
    slot_cell_.assign(capacity, -1);
    for (std::size_t c = 0; c < cells_.size(); ++c) {
      const std::uint64_t k = key(cells_[c].i, cells_[c].j, cells_[c].k);
      std::size_t h = mix(k) & mask_;
      while (slot_key_[h] != kEmpty)
        h = (h + 1) & mask_;
      slot_key_[h] = k;
      slot_cell_[h] = static_cast<int>(c);
    }
  }

  /** Calls f (index, squared distance) for every point within radius of q. */
  template <typename F>
  void
  forEachWithin(const Eigen::Vector3d& q, double radius, F&& f) const
  {
    const double r2 = radius * radius;
    const long x0 = coord(q.x() - radius), x1 = coord(q.x() + radius);
    const long y0 = coord(q.y() - radius), y1 = coord(q.y() + radius);
    const long z0 = coord(q.z() - radius), z1 = coord(q.z() + radius);
    for (long i = x0; i <= x1; ++i)
      for (long j = y0; j <= y1; ++j)
        for (long k = z0; k <= z1; ++k) {
          const Cell* c = find(i, j, k);
          if (!c)
            continue;
          for (int a = c->begin; a < c->end; ++a) {
            const double d2 = sq3(sorted_[a] - q);
            if (d2 <= r2)
              f(index_[a], d2);
          }
        }
  }

  /** Index of the nearest point other than skip within max_radius, else -1. */
  int
  nearest(const Eigen::Vector3d& q, double max_radius, int skip, double& distance) const
  {
    const long ci = coord(q.x()), cj = coord(q.y()), ck = coord(q.z());
    const long max_ring = static_cast<long>(std::ceil(max_radius / cell_)) + 1;
    int best = -1;
    double best2 = std::numeric_limits<double>::infinity();
    for (long ring = 0; ring <= max_ring; ++ring) {
      // Visit the shell of cells at Chebyshev distance `ring`.
      for (long di = -ring; di <= ring; ++di)
        for (long dj = -ring; dj <= ring; ++dj) {
          const bool inner = std::abs(di) < ring && std::abs(dj) < ring;
          const long step = inner ? 2 * ring : 1;
          for (long dk = -ring; dk <= ring; dk += step) {
            const Cell* c = find(ci + di, cj + dj, ck + dk);
            if (!c)
              continue;
            for (int a = c->begin; a < c->end; ++a) {
              if (index_[a] == skip)
                continue;
              const double d2 = sq3(sorted_[a] - q);
              if (d2 < best2 || (d2 == best2 && index_[a] < best)) {
                best2 = d2;
                best = index_[a];
              }
            }
          }
        }
      // Cells beyond this shell are more than ring * cell away from q.
      const double reach = ring * cell_;
      if (best >= 0 && best2 <= reach * reach)
        break;
    }
    if (best < 0 || best2 > max_radius * max_radius)
      return -1;
    distance = std::sqrt(best2);
    return best;
  }

  // Cell-wise traversal, for collecting all close pairs with one hash lookup per
  // neighbouring cell rather than per point.
  std::size_t
  cellCount() const
  {
    return cells_.size();
  }

  std::pair<int, int>
  cellRange(std::size_t c) const
  {
    return {cells_[c].begin, cells_[c].end};
  }

  /** Range (into the sorted order) of the cell at offset (di, dj, dk) from cell c. */
  std::pair<int, int>
  neighbourRange(std::size_t c, int di, int dj, int dk) const
  {
    const Cell* n = find(cells_[c].i + di, cells_[c].j + dj, cells_[c].k + dk);
    return n ? std::make_pair(n->begin, n->end) : std::make_pair(0, 0);
  }

  const Eigen::Vector3d&
  sortedPoint(int a) const
  {
    return sorted_[a];
  }

  int
  originalIndex(int a) const
  {
    return index_[a];
  }

private:
  struct Cell {
    long i, j, k;
    int begin, end;
  };

  // 21 bits per coordinate; clamping only matters for absurdly far queries.
  static constexpr long kOffset = 1L << 20;

  long
  coord(double x) const
  {
    const double c = std::floor(x / cell_);
    const double limit = static_cast<double>(kOffset - 2);
    return static_cast<long>(std::max(-limit, std::min(limit, c)));
  }

  static std::uint64_t
  key(long i, long j, long k)
  {
    return static_cast<std::uint64_t>(i + kOffset) |
           (static_cast<std::uint64_t>(j + kOffset) << 21) |
           (static_cast<std::uint64_t>(k + kOffset) << 42);
  }

  /** The packed key has structure in its low bits: the splitmix64 finaliser. */
  static std::uint64_t
  mix(std::uint64_t x)
  {
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  }

  const Cell*
  find(long i, long j, long k) const
  {
    const std::uint64_t wanted = key(i, j, k);
    for (std::size_t h = mix(wanted) & mask_;; h = (h + 1) & mask_) {
      if (slot_key_[h] == wanted)
        return &cells_[slot_cell_[h]];
      if (slot_key_[h] == kEmpty)
        return nullptr;
    }
  }

  double cell_;
  std::vector<Eigen::Vector3d> sorted_;
  std::vector<int> index_;
  std::vector<Cell> cells_;
  // Packed keys use 63 bits, so all ones marks an empty slot.
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
  std::vector<std::uint64_t> slot_key_;
  std::vector<int> slot_cell_;
  std::size_t mask_ = 0;
};

// ---------------------------------------------------------------------------------
// Site sampling

void
checkOptions(const SampleOptions& o)
{
  if (o.n < 4)
    throw std::invalid_argument("cocone_test: SampleOptions::n must be at least 4");
  if (!(o.noise >= 0.0) || !std::isfinite(o.noise))
    throw std::invalid_argument("cocone_test: SampleOptions::noise must be >= 0");
  if (!(o.density_ratio >= 1.0) || !std::isfinite(o.density_ratio))
    throw std::invalid_argument(
        "cocone_test: SampleOptions::density_ratio must be >= 1");
}

/** Relative density in [1, ratio], linear in t in [0, 1]. */
double
densityAt(double t, double ratio)
{
  return 1.0 + (ratio - 1.0) * std::max(0.0, std::min(1.0, t));
}

/** Area-uniform sites of a union of parts, thinned to the density profile. */
class SiteSource {
public:
  SiteSource(const std::vector<Part>& parts, double ratio)
  : parts_(parts), ratio_(ratio)
  {
    double sum = 0.0;
    for (const Part& part : parts) {
      sum += part.area;
      cumulative_.push_back(sum);
    }
  }

  Site
  draw(Rng& rng)
  {
    for (;;) {
      const double u = rng.uniform01() * cumulative_.back();
      std::size_t k = std::upper_bound(cumulative_.begin(), cumulative_.end(), u) -
                      cumulative_.begin();
      k = std::min(k, parts_.size() - 1);
      Site s = parts_[k].draw(rng);
      s.component = static_cast<int>(k);
      ++proposed_;
      if (ratio_ <= 1.0 || rng.uniform01() * ratio_ < density(s)) {
        ++accepted_;
        return s;
      }
    }
  }

  double
  density(const Site& s) const
  {
    if (ratio_ <= 1.0)
      return 1.0;
    const Part& part = parts_[s.component];
    return densityAt((s.p.x() - part.x_lo) / (part.x_hi - part.x_lo), ratio_);
  }

  /** Area average of density (), from the acceptance rate so far. */
  double
  meanDensity() const
  {
    return ratio_ <= 1.0 ? 1.0 : ratio_ * double(accepted_) / double(proposed_);
  }

  double
  area() const
  {
    return cumulative_.back();
  }

private:
  const std::vector<Part>& parts_;
  std::vector<double> cumulative_;
  double ratio_;
  std::size_t proposed_ = 0, accepted_ = 0;
};

std::vector<Site>
randomSites(const std::vector<Part>& parts, const SampleOptions& o, Rng& rng)
{
  SiteSource source(parts, o.density_ratio);
  std::vector<Site> sites;
  sites.reserve(o.n);
  for (std::size_t i = 0; i < o.n; ++i)
    sites.push_back(source.draw(rng));
  return sites;
}

/** Whether two candidates (by index) may exclude each other; empty: any two may. */
using Together = std::function<bool(std::uint32_t, std::uint32_t)>;

/** For each candidate, the earlier candidates closer than the cut-off. */
struct CloseEarlier {
  std::vector<std::uint32_t> first; // per candidate + 1: its entries in other / t
  std::vector<std::uint32_t> other;
  std::vector<float> t; // distance / local radius scale
};

CloseEarlier
closeEarlier(const std::vector<Eigen::Vector3d>& pos,
             const std::vector<double>& scale,
             double cutoff,
             const Together& together)
{
  // scale <= 1, so every pair that matters lies in neighbouring cells of size cutoff.
  const PointGrid grid(pos, cutoff);
  std::vector<int> index(pos.size());
  std::vector<double> sorted_scale(pos.size());
  for (std::size_t a = 0; a < pos.size(); ++a) {
    index[a] = grid.originalIndex(static_cast<int>(a));
    sorted_scale[a] = scale[index[a]];
  }
  struct Pair {
    std::uint32_t later, earlier;
    float t;
  };
  std::vector<Pair> pairs;
  pairs.reserve(10 * pos.size());
  const double cutoff2 = cutoff * cutoff;
  const auto consider = [&](int a, int b) {
    const double d2 = sq3(grid.sortedPoint(b) - grid.sortedPoint(a));
    if (d2 >= cutoff2)
      return;
    const double h = 0.5 * (sorted_scale[a] + sorted_scale[b]);
    if (d2 < cutoff2 * h * h) {
      const auto i = static_cast<std::uint32_t>(index[a]);
      const auto j = static_cast<std::uint32_t>(index[b]);
      if (together && !together(i, j))
        return;
      pairs.push_back(
          {std::max(i, j), std::min(i, j), static_cast<float>(std::sqrt(d2) / h)});
    }
  };
  // Each unordered pair once: within the cell, then the 13 neighbours that come
  // after it in lexicographic offset order.
  for (std::size_t c = 0; c < grid.cellCount(); ++c) {
    const auto own = grid.cellRange(c);
    for (int a = own.first; a < own.second; ++a)
      for (int b = a + 1; b < own.second; ++b)
        consider(a, b);
    for (int di = 0; di <= 1; ++di)
      for (int dj = (di ? -1 : 0); dj <= 1; ++dj)
        for (int dk = (di || dj ? -1 : 1); dk <= 1; ++dk) {
          const auto other = grid.neighbourRange(c, di, dj, dk);
          for (int a = own.first; a < own.second; ++a)
            for (int b = other.first; b < other.second; ++b)
              consider(a, b);
        }
  }
  // Counting sort by the later candidate.
  CloseEarlier close;
  close.first.assign(pos.size() + 1, 0);
  for (const Pair& p : pairs)
    ++close.first[p.later + 1];
  for (std::size_t i = 0; i < pos.size(); ++i)
    close.first[i + 1] += close.first[i];
  std::vector<std::uint32_t> fill(close.first.begin(), close.first.end() - 1);
  close.other.resize(pairs.size());
  close.t.resize(pairs.size());
  for (const Pair& p : pairs) {
    const std::uint32_t e = fill[p.later]++;
    close.other[e] = p.earlier;
    close.t[e] = p.t;
  }
  return close;
}

/** Greedy dart throwing over the candidates in their (random) order at radius r. */
std::size_t
acceptAt(const CloseEarlier& close, double r, std::vector<char>& accepted)
{
  const float rf = static_cast<float>(r);
  std::size_t count = 0;
  for (std::size_t i = 0; i + 1 < close.first.size(); ++i) {
    bool ok = true;
    for (std::uint32_t e = close.first[i]; e < close.first[i + 1]; ++e)
      if (close.t[e] < rf && accepted[close.other[e]]) {
        ok = false;
        break;
      }
    accepted[i] = ok;
    count += ok;
  }
  return count;
}

/** Poisson-disk sites: 8x area-uniform candidates (already thinned to the density),
 *  greedy elimination at a radius r / sqrt (density), r tuned to hit o.n. */
std::vector<Site>
poissonSites(const std::vector<Part>& parts,
             const SampleOptions& o,
             Rng& rng,
             const std::function<bool(const Site&, const Site&)>& together = {})
{
  const std::size_t n = o.n;
  const std::size_t m = 8 * n;
  SiteSource source(parts, o.density_ratio);
  std::vector<Site> candidates;
  candidates.reserve(m);
  std::vector<Eigen::Vector3d> pos(m);
  std::vector<double> scale(m);
  for (std::size_t i = 0; i < m; ++i) {
    candidates.push_back(source.draw(rng));
    pos[i] = candidates[i].p;
    scale[i] = 1.0 / std::sqrt(source.density(candidates[i]));
  }
  // Random sequential packing at 8x oversampling keeps about 0.55 A / r^2 points; a
  // varying radius r / sqrt (d) replaces A by the integral of d.
  const double r_est =
      std::sqrt(0.55 * source.area() * source.meanDensity() / double(n));
  const long tolerance = std::max(1L, std::lround(0.005 * double(n)));
  const long target = static_cast<long>(n);
  Together pair_ok;
  if (together)
    pair_ok = [&](std::uint32_t i, std::uint32_t j) {
      return together(candidates[i], candidates[j]);
    };

  std::vector<char> accepted(m), best_accepted;
  long best_miss = std::numeric_limits<long>::max();
  double cutoff = 1.15 * r_est;
  for (int attempt = 0; attempt < 6 && best_miss > tolerance; ++attempt) {
    const CloseEarlier close = closeEarlier(pos, scale, cutoff, pair_ok);
    // Count(r) falls roughly like r^-2: secant steps in that model, kept inside the
    // bracket [lo, hi] (count(lo) > n > count(hi)), else bisection.
    double lo = 0.0, hi = cutoff;
    double r = std::min(r_est, 0.99 * cutoff);
    bool hi_valid = false;
    for (int pass = 0; pass < 40; ++pass) {
      const long count = static_cast<long>(acceptAt(close, r, accepted));
      const long miss = std::abs(count - target);
      if (miss < best_miss) {
        best_miss = miss;
        best_accepted = accepted;
      }
      if (miss <= tolerance)
        break;
      if (count > target)
        lo = r;
      else {
        hi = r;
        hi_valid = true;
      }
      const double model = r * std::sqrt(double(count) / double(target));
      if (!hi_valid && count > target) // the model may overshoot: probe the cut-off
        r = std::min(model, 0.5 * (r + cutoff));
      else
        r = (model > lo && model < hi) ? model : 0.5 * (lo + hi);
    }
    if (!hi_valid)
      cutoff *= 1.5; // even the cut-off radius leaves too many points
  }

  std::vector<Site> sites;
  for (std::size_t i = 0; i < m; ++i)
    if (best_accepted[i])
      sites.push_back(candidates[i]);
  return sites;
}

// ---------------------------------------------------------------------------------
// Ground truth helpers

/** Points at equal arc-length steps <= max_step along a piece, its end excluded. */
void
samplePiece(const CurvePiece& piece, double max_step, std::vector<Eigen::Vector3d>& out)
{
  const int table = 4096;
  std::vector<double> s(table + 1, 0.0);
  Eigen::Vector3d prev = piece.at(piece.t0);
  for (int k = 1; k <= table; ++k) {
    const Eigen::Vector3d p = piece.at(piece.t0 + (piece.t1 - piece.t0) * k / table);
    s[k] = s[k - 1] + std::sqrt(sq3(p - prev));
    prev = p;
  }
  const double length = s[table];
  // The margin absorbs the table's chord error, so that steps stay <= max_step.
  const long steps =
      std::max(1L, static_cast<long>(std::ceil(length / (0.98 * max_step))));
  for (long j = 0; j < steps; ++j) {
    const double target = length * double(j) / double(steps);
    const long k = std::min<long>(
        table - 1, std::upper_bound(s.begin(), s.end(), target) - s.begin() - 1);
    const double span = s[k + 1] - s[k];
    const double f = span > 0.0 ? (target - s[k]) / span : 0.0;
    out.push_back(piece.at(piece.t0 + (piece.t1 - piece.t0) * (k + f) / table));
  }
}

double
segmentDistance(const Eigen::Vector3d& q,
                const Eigen::Vector3d& a,
                const Eigen::Vector3d& b)
{
  const Eigen::Vector3d ab = b - a;
  const double l2 = sq3(ab);
  const double t = l2 > 0.0 ? std::max(0.0, std::min(1.0, dot3(q - a, ab) / l2)) : 0.0;
  return std::sqrt(sq3(a + t * ab - q));
}

double
meanNearestDistance(const std::vector<Eigen::Vector3d>& points, double cell)
{
  const PointGrid grid(points, cell);
  double sum = 0.0;
  std::size_t counted = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    double d = 0.0;
    if (grid.nearest(points[i], 64.0 * cell, static_cast<int>(i), d) >= 0) {
      sum += d;
      ++counted;
    }
  }
  return counted ? sum / double(counted) : 0.0;
}

/** Fills everything but the points from the sites and parts; adds the noise last, so
 *  that the ground truth refers to the noise-free sites. spacing <= 0: measure it. */
Sample
assemble(const std::string& name,
         const std::vector<Part>& parts,
         const std::vector<Site>& sites,
         double spacing,
         const SampleOptions& o,
         Rng& rng)
{
  Sample s;
  s.name = name;
  s.outlier.assign(sites.size(), false);
  for (const Site& site : sites) {
    s.points.push_back(site.p);
    s.normals.push_back(site.n);
    s.component.push_back(site.component);
  }
  s.euler = 0;
  for (const Part& part : parts) {
    s.area += part.area;
    s.euler += part.euler;
  }
  s.spacing =
      spacing > 0.0
          ? spacing
          : meanNearestDistance(s.points, std::sqrt(s.area / double(sites.size())));

  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments;
  for (const Part& part : parts)
    for (const Loop& loop : part.loops) {
      std::vector<Eigen::Vector3d> curve;
      for (const CurvePiece& piece : loop)
        samplePiece(piece, 0.25 * s.spacing, curve);
      for (std::size_t k = 0; k < curve.size(); ++k) {
        segments.emplace_back(curve[k], curve[(k + 1) % curve.size()]);
        s.boundary_curve.push_back(curve[k]);
        s.boundary_curve_loop.push_back(s.boundary_loops);
      }
      ++s.boundary_loops;
    }
  s.components = static_cast<int>(parts.size());
  s.closed = s.boundary_loops == 0;

  s.near_boundary.assign(sites.size(), false);
  if (!segments.empty()) {
    std::vector<Eigen::Vector3d> mids;
    double half = 0.0;
    for (const auto& seg : segments) {
      mids.push_back(0.5 * (seg.first + seg.second));
      half = std::max(half, 0.5 * std::sqrt(sq3(seg.second - seg.first)));
    }
    const PointGrid grid(mids, s.spacing);
    for (std::size_t i = 0; i < sites.size(); ++i) {
      bool near = false;
      grid.forEachWithin(sites[i].p, s.spacing + half, [&](int k, double) {
        near =
            near || segmentDistance(sites[i].p, segments[k].first, segments[k].second) <
                        s.spacing;
      });
      s.near_boundary[i] = near;
    }
  }

  if (parts.size() == 1)
    s.distance = parts.front().distance;
  else {
    std::vector<Distance> each;
    for (const Part& part : parts)
      each.push_back(part.distance);
    s.distance = [each](const Eigen::Vector3d& q) {
      double d = std::numeric_limits<double>::infinity();
      for (const auto& f : each)
        d = std::min(d, f(q));
      return d;
    };
  }

  if (o.noise > 0.0)
    for (std::size_t i = 0; i < s.points.size(); ++i)
      s.points[i] += (rng.normal() * o.noise * s.spacing) * s.normals[i];
  return s;
}

Sample
generate(const std::string& name,
         const std::vector<Part>& parts,
         const SampleOptions& o)
{
  checkOptions(o);
  Rng rng(o.seed);
  const std::vector<Site> sites =
      o.even ? poissonSites(parts, o, rng) : randomSites(parts, o, rng);
  return assemble(name, parts, sites, 0.0, o, rng);
}

void
requirePositive(double v, const char* what)
{
  if (!(v > 0.0) || !std::isfinite(v))
    throw std::invalid_argument(std::string("cocone_test: ") + what + " must be > 0");
}

// ---------------------------------------------------------------------------------
// Parts

Part
spherePart(double radius)
{
  requirePositive(radius, "radius");
  Part part;
  part.area = 4.0 * kPi * radius * radius;
  part.x_lo = -radius;
  part.x_hi = radius;
  part.draw = [radius](Rng& rng) {
    Site s;
    s.n = rng.unitVector();
    s.p = radius * s.n;
    return s;
  };
  part.distance = [radius](const Eigen::Vector3d& q) {
    return std::abs(q.norm() - radius);
  };
  part.euler = 2;
  return part;
}

Part
hemispherePart(double radius)
{
  requirePositive(radius, "radius");
  Part part;
  part.area = 2.0 * kPi * radius * radius;
  part.x_lo = -radius;
  part.x_hi = radius;
  part.draw = [radius](Rng& rng) {
    Site s;
    s.n = rng.unitVector();
    s.n.z() = std::abs(s.n.z());
    s.p = radius * s.n;
    return s;
  };
  part.distance = [radius](const Eigen::Vector3d& q) {
    // Below the equator plane the nearest point is on the rim.
    if (q.z() >= 0.0)
      return std::abs(q.norm() - radius);
    return std::hypot(q.head<2>().norm() - radius, q.z());
  };
  part.loops.push_back(circleLoop(Eigen::Vector3d::Zero(),
                                  Eigen::Vector3d::UnitX(),
                                  Eigen::Vector3d::UnitY(),
                                  radius));
  part.euler = 1;
  return part;
}

Part
cylinderPart(double radius, double height)
{
  requirePositive(radius, "radius");
  requirePositive(height, "height");
  const double half = 0.5 * height;
  Part part;
  part.area = 2.0 * kPi * radius * height;
  part.x_lo = -radius;
  part.x_hi = radius;
  part.draw = [radius, half](Rng& rng) {
    const Eigen::Vector2d c = rng.unitCircle();
    Site s;
    s.n = Eigen::Vector3d(c.x(), c.y(), 0.0);
    s.p = Eigen::Vector3d(radius * c.x(), radius * c.y(), rng.uniform(-half, half));
    return s;
  };
  part.distance = [radius, half](const Eigen::Vector3d& q) {
    return std::hypot(q.head<2>().norm() - radius,
                      std::max(0.0, std::abs(q.z()) - half));
  };
  for (const double z : {-half, half})
    part.loops.push_back(circleLoop(Eigen::Vector3d(0, 0, z),
                                    Eigen::Vector3d::UnitX(),
                                    Eigen::Vector3d::UnitY(),
                                    radius));
  part.euler = 0;
  return part;
}

/** z = f (x, y) over [x0, x1] x [y0, y1]. */
struct HeightField {
  double (*f)(double, double);
  Eigen::Vector2d (*gradient)(double, double);
  Eigen::Vector3d (*hessian)(double, double); // f_xx, f_xy, f_yy
  double x0, x1, y0, y1;

  Eigen::Vector3d
  point(const Eigen::Vector2d& u) const
  {
    return {u.x(), u.y(), f(u.x(), u.y())};
  }

  Eigen::Vector3d
  normal(const Eigen::Vector2d& u) const
  {
    const Eigen::Vector2d g = gradient(u.x(), u.y());
    return Eigen::Vector3d(-g.x(), -g.y(), 1.0) / std::sqrt(1.0 + sq2(g));
  }

  Eigen::Vector2d
  clamp(const Eigen::Vector2d& u) const
  {
    return {std::max(x0, std::min(x1, u.x())), std::max(y0, std::min(y1, u.y()))};
  }
};

/** Exact distance to a height field over its rectangle: box-constrained Newton
 *  projection, started at the nearest point of a dense sample built on first use. */
class HeightFieldDistance {
public:
  explicit HeightFieldDistance(const HeightField& hf) : hf_(hf) {}

  double
  operator()(const Eigen::Vector3d& q) const
  {
    std::call_once(once_, [this] { build(); });
    // Far from the surface (other components, junk) the ring search would visit
    // many empty cells; the vertical projection is a good enough start there.
    const double reach = 8.0 * cell_;
    double d = 0.0;
    const bool near = box_.exteriorDistance(q) < reach;
    const int k = near ? grid_->nearest(q, reach, -1, d) : -1;
    Eigen::Vector2d u = k >= 0 ? params_[k] : hf_.clamp(q.head<2>());
    const auto energy = [&](const Eigen::Vector2d& v) {
      return 0.5 * (hf_.point(v) - q).squaredNorm();
    };
    for (int it = 0; it < 50; ++it) {
      const Eigen::Vector3d r = hf_.point(u) - q;
      const Eigen::Vector2d g = hf_.gradient(u.x(), u.y());
      const Eigen::Vector2d grad(r.x() + g.x() * r.z(), r.y() + g.y() * r.z());
      Eigen::Matrix2d h;
      h << 1.0 + g.x() * g.x(), g.x() * g.y(), g.x() * g.y(), 1.0 + g.y() * g.y();
      const Eigen::Vector3d second = hf_.hessian(u.x(), u.y());
      Eigen::Matrix2d full = h;
      full(0, 0) += r.z() * second[0];
      full(0, 1) += r.z() * second[1];
      full(1, 0) += r.z() * second[1];
      full(1, 1) += r.z() * second[2];
      if (full(0, 0) > 0.0 && full.determinant() > 0.0)
        h = full; // Newton where it is safe, Gauss-Newton elsewhere
      // Active set: a coordinate on its bound whose gradient pushes outwards stays.
      const bool free_x =
          !((u.x() <= hf_.x0 && grad.x() > 0.0) || (u.x() >= hf_.x1 && grad.x() < 0.0));
      const bool free_y =
          !((u.y() <= hf_.y0 && grad.y() > 0.0) || (u.y() >= hf_.y1 && grad.y() < 0.0));
      Eigen::Vector2d newton(0.0, 0.0), descent(0.0, 0.0);
      if (free_x && free_y)
        newton = -h.inverse() * grad;
      else if (free_x)
        newton.x() = -grad.x() / h(0, 0);
      else if (free_y)
        newton.y() = -grad.y() / h(1, 1);
      else
        break;
      // A clamped Newton step need not descend; a short gradient step always does.
      descent.x() = free_x ? -grad.x() / h.trace() : 0.0;
      descent.y() = free_y ? -grad.y() / h.trace() : 0.0;
      const double e0 = 0.5 * r.squaredNorm();
      bool moved = false;
      Eigen::Vector2d next = u;
      for (const Eigen::Vector2d& dir : {newton, descent}) {
        Eigen::Vector2d step = dir;
        for (int b = 0; b < 40 && !moved; ++b, step *= 0.5) {
          next = hf_.clamp(u + step);
          moved = energy(next) < e0;
        }
        if (moved)
          break;
      }
      if (!moved)
        break;
      const double change = (next - u).lpNorm<Eigen::Infinity>();
      u = next;
      if (change < 1e-14)
        break;
    }
    return std::sqrt(2.0 * energy(u));
  }

private:
  void
  build() const
  {
    const int steps = 256;
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < steps; ++i)
      for (int j = 0; j < steps; ++j) {
        const Eigen::Vector2d u(hf_.x0 + (hf_.x1 - hf_.x0) * i / (steps - 1),
                                hf_.y0 + (hf_.y1 - hf_.y0) * j / (steps - 1));
        params_.push_back(u);
        points.push_back(hf_.point(u));
        box_.extend(points.back());
      }
    cell_ = 2.0 * std::max(hf_.x1 - hf_.x0, hf_.y1 - hf_.y0) / (steps - 1);
    grid_ = std::make_unique<PointGrid>(points, cell_);
  }

  HeightField hf_;
  mutable std::once_flag once_;
  mutable std::vector<Eigen::Vector2d> params_;
  mutable std::unique_ptr<PointGrid> grid_;
  mutable double cell_ = 0.0;
  mutable Eigen::AlignedBox3d box_;
};

double
slopeFactor(const HeightField& hf, double x, double y)
{
  return std::sqrt(1.0 + sq2(hf.gradient(x, y)));
}

/** Rectangle edges lifted onto the surface, counter-clockwise seen from +z. */
Loop
heightFieldRim(const HeightField& hf)
{
  const auto edge = [hf](Eigen::Vector2d a, Eigen::Vector2d b) {
    CurvePiece piece;
    piece.at = [hf, a, b](double t) { return hf.point(a + t * (b - a)); };
    piece.t0 = 0.0;
    piece.t1 = 1.0;
    return piece;
  };
  const Eigen::Vector2d c00(hf.x0, hf.y0), c10(hf.x1, hf.y0), c11(hf.x1, hf.y1),
      c01(hf.x0, hf.y1);
  return {edge(c00, c10), edge(c10, c11), edge(c11, c01), edge(c01, c00)};
}

Part
heightFieldPart(const HeightField& hf)
{
  Part part;
  // Midpoint rule; both fields used here are polynomials, 512^2 cells is plenty.
  const int cells = 512;
  const double dx = (hf.x1 - hf.x0) / cells, dy = (hf.y1 - hf.y0) / cells;
  double sum = 0.0, w_max = 0.0;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j)
      sum += slopeFactor(hf, hf.x0 + (i + 0.5) * dx, hf.y0 + (j + 0.5) * dy);
  part.area = sum * dx * dy;
  // The rejection bound: |grad f|^2 is convex for these fields, so the corners
  // (on the grid) hold the maximum; the margin only costs a few rejections.
  for (int i = 0; i <= 64; ++i)
    for (int j = 0; j <= 64; ++j)
      w_max = std::max(w_max,
                       slopeFactor(hf,
                                   hf.x0 + (hf.x1 - hf.x0) * i / 64.0,
                                   hf.y0 + (hf.y1 - hf.y0) * j / 64.0));
  w_max *= 1.02;
  part.x_lo = hf.x0;
  part.x_hi = hf.x1;
  part.draw = [hf, w_max](Rng& rng) {
    for (;;) {
      const double x = rng.uniform(hf.x0, hf.x1);
      const Eigen::Vector2d u(x, rng.uniform(hf.y0, hf.y1));
      if (rng.uniform01() * w_max < slopeFactor(hf, u.x(), u.y())) {
        Site s;
        s.p = hf.point(u);
        s.n = hf.normal(u);
        return s;
      }
    }
  };
  const auto projector = std::make_shared<HeightFieldDistance>(hf);
  part.distance = [projector](const Eigen::Vector3d& q) { return (*projector)(q); };
  part.loops.push_back(heightFieldRim(hf));
  part.euler = 1;
  return part;
}

HeightField
sheetField()
{
  HeightField hf;
  hf.f = [](double x, double y) { return 0.15 * (x * x - 0.5 * y * y); };
  hf.gradient = [](double x, double y) { return Eigen::Vector2d(0.3 * x, -0.15 * y); };
  hf.hessian = [](double, double) { return Eigen::Vector3d(0.3, 0.0, -0.15); };
  hf.x0 = -1.0;
  hf.x1 = 1.0;
  hf.y0 = -0.7;
  hf.y1 = 0.7;
  return hf;
}

HeightField
monkeyField()
{
  HeightField hf;
  hf.f = [](double x, double y) { return x * x * x - 3.0 * x * y * y; };
  hf.gradient = [](double x, double y) {
    return Eigen::Vector2d(3.0 * x * x - 3.0 * y * y, -6.0 * x * y);
  };
  hf.hessian = [](double x, double y) {
    return Eigen::Vector3d(6.0 * x, -6.0 * y, -6.0 * x);
  };
  hf.x0 = -1.0;
  hf.x1 = 1.0;
  hf.y0 = -1.0;
  hf.y1 = 1.0;
  return hf;
}

/** Unit vector u with ordered tangents e1, e2 completing a right-handed frame. */
void
frame(const Eigen::Vector3d& u, Eigen::Vector3d& e1, Eigen::Vector3d& e2)
{
  const Eigen::Vector3d helper =
      std::abs(u.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  e1 = unit3(helper.cross(u));
  e2 = u.cross(e1);
}

/** Monotone table of a cumulative integral, inverted by linear interpolation. */
struct CumulativeTable {
  std::vector<double> x, s;

  template <typename F>
  CumulativeTable(double x0, double x1, int steps, F&& density)
  {
    x.resize(steps + 1);
    s.assign(steps + 1, 0.0);
    for (int k = 0; k <= steps; ++k)
      x[k] = x0 + (x1 - x0) * k / steps;
    for (int k = 1; k <= steps; ++k)
      s[k] = s[k - 1] + (x[k] - x[k - 1]) * density(0.5 * (x[k] + x[k - 1]));
  }

  double
  total() const
  {
    return s.back();
  }

  double
  inverse(double target) const
  {
    if (target <= 0.0)
      return x.front();
    if (target >= s.back())
      return x.back();
    const std::size_t k = std::upper_bound(s.begin(), s.end(), target) - s.begin() - 1;
    return x[k] + (x[k + 1] - x[k]) * (target - s[k]) / (s[k + 1] - s[k]);
  }
};

/** Mean nearest-neighbour distance within groups of sites (key (site) >= 0: its
 *  group; < 0: left out), over all sites in a group. */
template <typename Key>
double
meanNearestDistanceWithin(const std::vector<Site>& sites, Key&& key, double cell)
{
  std::vector<std::vector<Eigen::Vector3d>> groups;
  for (const Site& site : sites) {
    const int k = key(site);
    if (k < 0)
      continue;
    if (static_cast<std::size_t>(k) >= groups.size())
      groups.resize(k + 1);
    groups[k].push_back(site.p);
  }
  double sum = 0.0;
  std::size_t count = 0;
  for (const auto& group : groups) {
    sum += meanNearestDistance(group, cell) * double(group.size());
    count += group.size();
  }
  return count ? sum / double(count) : 0.0;
}

/** One counter-clockwise piece of a planar domain's boundary: the segment from a to
 *  b, or (radius > 0) the arc about a from angle phi0 over sweep, convex (sign +1:
 *  the domain inside the circle) or concave (-1: a hole's rim). */
struct Rim {
  Eigen::Vector2d a, b;
  double radius = 0.0, phi0 = 0.0, sweep = 0.0, sign = 1.0;
};

Rim
segmentRim(double ax, double ay, double bx, double by)
{
  Rim rim;
  rim.a = Eigen::Vector2d(ax, ay);
  rim.b = Eigen::Vector2d(bx, by);
  return rim;
}

Rim
arcRim(double cx, double cy, double radius, double phi0, double sweep, double sign)
{
  Rim rim;
  rim.a = Eigen::Vector2d(cx, cy);
  rim.radius = radius;
  rim.phi0 = phi0;
  rim.sweep = sweep;
  rim.sign = sign;
  return rim;
}

/** The points at distance r from a planar domain D in z = 0 (r below the radius of
 *  every concave rim): D's copies at z = +-r (normals +-z) joined by half tubes
 *  around D's boundary. outside (p): the distance from p to D, exactly 0 in D. On
 *  a rim piece of length L and curvature k the half tube's area element is
 *  r (1 + k r cos theta) dtheta ds, theta in [-pi/2, pi/2]. */
Part
slabPart(const std::function<double(const Eigen::Vector2d&)>& outside,
         double domain_area,
         const Eigen::Vector2d& lo,
         const Eigen::Vector2d& hi,
         const std::vector<Rim>& rims,
         double r,
         int euler)
{
  std::vector<double> cumulative{domain_area, 2.0 * domain_area};
  for (const Rim& rim : rims) {
    const double area = rim.radius > 0.0
                            ? r * (kPi * rim.radius * std::abs(rim.sweep) +
                                   2.0 * rim.sign * r * std::abs(rim.sweep))
                            : kPi * r * std::sqrt(sq2(rim.b - rim.a));
    cumulative.push_back(cumulative.back() + area);
  }
  Part part;
  part.area = cumulative.back();
  part.x_lo = lo.x() - r;
  part.x_hi = hi.x() + r;
  part.draw = [=](Rng& rng) {
    const double u = rng.uniform01() * cumulative.back();
    const std::size_t k = std::min<std::size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin(),
        cumulative.size() - 1);
    Site s;
    if (k < 2) {
      const double side = k == 0 ? 1.0 : -1.0;
      for (;;) {
        const double x = rng.uniform(lo.x(), hi.x());
        const Eigen::Vector2d q(x, rng.uniform(lo.y(), hi.y()));
        if (outside(q) == 0.0) {
          s.p = Eigen::Vector3d(q.x(), q.y(), side * r);
          s.n = Eigen::Vector3d(0.0, 0.0, side);
          return s;
        }
      }
    }
    const Rim& rim = rims[k - 2];
    // Accepted with probability (1 + k r cos theta) / (1 + max (k, 0) r).
    const double bound =
        1.0 + (rim.radius > 0.0 ? std::max(0.0, rim.sign) * r / rim.radius : 0.0);
    for (;;) {
      const double t = rng.uniform01();
      const Eigen::Vector2d c = rng.unitCircle(); // theta uniform in [-pi/2, pi/2]
      const double cos_t = std::abs(c.x()), sin_t = c.y();
      const double weight =
          rim.radius > 0.0 ? 1.0 + rim.sign * r * cos_t / rim.radius : 1.0;
      if (!(rng.uniform01() * bound < weight))
        continue;
      // The boundary point b and D's outward normal m there.
      Eigen::Vector2d b, m;
      if (rim.radius > 0.0) {
        const Eigen::Vector2d cs = portableCosSin(rim.phi0 + rim.sweep * t);
        b = rim.a + rim.radius * cs;
        m = rim.sign * cs;
      }
      else {
        const Eigen::Vector2d d = rim.b - rim.a;
        b = rim.a + t * d;
        m = Eigen::Vector2d(d.y(), -d.x()) / std::sqrt(sq2(d));
      }
      s.n = Eigen::Vector3d(cos_t * m.x(), cos_t * m.y(), sin_t);
      s.p = Eigen::Vector3d(b.x(), b.y(), 0.0) + r * s.n;
      return s;
    }
  };
  part.distance = [outside, r](const Eigen::Vector3d& q) {
    return std::abs(std::hypot(outside(q.head<2>()), q.z()) - r);
  };
  part.euler = euler;
  return part;
}

/** The trefoil (sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t) and its first two
 *  derivatives at (cos t, sin t) = cs, with the multiple angles by polynomials. */
struct CurvePoint {
  Eigen::Vector3d p, d1, d2;
};

CurvePoint
trefoil(const Eigen::Vector2d& cs)
{
  const double c = cs.x(), s = cs.y();
  const double c2 = c * c - s * s, s2 = 2.0 * s * c;
  const double c3 = c * c2 - s * s2, s3 = s * c2 + c * s2;
  return {Eigen::Vector3d(s + 2.0 * s2, c - 2.0 * c2, -s3),
          Eigen::Vector3d(c + 4.0 * c2, -s + 4.0 * s2, -3.0 * c3),
          Eigen::Vector3d(-s - 8.0 * s2, -c + 8.0 * c2, 9.0 * s3)};
}

/** Distance to the trefoil: the nearest of a table of curve points, refined by
 *  Newton steps on (gamma (t) - q) . gamma' (t) = 0 within a table step. */
class TrefoilDistance {
public:
  TrefoilDistance()
  {
    for (int k = 0; k < kTable; ++k)
      table_.push_back(trefoil(portableCosSin(2.0 * kPi * k / kTable)).p);
  }

  double
  operator()(const Eigen::Vector3d& q) const
  {
    int best = 0;
    double best2 = std::numeric_limits<double>::infinity();
    for (int k = 0; k < kTable; ++k) {
      const double d2 = sq3(table_[k] - q);
      if (d2 < best2) {
        best2 = d2;
        best = k;
      }
    }
    const double h = 2.0 * kPi / kTable, t0 = best * h;
    double t = t0;
    for (int it = 0; it < 30; ++it) {
      const CurvePoint c = trefoil(portableCosSin(t));
      const Eigen::Vector3d r = c.p - q;
      const double g = dot3(r, c.d1), dg = sq3(c.d1) + dot3(r, c.d2);
      if (!(dg > 0.0))
        break;
      const double next = std::max(t0 - h, std::min(t0 + h, t - g / dg));
      if (next == t)
        break;
      t = next;
    }
    return std::sqrt(std::min(best2, sq3(trefoil(portableCosSin(t)).p - q)));
  }

private:
  static constexpr int kTable = 2048;
  std::vector<Eigen::Vector3d> table_;
};

/** Indices 0 .. n - 1 in a random order's first `count` places (partial
 *  Fisher-Yates). */
std::vector<std::size_t>
randomSubset(std::size_t n, std::size_t count, Rng& rng)
{
  std::vector<std::size_t> index(n);
  for (std::size_t i = 0; i < n; ++i)
    index[i] = i;
  for (std::size_t i = 0; i < count; ++i) {
    const auto j =
        std::min(n - 1, i + static_cast<std::size_t>(rng.uniform01() * double(n - i)));
    std::swap(index[i], index[j]);
  }
  index.resize(count);
  return index;
}

/** Bounding box corner by corner, in a fixed order. */
void
boundingBox(const std::vector<Eigen::Vector3d>& points,
            Eigen::Vector3d& lo,
            Eigen::Vector3d& hi)
{
  lo = hi = points.front();
  for (const Eigen::Vector3d& p : points)
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], p[i]);
      hi[i] = std::max(hi[i], p[i]);
    }
}

} // namespace

// ---------------------------------------------------------------------------------
// Generators

Sample
sphere(const SampleOptions& o, double radius)
{
  return generate("sphere", {spherePart(radius)}, o);
}

Sample
ellipsoid(const SampleOptions& o, double a, double b, double c)
{
  requirePositive(a, "a");
  requirePositive(b, "b");
  requirePositive(c, "c");
  const Eigen::Vector3d axes(a, b, c);
  // The map u -> (a ux, b uy, c uz) from the unit sphere scales area by g (u); area
  // uniform sites: sphere-uniform u accepted with probability g / g_max.
  const auto g = [a, b, c](const Eigen::Vector3d& u) {
    const Eigen::Vector3d v(b * c * u.x(), a * c * u.y(), a * b * u.z());
    return std::sqrt(sq3(v));
  };
  const double g_max = std::max({b * c, a * c, a * b});
  Part part;
  // Area = integral of g over the sphere, dOmega = dz dphi. g is even in every
  // coordinate, so one quadrant in phi suffices; phi = 2 atan t (cos, sin rational
  // in t, dphi = 2 dt / (1 + t^2)) avoids libm. Midpoint rule in z and t.
  const int nz = 512, nt = 256;
  double sum = 0.0;
  for (int i = 0; i < nz; ++i) {
    const double z = -1.0 + (i + 0.5) * 2.0 / nz;
    const double rho = std::sqrt(1.0 - z * z);
    for (int j = 0; j < nt; ++j) {
      const double t = (j + 0.5) / nt, w = 1.0 + t * t;
      sum +=
          2.0 / w * g(Eigen::Vector3d(rho * (1.0 - t * t) / w, rho * 2.0 * t / w, z));
    }
  }
  part.area = 4.0 * sum * (2.0 / nz) / nt;
  part.x_lo = -a;
  part.x_hi = a;
  part.draw = [axes, g, g_max](Rng& rng) {
    for (;;) {
      const Eigen::Vector3d u = rng.unitVector();
      if (rng.uniform01() * g_max < g(u)) {
        Site s;
        s.p = axes.cwiseProduct(u);
        s.n = unit3(s.p.cwiseQuotient(axes.cwiseProduct(axes)));
        return s;
      }
    }
  };
  part.distance = [axes](const Eigen::Vector3d& q) {
    // Nearest point x_i = a_i^2 y_i / (t + a_i^2), t the root of
    // F (t) = sum (a_i y_i / (t + a_i^2))^2 - 1, decreasing on (-min a_i^2, inf).
    // Bisect on e = t + min a_i^2 > 0: near e = 0 (points deep inside) t itself
    // would have too few significant digits.
    const Eigen::Vector3d a2 = axes.cwiseProduct(axes);
    const Eigen::Vector3d gap = a2 - Eigen::Vector3d::Constant(a2.minCoeff());
    Eigen::Vector3d y = q.cwiseAbs();
    // A zero coordinate along the shortest axis would leave F bounded near e = 0.
    for (int i = 0; i < 3; ++i)
      y[i] = std::max(y[i], 1e-12 * axes.maxCoeff());
    double lo = 0.0, hi = a2.minCoeff() + axes.maxCoeff() * y.norm();
    for (int it = 0; it < 400; ++it) {
      const double e = 0.5 * (lo + hi);
      if (e <= lo || e >= hi)
        break;
      double f = -1.0;
      for (int i = 0; i < 3; ++i) {
        const double v = axes[i] * y[i] / (e + gap[i]);
        f += v * v;
      }
      (f > 0.0 ? lo : hi) = e;
    }
    const double e = 0.5 * (lo + hi);
    Eigen::Vector3d x;
    for (int i = 0; i < 3; ++i)
      x[i] = a2[i] * y[i] / (e + gap[i]);
    return (x - y).norm();
  };
  part.euler = 2;
  return generate("ellipsoid", {part}, o);
}

Sample
torus(const SampleOptions& o, double R, double r)
{
  requirePositive(r, "r");
  if (!(R > r) || !std::isfinite(R))
    throw std::invalid_argument("cocone_test: torus needs R > r");
  Part part;
  part.area = 4.0 * kPi * kPi * R * r;
  part.x_lo = -(R + r);
  part.x_hi = R + r;
  part.draw = [R, r](Rng& rng) {
    // The area element is proportional to R + r cos v.
    for (;;) {
      const Eigen::Vector2d cu = rng.unitCircle();
      const Eigen::Vector2d cv = rng.unitCircle();
      if (rng.uniform01() * (R + r) < R + r * cv.x()) {
        Site s;
        s.n = Eigen::Vector3d(cv.x() * cu.x(), cv.x() * cu.y(), cv.y());
        s.p = Eigen::Vector3d(R * cu.x(), R * cu.y(), 0.0) + r * s.n;
        return s;
      }
    }
  };
  part.distance = [R, r](const Eigen::Vector3d& q) {
    return std::abs(std::hypot(q.head<2>().norm() - R, q.z()) - r);
  };
  part.euler = 0;
  return generate("torus", {part}, o);
}

Sample
hemisphere(const SampleOptions& o, double radius)
{
  return generate("hemisphere", {hemispherePart(radius)}, o);
}

Sample
monkeySaddle(const SampleOptions& o)
{
  return generate("monkey_saddle", {heightFieldPart(monkeyField())}, o);
}

Sample
openCylinder(const SampleOptions& o, double radius, double height)
{
  return generate("open_cylinder", {cylinderPart(radius, height)}, o);
}

Sample
curvedSheet(const SampleOptions& o)
{
  return generate("curved_sheet", {heightFieldPart(sheetField())}, o);
}

Sample
scanLineSheet(const SampleOptions& o)
{
  checkOptions(o);
  const HeightField hf = sheetField();
  const std::vector<Part> parts{heightFieldPart(hf)};
  const double ratio = o.density_ratio;
  const auto density = [&](double y) {
    return densityAt((y - hf.y0) / (hf.y1 - hf.y0), ratio);
  };
  // Across the rows: arc length in y (the same for every x, as f_y does not depend
  // on x) divided by the local scale 1 / sqrt (density). Along a row: arc length in
  // x, the same for every row, as f_x does not depend on y.
  const CumulativeTable across(hf.y0, hf.y1, 4096, [&](double y) {
    const double fy = hf.gradient(0.0, y).y();
    return std::sqrt((1.0 + fy * fy) * density(y));
  });
  const CumulativeTable along(hf.x0, hf.x1, 4096, [&](double x) {
    const double fx = hf.gradient(x, 0.0).x();
    return std::sqrt(1.0 + fx * fx);
  });
  const double row_length = along.total();

  struct Row {
    double y;
    long steps;
  };
  const auto layout = [&](double s) {
    const long gaps = std::max(1L, std::lround(across.total() / (3.0 * s)));
    std::vector<Row> rows;
    for (long k = 0; k <= gaps; ++k) {
      const double y = across.inverse(across.total() * double(k) / double(gaps));
      const double step = s / std::sqrt(density(y));
      rows.push_back({y, std::max(1L, std::lround(row_length / step))});
    }
    return rows;
  };
  const auto count = [](const std::vector<Row>& rows) {
    long total = 0;
    for (const Row& row : rows)
      total += row.steps + 1;
    return total;
  };
  // Bisection on s; the count falls (in steps) as s grows.
  const long target = static_cast<long>(o.n);
  const double s0 =
      std::sqrt(parts[0].area * 0.5 * (1.0 + ratio) / (3.0 * double(o.n)));
  double lo = 0.2 * s0, hi = 5.0 * s0;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (count(layout(mid)) > target ? lo : hi) = mid;
  }
  const std::vector<Row> rows =
      std::abs(count(layout(lo)) - target) <= std::abs(count(layout(hi)) - target)
          ? layout(lo)
          : layout(hi);

  Rng rng(o.seed);
  std::vector<Site> sites;
  double step_sum = 0.0;
  for (const Row& row : rows) {
    const double step = row_length / double(row.steps);
    for (long j = 0; j <= row.steps; ++j) {
      // Tangential jitter in the parameters keeps the site exactly on the surface.
      Eigen::Vector2d u(along.inverse(step * double(j)), row.y);
      u.x() += rng.uniform(-0.05, 0.05) * step;
      u.y() += rng.uniform(-0.05, 0.05) * step;
      u = hf.clamp(u);
      Site site;
      site.p = hf.point(u);
      site.n = hf.normal(u);
      sites.push_back(site);
      step_sum += step;
    }
  }
  return assemble(
      "scan_line_sheet", parts, sites, step_sum / double(sites.size()), o, rng);
}

Sample
threeComponents(const SampleOptions& o)
{
  checkOptions(o);
  std::vector<Part> parts{
      hemispherePart(1.0), heightFieldPart(sheetField()), cylinderPart(0.5, 2.0)};
  double area = 0.0;
  for (const Part& part : parts)
    area += part.area;
  // sqrt (area / n) is about 1.2 spacings (even) or 2 spacings (random).
  const double gap = std::max(1.0, 30.0 * std::sqrt(area / double(o.n)));
  double x = parts.front().x_hi;
  for (std::size_t k = 1; k < parts.size(); ++k) {
    const double shift = x + gap - parts[k].x_lo;
    parts[k] = translated(parts[k], Eigen::Vector3d(shift, 0.0, 0.0));
    x = parts[k].x_hi;
  }
  return generate("three_components", parts, o);
}

Sample
sphereWithHoles(const SampleOptions& o, int holes, double hole_angle)
{
  if (holes < 0)
    throw std::invalid_argument("cocone_test: holes must be >= 0");
  if (holes > 0)
    requirePositive(hole_angle, "hole_angle");
  std::vector<Eigen::Vector3d> centres;
  const Eigen::Vector3d axes[6] = {Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d::UnitY(),
                                   Eigen::Vector3d::UnitZ(),
                                   -Eigen::Vector3d::UnitX(),
                                   -Eigen::Vector3d::UnitY(),
                                   -Eigen::Vector3d::UnitZ()};
  for (int k = 0; k < holes; ++k) {
    if (holes <= 6)
      centres.push_back(axes[k]);
    else {
      // Fibonacci lattice: nearly even directions for any count.
      const double z = 1.0 - (2.0 * k + 1.0) / holes;
      const double phi = k * kPi * (3.0 - std::sqrt(5.0));
      const double rho = std::sqrt(1.0 - z * z);
      const Eigen::Vector2d cs = portableCosSin(phi);
      centres.emplace_back(rho * cs.x(), rho * cs.y(), z);
    }
  }
  // Disjoint caps with a margin, so that every rim is a separate circle.
  for (int k = 0; k < holes; ++k)
    for (int l = 0; l < k; ++l)
      if (std::acos(std::max(-1.0, std::min(1.0, centres[k].dot(centres[l])))) <
          2.0 * hole_angle + 0.05)
        throw std::invalid_argument("cocone_test: sphereWithHoles caps would touch");
  if (hole_angle >= kPi / 2.0 && holes > 0)
    throw std::invalid_argument("cocone_test: hole_angle must be < pi/2");

  const Eigen::Vector2d cs = portableCosSin(hole_angle);
  const double cos_a = cs.x(), sin_a = cs.y();
  Part part;
  part.area = 4.0 * kPi - holes * 2.0 * kPi * (1.0 - cos_a);
  part.x_lo = -1.0;
  part.x_hi = 1.0;
  part.draw = [centres, cos_a](Rng& rng) {
    for (;;) {
      const Eigen::Vector3d u = rng.unitVector();
      bool in_cap = false;
      for (const auto& c : centres)
        in_cap = in_cap || dot3(u, c) > cos_a;
      if (!in_cap) {
        Site s;
        s.p = u;
        s.n = u;
        return s;
      }
    }
  };
  part.distance = [centres, cos_a, sin_a](const Eigen::Vector3d& q) {
    const double len = q.norm();
    if (len == 0.0)
      return 1.0;
    const Eigen::Vector3d dir = q / len;
    for (const auto& c : centres)
      if (dir.dot(c) > cos_a) {
        // Over a hole the nearest point is on its rim, towards q.
        Eigen::Vector3d w = dir - dir.dot(c) * c;
        if (w.norm() < 1e-12) {
          Eigen::Vector3d e2;
          frame(c, w, e2);
        }
        return (q - (cos_a * c + sin_a * w.normalized())).norm();
      }
    return std::abs(len - 1.0);
  };
  for (const auto& c : centres) {
    Eigen::Vector3d e1, e2;
    frame(c, e1, e2);
    part.loops.push_back(circleLoop(cos_a * c, e1, e2, sin_a));
  }
  part.euler = 2 - holes;
  return generate("sphere_with_holes", {part}, o);
}

Sample
genus2(const SampleOptions& o)
{
  // The stadium: the segment [-a, a] x {0} widened by ro; holes of radius rh about
  // (+-a, 0); r < rh keeps the holes open.
  const double a = 1.0, ro = 1.0, rh = 0.5, r = 0.3;
  const auto outside = [a, ro, rh](const Eigen::Vector2d& p) {
    for (const double cx : {-a, a}) {
      const double d = std::sqrt(sq2(p - Eigen::Vector2d(cx, 0.0)));
      if (d < rh)
        return rh - d;
    }
    const double x = std::max(0.0, std::abs(p.x()) - a);
    return std::max(0.0, std::sqrt(x * x + p.y() * p.y()) - ro);
  };
  const std::vector<Rim> rims{segmentRim(-a, -ro, a, -ro),
                              arcRim(a, 0.0, ro, -0.5 * kPi, kPi, 1.0),
                              segmentRim(a, ro, -a, ro),
                              arcRim(-a, 0.0, ro, 0.5 * kPi, kPi, 1.0),
                              arcRim(-a, 0.0, rh, 0.0, 2.0 * kPi, -1.0),
                              arcRim(a, 0.0, rh, 0.0, 2.0 * kPi, -1.0)};
  const double domain_area = kPi * ro * ro + 4.0 * a * ro - 2.0 * kPi * rh * rh;
  return generate("genus2",
                  {slabPart(outside,
                            domain_area,
                            Eigen::Vector2d(-a - ro, -ro),
                            Eigen::Vector2d(a + ro, ro),
                            rims,
                            r,
                            -2)},
                  o);
}

Sample
thinPlate(const SampleOptions& o, double thickness)
{
  checkOptions(o);
  requirePositive(thickness, "thickness");
  // The rectangle [-wx, wx] x [-wy, wy] with corners rounded by rc: the rectangle
  // [-ix, ix] x [-iy, iy] widened by rc.
  const double wx = 1.0, wy = 0.7, rc = 0.2, ix = wx - rc, iy = wy - rc;
  const auto outside = [ix, iy, rc](const Eigen::Vector2d& p) {
    const double x = std::max(0.0, std::abs(p.x()) - ix);
    const double y = std::max(0.0, std::abs(p.y()) - iy);
    return std::max(0.0, std::sqrt(x * x + y * y) - rc);
  };
  const std::vector<Rim> rims{segmentRim(-ix, -wy, ix, -wy),
                              arcRim(ix, -iy, rc, -0.5 * kPi, 0.5 * kPi, 1.0),
                              segmentRim(wx, -iy, wx, iy),
                              arcRim(ix, iy, rc, 0.0, 0.5 * kPi, 1.0),
                              segmentRim(ix, wy, -ix, wy),
                              arcRim(-ix, iy, rc, 0.5 * kPi, 0.5 * kPi, 1.0),
                              segmentRim(-wx, iy, -wx, -iy),
                              arcRim(-ix, -iy, rc, kPi, 0.5 * kPi, 1.0)};
  const std::vector<Part> parts{slabPart(outside,
                                         4.0 * wx * wy - (4.0 - kPi) * rc * rc,
                                         Eigen::Vector2d(-wx, -wy),
                                         Eigen::Vector2d(wx, wy),
                                         rims,
                                         0.5 * thickness,
                                         2)};
  Rng rng(o.seed);
  std::vector<Site> sites;
  if (o.even) {
    // Candidates on opposite sheets (normals more than 90 degrees apart) do not
    // exclude each other.
    sites = poissonSites(parts, o, rng, [](const Site& s, const Site& t) {
      return dot3(s.n, t.n) > 0.0;
    });
  }
  else
    sites = randomSites(parts, o, rng);
  const double spacing = meanNearestDistanceWithin(
      sites,
      [](const Site& site) { return site.n.z() > 0.0 ? 0 : 1; },
      std::sqrt(parts[0].area / double(sites.size())));
  return assemble("thin_plate", parts, sites, spacing, o, rng);
}

Sample
cube(const SampleOptions& o, double side)
{
  requirePositive(side, "side");
  const double h = 0.5 * side;
  Part part;
  part.area = 6.0 * side * side;
  part.x_lo = -h;
  part.x_hi = h;
  part.draw = [h](Rng& rng) {
    const int face = std::min(5, static_cast<int>(6.0 * rng.uniform01()));
    const int axis = face % 3;
    const double sign = face < 3 ? 1.0 : -1.0;
    Site s;
    s.p[axis] = sign * h;
    s.p[(axis + 1) % 3] = rng.uniform(-h, h);
    s.p[(axis + 2) % 3] = rng.uniform(-h, h);
    s.n = Eigen::Vector3d::Zero();
    s.n[axis] = sign;
    return s;
  };
  part.distance = [h](const Eigen::Vector3d& q) {
    const Eigen::Vector3d d = q.cwiseAbs() - Eigen::Vector3d::Constant(h);
    if (d.maxCoeff() > 0.0)
      return d.cwiseMax(0.0).norm();
    return -d.maxCoeff();
  };
  part.euler = 2;
  return generate("cube", {part}, o);
}

Sample
tube(const SampleOptions& o, double radius)
{
  requirePositive(radius, "radius");
  // The trefoil's curvature is at most 0.78 and distant strands are more than 1.2
  // apart: below 0.5 the tube does not touch itself.
  if (radius >= 0.5)
    throw std::invalid_argument("cocone_test: tube needs radius < 0.5");
  // |gamma'|^2 = 17 + 8 cos 3t + 9 cos^2 3t in [15.2, 34], |gamma''|^2 <= 162: the
  // area element |gamma'| (1 - radius kappa . u) is below the bound.
  const double bound = std::sqrt(34.0) * (1.0 + radius * std::sqrt(162.0) / 15.2);
  double length = 0.0; // midpoint rule: spectrally accurate for a periodic integrand
  const int steps = 4096;
  double x_lo = 0.0, x_hi = 0.0;
  for (int k = 0; k < steps; ++k) {
    const CurvePoint c = trefoil(portableCosSin(2.0 * kPi * (k + 0.5) / steps));
    length += std::sqrt(sq3(c.d1));
    x_lo = std::min(x_lo, c.p.x());
    x_hi = std::max(x_hi, c.p.x());
  }
  length *= 2.0 * kPi / steps;
  Part part;
  part.area = 2.0 * kPi * radius * length;
  part.x_lo = x_lo - radius;
  part.x_hi = x_hi + radius;
  part.draw = [radius, bound](Rng& rng) {
    for (;;) {
      const CurvePoint c = trefoil(rng.unitCircle());
      const double speed2 = sq3(c.d1);
      Eigen::Vector3d e1, e2;
      frame(c.d1 / std::sqrt(speed2), e1, e2);
      const Eigen::Vector2d v = rng.unitCircle();
      const Eigen::Vector3d u = v.x() * e1 + v.y() * e2;
      // kappa . u = gamma'' . u / |gamma'|^2 for u normal to gamma'.
      const double weight = std::sqrt(speed2) * (1.0 - radius * dot3(c.d2, u) / speed2);
      if (rng.uniform01() * bound < weight) {
        Site s;
        s.n = u;
        s.p = c.p + radius * u;
        return s;
      }
    }
  };
  const auto curve = std::make_shared<TrefoilDistance>();
  part.distance = [curve, radius](const Eigen::Vector3d& q) {
    return std::abs((*curve)(q)-radius);
  };
  part.euler = 0;
  return generate("tube", {part}, o);
}

Sample
twoTouchingSpheres(const SampleOptions& o, double radius, double gap)
{
  checkOptions(o);
  if (!(gap >= 0.0) || !std::isfinite(gap))
    throw std::invalid_argument("cocone_test: gap must be >= 0");
  // Both spheres are sampled about the origin, each on its own, and moved apart once
  // the spacing is known.
  std::vector<Part> parts{spherePart(radius), spherePart(radius)};
  Rng rng(o.seed);
  std::vector<Site> sites = o.even ? poissonSites(parts,
                                                  o,
                                                  rng,
                                                  [](const Site& s, const Site& t) {
                                                    return s.component == t.component;
                                                  })
                                   : randomSites(parts, o, rng);
  const double spacing = meanNearestDistanceWithin(
      sites,
      [](const Site& site) { return site.component; },
      std::sqrt(2.0 * parts[0].area / double(sites.size())));
  const double shift = radius + 0.5 * gap * spacing;
  const Eigen::Vector3d offset[2] = {Eigen::Vector3d(-shift, 0.0, 0.0),
                                     Eigen::Vector3d(shift, 0.0, 0.0)};
  for (int k = 0; k < 2; ++k)
    parts[k] = translated(parts[k], offset[k]);
  for (Site& site : sites)
    site.p += offset[site.component];
  return assemble("two_touching_spheres", parts, sites, spacing, o, rng);
}

Sample
rangeViews(const Sample& surface,
           int views,
           double registration_error,
           std::uint64_t seed,
           double noise,
           double keep)
{
  if (views < 1)
    throw std::invalid_argument("cocone_test: rangeViews needs views >= 1");
  if (!(registration_error >= 0.0) || !std::isfinite(registration_error))
    throw std::invalid_argument("cocone_test: registration_error must be >= 0");
  if (!(noise >= 0.0) || !std::isfinite(noise))
    throw std::invalid_argument("cocone_test: noise must be >= 0");
  if (!(keep > 0.0 && keep <= 1.0))
    throw std::invalid_argument("cocone_test: keep must be in (0, 1]");
  if (surface.points.empty() || surface.normals.size() != surface.points.size())
    throw std::invalid_argument("cocone_test: rangeViews needs a sampled surface");
  const std::vector<Eigen::Vector3d>& sites = surface.points;
  const std::size_t n = sites.size();
  const auto usable = [&](std::size_t i) {
    return surface.outlier.empty() || !surface.outlier[i];
  };
  Eigen::Vector3d lo, hi;
  boundingBox(sites, lo, hi);
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double extent = 0.5 * std::sqrt(sq3(hi - lo));
  const double s = surface.spacing;
  Rng rng(seed);

  // Views one after the other: a z-buffer of the splatted points, then each visible
  // point not yet kept is kept with probability keep.
  std::vector<int> owner(n, -1);
  std::vector<char> seen(n, false);
  std::vector<std::size_t> kept;
  for (int v = 0; v < views; ++v) {
    const double z = 1.0 - (2.0 * v + 1.0) / views;
    const Eigen::Vector2d cs = portableCosSin(v * kPi * (3.0 - std::sqrt(5.0)));
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d d(rho * cs.x(), rho * cs.y(), z);
    const Eigen::Vector3d camera = centre + 4.0 * extent * d;
    Eigen::Vector3d e1, e2;
    frame(d, e1, e2);
    // Image coordinates: tangents of the view angles, cells of 0.7 spacings at the
    // centre's distance. Each point is a disc of radius 2 spacings in its tangent
    // plane, drawn into the cells within 3 of its own (which covers the gaps
    // between the samples at every angle); a point is seen where it is at most 1.5
    // spacings behind the nearest disc in its cell.
    const double cell = 0.7 * s / (4.0 * extent);
    const long reach = 3;
    std::vector<long> ci(n), cj(n);
    long i0 = std::numeric_limits<long>::max(), j0 = i0, i1 = -i0, j1 = -i0;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d w = sites[i] - camera;
      const double depth = -dot3(w, d);
      ci[i] = static_cast<long>(std::floor(dot3(w, e1) / depth / cell));
      cj[i] = static_cast<long>(std::floor(dot3(w, e2) / depth / cell));
      i0 = std::min(i0, ci[i]);
      i1 = std::max(i1, ci[i]);
      j0 = std::min(j0, cj[i]);
      j1 = std::max(j1, cj[i]);
    }
    i0 -= reach;
    j0 -= reach;
    const long wj = j1 - j0 + reach + 1;
    std::vector<double> zbuffer((i1 - i0 + reach + 1) * wj,
                                std::numeric_limits<double>::infinity());
    const double disc2 = 4.0 * s * s;
    for (std::size_t i = 0; i < n; ++i) {
      if (!usable(i))
        continue;
      const Eigen::Vector3d& nrm = surface.normals[i];
      const double height = dot3(nrm, sites[i] - camera);
      for (long a = ci[i] - reach; a <= ci[i] + reach; ++a)
        for (long b = cj[i] - reach; b <= cj[i] + reach; ++b) {
          // The ray through the cell's centre, at depth t: camera + t ray.
          const Eigen::Vector3d ray =
              ((a + 0.5) * cell) * e1 + ((b + 0.5) * cell) * e2 - d;
          const double slope = dot3(nrm, ray);
          if (slope == 0.0)
            continue;
          const double t = height / slope;
          if (t > 0.0 && sq3(camera + t * ray - sites[i]) <= disc2) {
            double& z = zbuffer[(a - i0) * wj + (b - j0)];
            z = std::min(z, t);
          }
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!usable(i))
        continue;
      double facing = dot3(surface.normals[i], camera - sites[i]);
      if (!surface.closed)
        facing = std::abs(facing);
      if (!(facing > 0.0) || -dot3(sites[i] - camera, d) >
                                 zbuffer[(ci[i] - i0) * wj + (cj[i] - j0)] + 1.5 * s)
        continue;
      seen[i] = true;
      if (owner[i] < 0 && rng.uniform01() < keep) {
        owner[i] = v;
        kept.push_back(i);
      }
    }
  }
  if (kept.empty())
    throw std::invalid_argument("cocone_test: rangeViews: no view sees the surface");
  // Views in order, each in the order of the sites.
  std::stable_sort(kept.begin(), kept.end(), [&](std::size_t a, std::size_t b) {
    return owner[a] < owner[b];
  });

  Sample out;
  out.name = surface.name + "_range_views";
  out.area = surface.area;
  out.distance = surface.distance;
  for (const std::size_t i : kept) {
    out.points.push_back(sites[i]);
    out.normals.push_back(surface.normals[i]);
    out.view.push_back(owner[i]);
    out.component.push_back(surface.component.empty() ? 0 : surface.component[i]);
    out.near_boundary.push_back(!surface.near_boundary.empty() &&
                                surface.near_boundary[i]);
  }
  out.outlier.assign(kept.size(), false);
  out.spacing = meanNearestDistance(out.points, s);

  // Coverage: every site within 2 (dense) spacings of one that a view saw.
  std::vector<Eigen::Vector3d> visible, unseen;
  for (std::size_t i = 0; i < n; ++i)
    if (seen[i])
      visible.push_back(sites[i]);
  const PointGrid grid(visible, s);
  for (std::size_t i = 0; i < n; ++i) {
    double dist = 0.0;
    if (usable(i) && !seen[i] && grid.nearest(sites[i], 2.0 * s, -1, dist) < 0)
      unseen.push_back(sites[i]);
  }
  if (unseen.empty()) {
    out.boundary_curve = surface.boundary_curve;
    out.boundary_curve_loop = surface.boundary_curve_loop;
    out.boundary_loops = surface.boundary_loops;
    out.components = surface.components;
    out.euler = surface.euler;
    out.closed = surface.closed;
  }
  else {
    out.boundary_loops = -1;
    out.components = -1;
    out.euler = 0;
    out.closed = false;
    const PointGrid holes(unseen, out.spacing);
    for (std::size_t k = 0; k < out.points.size(); ++k) {
      double dist = 0.0;
      if (holes.nearest(out.points[k], 3.0 * out.spacing, -1, dist) >= 0)
        out.near_boundary[k] = true;
    }
  }

  // Noise, then the view's motion: a rotation about the centre by an angle that
  // moves no point more than registration_error / 2 spacings, and a translation of
  // that length.
  std::size_t k = 0;
  for (int v = 0; v < views; ++v) {
    const std::size_t begin = k;
    for (; k < kept.size() && out.view[k] == v; ++k)
      out.points[k] += (rng.normal() * noise * out.spacing) * out.normals[k];
    const double move = 0.5 * registration_error * out.spacing;
    const Eigen::Vector3d axis = rng.unitVector();
    const Eigen::Vector3d shift = move * rng.unitVector();
    const Eigen::Vector2d half = portableCosSin(0.5 * move / extent);
    const double qw = half.x();
    const Eigen::Vector3d qv = half.y() * axis;
    // The rotation matrix of the unit quaternion (qw, qv), row by row.
    const double x = qv.x(), y = qv.y(), z = qv.z();
    const Eigen::Vector3d rows[3] = {Eigen::Vector3d(1.0 - 2.0 * (y * y + z * z),
                                                     2.0 * (x * y - qw * z),
                                                     2.0 * (x * z + qw * y)),
                                     Eigen::Vector3d(2.0 * (x * y + qw * z),
                                                     1.0 - 2.0 * (x * x + z * z),
                                                     2.0 * (y * z - qw * x)),
                                     Eigen::Vector3d(2.0 * (x * z - qw * y),
                                                     2.0 * (y * z + qw * x),
                                                     1.0 - 2.0 * (x * x + y * y))};
    for (std::size_t i = begin; i < k; ++i) {
      const Eigen::Vector3d w = out.points[i] - centre;
      out.points[i] =
          centre +
          Eigen::Vector3d(dot3(rows[0], w), dot3(rows[1], w), dot3(rows[2], w)) + shift;
    }
  }
  return out;
}

Sample
withOutliers(Sample s, double fraction, double max_offset_spacings, std::uint64_t seed)
{
  if (!(fraction >= 0.0 && fraction <= 1.0))
    throw std::invalid_argument("cocone_test: fraction must be in [0, 1]");
  if (!(max_offset_spacings >= 1.0) || !std::isfinite(max_offset_spacings))
    throw std::invalid_argument("cocone_test: max_offset_spacings must be >= 1");
  const std::size_t n = s.points.size();
  s.outlier.resize(n, false);
  s.near_boundary.resize(n, false);
  s.component.resize(n, 0);
  Rng rng(seed);
  const auto count = static_cast<std::size_t>(fraction * double(n) + 0.5);
  for (const std::size_t i : randomSubset(n, count, rng)) {
    const double offset = rng.uniform(1.0, max_offset_spacings) * s.spacing;
    const double side = rng.uniform01() < 0.5 ? -1.0 : 1.0;
    s.points[i] += (side * offset) * s.normals[i];
    s.outlier[i] = true;
    s.near_boundary[i] = false;
    s.component[i] = -1;
  }
  return s;
}

Sample
withScatteredOutliers(Sample s, double fraction, std::uint64_t seed)
{
  if (!(fraction >= 0.0) || !std::isfinite(fraction))
    throw std::invalid_argument("cocone_test: fraction must be >= 0");
  const std::size_t n = s.points.size();
  if (n == 0)
    return s;
  s.outlier.resize(n, false);
  s.near_boundary.resize(n, false);
  s.component.resize(n, 0);
  Eigen::Vector3d lo, hi;
  boundingBox(s.points, lo, hi);
  const double margin = 0.05 * (hi - lo).maxCoeff();
  lo -= Eigen::Vector3d::Constant(margin);
  hi += Eigen::Vector3d::Constant(margin);
  Rng rng(seed);
  const auto count = static_cast<std::size_t>(fraction * double(n) + 0.5);
  for (std::size_t k = 0; k < count; ++k) {
    const double x = rng.uniform(lo.x(), hi.x());
    const double y = rng.uniform(lo.y(), hi.y());
    const double z = rng.uniform(lo.z(), hi.z());
    s.points.emplace_back(x, y, z);
    s.normals.push_back(Eigen::Vector3d::Zero());
    s.outlier.push_back(true);
    s.near_boundary.push_back(false);
    s.component.push_back(-1);
    if (!s.view.empty())
      s.view.push_back(-1);
  }
  return s;
}

} // namespace cocone_test
