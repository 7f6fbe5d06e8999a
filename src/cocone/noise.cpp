/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/noise.h>

#include <Eigen/Eigenvalues>

#include "allocator.h"
#include "parallel.h"
#include "points.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

constexpr int NEAREST = VoronoiCells::NEAREST;
constexpr std::size_t TWO_RING = std::size_t(NEAREST) * (NEAREST + 1);
/** Neighbourhood of the smoothing: CGAL's default for jet fitting. */
constexpr int SMOOTHING_NEIGHBOURS = 24;
/** Of each neighbour's nearest Delaunay neighbours, the nearest this many count
 * towards p's two-ring. All 12 give the undersampled labels 0.02 to 0.07 more
 * precision on the noisy open surfaces of the quality table, but smooth the Stanford
 * range scans more and close more of their dropouts (mesh-border F1 -0.03 to 0); with
 * 8 one noisy test surface tears a hole. */
constexpr int SECOND_RING = 10;
/** Points a jet is fitted to at least: twice its six coefficients, or the fit
 * follows the noise. */
constexpr int JET_POINTS = 12;
/** Turns sqrt(mean square off the plane / spread along it) over a point and its
 * nearest Delaunay neighbours into sigma in spacings: measured on random samples
 * with Gaussian noise of 0.3, 0.5 and 1 spacing. */
constexpr double LEVEL_SCALE = 3.8;
/** One point in this many has its noise level measured again after smoothing. */
constexpr int RECHECK_STRIDE = 4;
/** An outlier stands off its neighbours' plane by more than this many times their
 * RMS distance from it (isOutlier()). Measured on 312 clean generated clouds: false
 * outliers 1,801 -> 171 (thin plates 1,036 -> 43, the coarse tube 652 -> 76), 448
 * with 2, 79 with 4; the flying pixels and scattered outliers of the quality table
 * found as before. */
constexpr double PLANE_OFFSET_RMS = 3.0;
/** Rounds of the outlier search at most. */
constexpr int OUTLIER_ROUNDS = 3;

/** Least-squares plane of points given by their sums relative to an origin: the
 * centroid, the unit normal and the mean squared distance to the plane. */
struct Plane {
  Eigen::Vector3d centroid;
  Eigen::Vector3d normal;
  Eigen::Vector3d tangent_u, tangent_v;
  double mean_square = 0.0;
  /** Mean squared distance from the centroid along the plane. */
  double spread = 0.0;
  /** Of that, the part along tangent_v (the narrower way). */
  double narrow_spread = 0.0;
};

/** The centroid and covariance of points given by their sums relative to an
 * origin: what fitPlane(), fitJetPlane() and the outlier test's bound read. */
struct Scatter {
  Scatter(const Eigen::Vector3d& sum, const Eigen::Matrix3d& outer, int count)
  : centroid(sum / count), covariance(outer / count - centroid * centroid.transpose())
  {}

  Eigen::Vector3d centroid;
  Eigen::Matrix3d covariance;
};

Plane
fitPlane(const Scatter& scatter)
{
  Plane plane;
  plane.centroid = scatter.centroid;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(scatter.covariance);
  // Ascending eigenvalues: the smallest's vector is the normal.
  plane.normal = solver.eigenvectors().col(0);
  plane.tangent_u = solver.eigenvectors().col(2);
  plane.tangent_v = solver.eigenvectors().col(1);
  plane.mean_square = std::max(solver.eigenvalues()(0), 0.0);
  plane.spread = solver.eigenvalues()(1) + solver.eigenvalues()(2);
  plane.narrow_spread = solver.eigenvalues()(1);
  return plane;
}

/** The unit direction of the largest column of the adjugate of the symmetric \a M
 * (the cross products of its columns in pairs), which lies along the eigenvector of
 * its eigenvalue nearest 0 where that one is apart from the others; false where
 * the columns are all zero or not finite. */
bool
largestAdjugateColumn(const Eigen::Matrix3d& M, Eigen::Vector3d* direction)
{
  const Eigen::Vector3d columns[3] = {
      M.col(1).cross(M.col(2)), M.col(2).cross(M.col(0)), M.col(0).cross(M.col(1))};
  int largest = 0;
  for (int i = 1; i < 3; ++i)
    if (columns[i].squaredNorm() > columns[largest].squaredNorm())
      largest = i;
  const double length = columns[largest].norm();
  if (!(length > 0.0) || !std::isfinite(length))
    return false;
  *direction = columns[largest] / length;
  return true;
}

/** The smallest eigenvalue of the symmetric \a S of trace 1, and its unit
 * eigenvector, where it is at least GAP below the next; false otherwise. Newton's
 * iteration on the characteristic polynomial f from 0 climbs to the smallest root
 * without overshooting it (f is increasing and concave below it), in two or three
 * steps where the points are near a plane (the smallest eigenvalue far below the
 * others), and the eigenvector is the largest column of the adjugate of S - l0 I
 * (largestAdjugateColumn()): what a jet needs of its plane, without the closed form's
 * trigonometry (Eigen's computeDirect(); the noise analysis of a clean million
 * 0.63 -> 0.55 s, one thread). */
bool
smallestEigenpair(const Eigen::Matrix3d& S, double* l0, Eigen::Vector3d* normal)
{
  constexpr double GAP = 1e-3;
  constexpr int STEPS = 16;
  // f(x) = x^3 - x^2 + c1 x - c0: c1 the sum of the principal 2 x 2 minors.
  const double c1 = S(0, 0) * S(1, 1) - S(0, 1) * S(0, 1) + S(0, 0) * S(2, 2) -
                    S(0, 2) * S(0, 2) + S(1, 1) * S(2, 2) - S(1, 2) * S(1, 2);
  const double c0 = S.determinant();
  // The first step from 0 lands on c0 / c1 (0 where S is singular within rounding).
  double x = c0 > 0.0 && c1 > 0.0 ? c0 / c1 : 0.0;
  bool converged = !(x > 0.0);
  for (int step = 0; step < STEPS && !converged; ++step) {
    const double f = ((x - 1.0) * x + c1) * x - c0;
    const double slope = (3.0 * x - 2.0) * x + c1;
    const double dx = -f / slope;
    if (!(f < 0.0) || !(dx > 1e-17)) // at the root within rounding
      converged = true;
    else
      x += dx;
  }
  // The other two roots, of f / (x - l0) = y^2 + b y + c.
  const double b = x - 1.0, c = c1 + x * b;
  const double next = 0.5 * (-b - std::sqrt(std::max(b * b - 4.0 * c, 0.0)));
  if (!converged || !(next - x > GAP))
    return false;
  if (!largestAdjugateColumn(S - x * Eigen::Matrix3d::Identity(), normal))
    return false;
  *l0 = x;
  return true;
}

/** The plane of a jet: fitPlane()'s centroid, normal, mean square and spread, with
 * some unit tangents (a jet over the plane does not depend on which), from
 * smallestEigenpair() where it answers; fitPlane()'s otherwise. */
Plane
fitJetPlane(const Scatter& scatter)
{
  const double trace = scatter.covariance.trace();
  double l0 = 0.0;
  Eigen::Vector3d normal;
  if (!(trace > 0.0) || !std::isfinite(trace) ||
      !smallestEigenpair(scatter.covariance * (1.0 / trace), &l0, &normal))
    return fitPlane(scatter);
  Plane plane;
  plane.centroid = scatter.centroid;
  plane.normal = normal;
  plane.tangent_u = normal.unitOrthogonal();
  plane.tangent_v = normal.cross(plane.tangent_u);
  plane.mean_square = l0 * trace;
  plane.spread = (1.0 - l0) * trace;
  plane.narrow_spread = std::numeric_limits<double>::quiet_NaN(); // not known
  return plane;
}

int
count(const std::array<int, NEAREST>& near)
{
  int c = 0;
  while (c < NEAREST && near[c] >= 0)
    ++c;
  return c;
}

template <typename T>
T
median(std::vector<T> values)
{
  if (values.empty())
    return T(0);
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/** The first and second moments of the points P[i] - origin over \a neighbours
 * (the origin adds zeros), and the largest squared distance among them. */
struct Moments {
  Moments(const Eigen::Vector3d* P,
          const Eigen::Vector3d& origin,
          const int* neighbours,
          int k)
  {
    // The six sums of the symmetric outer products rather than Eigen's q q^T,
    // whose nine cost a fifth of the noise analysis (a clean million 0.46 ->
    // 0.36 s, one thread; the same bits).
    double xx = 0.0, yx = 0.0, zx = 0.0, yy = 0.0, zy = 0.0, zz = 0.0;
    for (int i = 0; i < k; ++i) {
      const Eigen::Vector3d q = P[neighbours[i]] - origin;
      sum += q;
      xx += q.x() * q.x();
      yx += q.y() * q.x();
      zx += q.z() * q.x();
      yy += q.y() * q.y();
      zy += q.z() * q.y();
      zz += q.z() * q.z();
      radius2 = std::max(radius2, q.squaredNorm());
    }
    outer << xx, yx, zx, yx, yy, zy, zx, zy, zz;
  }

  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  double radius2 = 0.0;
};

/** Solve the normal equations A c = b of a jet (A symmetric, its lower triangle
 * given) by LDL^T without pivoting, in place of Eigen's LDLT, whose pivoting and
 * blocked updates cost more than the sums on a 6 x 6 system (the noise analysis of
 * a clean million 0.85 -> 0.66 s, one thread). The normal matrix of a fit is
 * positive definite where the fit is determined, so no pivot is needed; false
 * where a pivot is not positive or the pivots span more than 1e9 (the points on a
 * conic of the plane: the jet is not determined). */
bool
solveNormalEquations(double (&A)[6][6],
                     const Eigen::Matrix<double, 6, 1>& b,
                     Eigen::Matrix<double, 6, 1>& c)
{
  double d[6];
  for (int j = 0; j < 6; ++j) {
    // Column j of L (stored below the diagonal of A) and the pivot d[j].
    double pivot = A[j][j];
    for (int k = 0; k < j; ++k)
      pivot -= A[j][k] * A[j][k] * d[k];
    if (!(pivot > 0.0))
      return false;
    d[j] = pivot;
    for (int i = j + 1; i < 6; ++i) {
      double sum = A[i][j];
      for (int k = 0; k < j; ++k)
        sum -= A[i][k] * A[j][k] * d[k];
      A[i][j] = sum / pivot;
    }
  }
  if (!(*std::min_element(d, d + 6) > 1e-9 * *std::max_element(d, d + 6)))
    return false;
  double y[6];
  for (int i = 0; i < 6; ++i) {
    y[i] = b(i);
    for (int k = 0; k < i; ++k)
      y[i] -= A[i][k] * y[k];
  }
  for (int i = 5; i >= 0; --i) {
    double x = y[i] / d[i];
    for (int k = i + 1; k < 6; ++k)
      x -= A[k][i] * c(k);
    c(i) = x;
  }
  return true;
}

/** Least-squares degree-2 jet: a quadratic height field w(u, v) over the plane of
 * the points, u and v scaled by the neighbourhood's radius so that the normal
 * equations stay well conditioned. */
class Jet {
public:
  /** The jet of \a P[i] - origin over \a neighbours, and of the origin itself when
   * \a with_origin. */
  Jet(const Eigen::Vector3d* P,
      const Eigen::Vector3d& origin,
      const int* neighbours,
      int k,
      bool with_origin,
      int min_points = JET_POINTS)
  : Jet(P,
        origin,
        neighbours,
        k,
        Moments(P, origin, neighbours, k),
        with_origin,
        min_points)
  {}

  /** The same, with the \a moments of the neighbours about the origin given. */
  Jet(const Eigen::Vector3d* P,
      const Eigen::Vector3d& origin,
      const int* neighbours,
      int k,
      const Moments& moments,
      bool with_origin,
      int min_points = JET_POINTS)
  : origin_(origin)
  {
    const double radius2 = moments.radius2;
    const int points = k + (with_origin ? 1 : 0);
    if (points < 3 || radius2 == 0.0)
      return;
    // The origin adds zeros to the sums.
    plane_ = fitJetPlane(Scatter(moments.sum, moments.outer, points));
    planar_ = true;
    mean_square_ = plane_.mean_square;
    if (points > 3)
      sigma_ = std::sqrt(mean_square_ * points / (points - 3));
    if (points < min_points)
      return;
    scale_ = 1.0 / std::sqrt(radius2);
    // The normal equations' matrix over the basis 1, u, v, u^2, uv, v^2 holds the
    // moments u^a v^b (a + b <= 4) of the points: 15 sums per point rather than a
    // 6 x 6 rank update (the smoothing's hot loop: measured a fifth faster).
    double m[5][5] = {}; // m[a][b]: the sum of u^a v^b
    Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
    double heights2 = 0.0;
    const auto add = [&](const Eigen::Vector3d& q) {
      const Eigen::Vector3d d = q - plane_.centroid;
      const double u = d.dot(plane_.tangent_u) * scale_,
                   v = d.dot(plane_.tangent_v) * scale_, w = d.dot(plane_.normal);
      const double uu = u * u, uv = u * v, vv = v * v;
      m[0][0] += 1.0;
      m[1][0] += u;
      m[0][1] += v;
      m[2][0] += uu;
      m[1][1] += uv;
      m[0][2] += vv;
      m[3][0] += uu * u;
      m[2][1] += uu * v;
      m[1][2] += u * vv;
      m[0][3] += vv * v;
      m[4][0] += uu * uu;
      m[3][1] += uu * uv;
      m[2][2] += uu * vv;
      m[1][3] += uv * vv;
      m[0][4] += vv * vv;
      rhs(0) += w;
      rhs(1) += w * u;
      rhs(2) += w * v;
      rhs(3) += w * uu;
      rhs(4) += w * uv;
      rhs(5) += w * vv;
      heights2 += w * w;
    };
    if (with_origin)
      add(Eigen::Vector3d::Zero());
    for (int i = 0; i < k; ++i)
      add(P[neighbours[i]] - origin);
    // The exponents (a, b) of each basis function.
    constexpr int EXPONENT[6][2] = {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}};
    double normal_matrix[6][6];
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j <= i; ++j)
        normal_matrix[i][j] =
            m[EXPONENT[i][0] + EXPONENT[j][0]][EXPONENT[i][1] + EXPONENT[j][1]];
    if (!solveNormalEquations(normal_matrix, rhs, coefficients_))
      return;
    // The residual sum of squares of a least-squares fit: |w|^2 - c . (A^T w).
    const double residual = (heights2 - coefficients_.dot(rhs)) / points;
    if (!coefficients_.allFinite() || !std::isfinite(residual))
      return;
    curved_ = true;
    mean_square_ = std::max(residual, 0.0);
    sigma_ = std::sqrt(mean_square_ * points / (points - 6));
  }

  /** The point of the jet above or below \a x (of the plane where the jet is not
   * determined); x itself without a plane. */
  Eigen::Vector3d
  project(const Eigen::Vector3d& x) const
  {
    if (!planar_)
      return x;
    const Eigen::Vector3d d = x - origin_ - plane_.centroid;
    const double height = curved_ ? basis(d).dot(coefficients_) : 0.0;
    return x + (height - d.dot(plane_.normal)) * plane_.normal;
  }

  /** Signed distance of \a x to the jet (to the plane where the jet is not
   * determined) along the plane's normal. */
  double
  residual(const Eigen::Vector3d& x) const
  {
    if (!planar_)
      return 0.0;
    const Eigen::Vector3d d = x - origin_ - plane_.centroid;
    return d.dot(plane_.normal) - (curved_ ? basis(d).dot(coefficients_) : 0.0);
  }

  /** Whether the plane is determined (else the jet is nothing). */
  bool
  planar() const
  {
    return planar_;
  }

  /** Whether the jet is determined (else it is the plane). */
  bool
  curved() const
  {
    return curved_;
  }

  /** The unit normal of the plane of the points. */
  const Eigen::Vector3d&
  normal() const
  {
    return plane_.normal;
  }

  /** Mean squared distance of the points to the jet (to the plane where the jet is
   * not determined). */
  double
  meanSquare() const
  {
    return mean_square_;
  }

  /** The noise's standard deviation about the jet (the plane where the jet is not
   * determined): the residual with the fit's degrees of freedom taken out. */
  double
  sigma() const
  {
    return sigma_;
  }

  /** Mean squared distance of the points from their centroid along the plane. */
  double
  spread() const
  {
    return plane_.spread;
  }

private:
  Eigen::Matrix<double, 6, 1>
  basis(const Eigen::Vector3d& d) const
  {
    const double u = d.dot(plane_.tangent_u) * scale_,
                 v = d.dot(plane_.tangent_v) * scale_;
    Eigen::Matrix<double, 6, 1> b;
    b << 1.0, u, v, u * u, u * v, v * v;
    return b;
  }

  Eigen::Vector3d origin_;
  Plane plane_;
  double scale_ = 1.0;
  Eigen::Matrix<double, 6, 1> coefficients_ = Eigen::Matrix<double, 6, 1>::Zero();
  double mean_square_ = 0.0;
  double sigma_ = std::numeric_limits<double>::infinity();
  bool planar_ = false, curved_ = false;
};

/** The K nearest of a vertex's nearest Delaunay neighbours and theirs (its
 * two-ring, SECOND_RING of theirs), the nearest by distance, then id (in no
 * particular order); the vertices excluded are left out. */
class TwoRing {
public:
  TwoRing(const std::vector<Eigen::Vector3d>& points,
          const std::vector<std::array<int, NEAREST>>& nearest,
          const std::vector<std::uint8_t>& excluded)
  : points_(points), nearest_(nearest), excluded_(excluded), seen_(points.size(), -1)
  {}

  /** Write up to \a k neighbours of \a p to \a out; returns how many. */
  int
  gather(int p, int k, int* out)
  {
    int r = 0;
    seen_[p] = p;
    // A stamp per vertex drops the duplicates (a ring holds each neighbour several
    // times) without a sort.
    const auto offer = [&](int q) {
      if (seen_[q] != p && (excluded_.empty() || !excluded_[q])) {
        seen_[q] = p;
        ring_[r++] = {(points_[q] - points_[p]).squaredNorm(), q};
      }
    };
    for (const int q : nearest_[p]) {
      if (q < 0)
        break;
      offer(q);
      for (int i = 0; i < SECOND_RING && nearest_[q][i] >= 0; ++i)
        offer(nearest_[q][i]);
    }
    const int size = std::min(r, k);
    std::nth_element(ring_.begin(), ring_.begin() + size, ring_.begin() + r);
    for (int i = 0; i < size; ++i)
      out[i] = ring_[i].second;
    return size;
  }

private:
  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<std::array<int, NEAREST>>& nearest_;
  const std::vector<std::uint8_t>& excluded_;
  std::vector<int> seen_;
  std::array<std::pair<double, int>, TWO_RING> ring_;
};

/** The number of p's nearest neighbours within three of its \a spacing (the mean
 * distance to the 6 nearest, meanNeighbourDistance()): the Delaunay neighbours of
 * a surface sample include long edges across the inside or the outside, which are
 * not the surface's. */
int
nearNeighbours(const std::vector<Eigen::Vector3d>& points,
               const std::array<int, NEAREST>& list,
               int p,
               double spacing)
{
  const int c = count(list);
  const double reach2 = 9.0 * spacing * spacing;
  int k = 0;
  while (k < c && (points[list[k]] - points[p]).squaredNorm() <= reach2)
    ++k;
  return k;
}

/** p's spacing over its neighbour \a list: the mean distance to the nearest 6
 * (meanNeighbourDistance(), as meanSpacing()). */
double
spacingOf(const std::vector<Eigen::Vector3d>& points,
          const std::array<int, NEAREST>& list,
          int p)
{
  return detail::meanNeighbourDistance(points, list, p, detail::SPACING_NEIGHBOURS);
}

/** The noise level of a point from the jet of it and its near neighbours: against
 * the spread along the surface, which the noise does not inflate as it does the
 * distances; off the jet rather than the plane, which would read a coarse sample's
 * curvature as noise. */
double
noiseLevel(const Jet& jet)
{
  return jet.spread() > 0.0 ? LEVEL_SCALE * std::sqrt(jet.meanSquare() / jet.spread())
                            : 0.0;
}

/** What the outlier test reads of a point's near neighbours (nearNeighbours()),
 * per vertex: how many there are and their mean spacing. */
struct Neighbourhoods {
  explicit Neighbourhoods(std::size_t n) : near(n, 0), spacing(n) {}
  std::vector<std::uint8_t> near;
  std::vector<float> spacing;
};

/** Fill in p's entry of \a hoods from its neighbour list and its \a spacing
 * (spacingOf()). */
void
describe(const std::vector<Eigen::Vector3d>& points,
         const std::array<int, NEAREST>& list,
         int p,
         double spacing,
         Neighbourhoods& hoods)
{
  hoods.spacing[p] = static_cast<float>(spacing);
  hoods.near[p] = static_cast<std::uint8_t>(nearNeighbours(points, list, p, spacing));
}

/** A second sheet closer than the spacing (two bodies touching, the sparser of two
 * sheets) may have only the other sheet's samples among a sample's nearest: it
 * stands off their surface as an outlier does. Unlike one, it has company there:
 * this many samples off that surface on its side, on a plane with it that they
 * span (onSheetOfItsOwn()). Measured on two spheres half a spacing apart sampled
 * with the density growing 1:8: of the samples of the sparser cap set aside, 7 and
 * 12, all but one each have it; the flying pixels and scattered outliers of the
 * quality table do not (found as before, 96 and 95 of 100 and 92 of 97, with the
 * test on whatever the noise). */
constexpr int SHEET_COMPANIONS = 3;

/** The points in the cells of a hash grid round a few centres (the 3 x 3 x 3 cells
 * round each): a radius search of up to one cell round them, for a few points of a
 * large cloud, without a tree over all of it (one pass over the points). */
class LocalGrid {
public:
  LocalGrid(const std::vector<Eigen::Vector3d>& points,
            const std::vector<Eigen::Vector3d>& centres,
            double cell)
  : cell_(cell)
  {
    std::unordered_map<std::uint64_t, std::vector<int>> wanted;
    for (const auto& c : centres)
      forEachCell(c,
                  [&](std::uint64_t key) { wanted.emplace(key, std::vector<int>()); });
    for (std::size_t v = 0; v < points.size(); ++v) {
      const auto found = wanted.find(key(points[v]));
      if (found != wanted.end())
        found->second.push_back(static_cast<int>(v));
    }
    cells_ = std::move(wanted);
  }

  /** Calls f(v) for every point v in the cells round \a x (a centre's). */
  template <typename F>
  void
  forEachNear(const Eigen::Vector3d& x, const F& f) const
  {
    forEachCell(x, [&](std::uint64_t key) {
      const auto found = cells_.find(key);
      if (found != cells_.end())
        for (const int v : found->second)
          f(v);
    });
  }

private:
  /** A cell's key: its three coordinates, 21 bits each (wrapping: a key shared by
   * distant cells only adds points to test). */
  std::uint64_t
  key(const Eigen::Vector3d& x, int dx = 0, int dy = 0, int dz = 0) const
  {
    const auto coordinate = [&](double c, int d) {
      return static_cast<std::uint64_t>(
                 static_cast<std::int64_t>(std::floor(c / cell_)) + d) &
             ((std::uint64_t(1) << 21) - 1);
    };
    return coordinate(x.x(), dx) | (coordinate(x.y(), dy) << 21) |
           (coordinate(x.z(), dz) << 42);
  }

  template <typename F>
  void
  forEachCell(const Eigen::Vector3d& x, const F& f) const
  {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          f(key(x, dx, dy, dz));
  }

  double cell_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

/** The median spacing of p's near neighbours (describe()). */
double
aroundSpacing(const std::array<int, NEAREST>& list, int k, const Neighbourhoods& hoods)
{
  // The value of rank k / 2 by counting, for each value, the values below it and
  // equal to it: branch-free comparisons over a fixed 12, cheaper than an insertion
  // sort's unpredictable branches on so few values (the noise analysis of a clean
  // million 0.66 -> 0.63 s, one thread); the same median.
  std::array<float, NEAREST> around;
  around.fill(std::numeric_limits<float>::infinity());
  for (int i = 0; i < k; ++i)
    around[i] = hoods.spacing[list[i]];
  const int middle = k / 2;
  for (int i = 0; i < k; ++i) {
    int below = 0, equal = 0;
    for (int j = 0; j < NEAREST; ++j) {
      below += around[j] < around[i];
      equal += around[j] == around[i];
    }
    if (below <= middle && middle < below + equal)
      return around[i];
  }
  return around[middle]; // not reached: some value has rank k / 2
}

/** The least spacing of p's near neighbours (describe()): a lower bound of
 * aroundSpacing() for a fraction of its cost. */
double
leastSpacing(const std::array<int, NEAREST>& list, int k, const Neighbourhoods& hoods)
{
  float least = std::numeric_limits<float>::infinity();
  for (int i = 0; i < k; ++i)
    least = std::min(least, hoods.spacing[list[i]]);
  return least;
}

/** Companions tell a second sheet from outliers only in a cloud whose noise level
 * (sigma in spacings) is at most this, well within their band of a quarter
 * spacing: in a noisier one the tails of the noise have company at their height by
 * chance (kept, with noise of 0.3 spacings, they left 38 loops on the closed meshes
 * of three seeds rather than 32). */
constexpr double SHEET_NOISE_LEVEL = 0.1;

/** How far from an outlier found its companions (onSheetOfItsOwn()) may lie, in
 * its neighbours' spacing: the second sheet may be sampled more sparsely than the
 * one they are on (up to 2.8 times across the spheres sampled 1:8). Not in its own
 * spacing, which a point floating off the surface has as wide as its height. */
constexpr double COMPANION_REACH = 4.0;

/** Whether p, found an outlier over its near neighbours in \a list (isOutlier(),
 * not isolated; \a around_spacing their spacing, aroundSpacing()), has
 * SHEET_COMPANIONS samples of a sheet of its own round it (\a grid holds them):
 * samples off its neighbours' jet on its side by more than a quarter of their
 * spacing, within COMPANION_REACH of their spacing, which with p lie on a plane
 * (within that quarter) that they span both ways. Off the jet, not off the plane:
 * on a curved surface the samples a few spacings round an outlier rise off its
 * neighbours' plane to its height. The jet is fitted again, as isOutlier() did:
 * kept for every point judged, it would cost a jet's size per point for the few
 * found. */
bool
onSheetOfItsOwn(const std::vector<Eigen::Vector3d>& points,
                const std::array<int, NEAREST>& list,
                int p,
                const Neighbourhoods& hoods,
                double around_spacing,
                const LocalGrid& grid)
{
  const int k = hoods.near[p];
  const double band = 0.25 * around_spacing;
  const double across = COMPANION_REACH * around_spacing;
  const Jet jet(points.data(), points[p], list.data(), k, false, 9);
  const double own = jet.residual(points[p]);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  int companions = 0;
  grid.forEachNear(points[p], [&](int q) {
    const Eigen::Vector3d d = points[q] - points[p];
    const double h = jet.residual(points[q]);
    if (q == p || h * own <= 0.0 || std::abs(h) <= band ||
        d.squaredNorm() > across * across)
      return;
    ++companions;
    sum += d;
    outer += d * d.transpose();
  });
  if (companions < SHEET_COMPANIONS)
    return false;
  // Their plane with p (the origin adds zeros): p on it, they on it, spread both
  // ways along it (the smaller axis at least a fifth of the larger: not a streak).
  const Plane sheet = fitPlane(Scatter(sum, outer, companions + 1));
  return std::abs(sheet.normal.dot(sheet.centroid)) <= band &&
         sheet.mean_square <= band * band &&
         sheet.narrow_spread > 0.04 * (sheet.spread - sheet.narrow_spread);
}

/** What isOutlier() finds. */
enum class Verdict : std::uint8_t { SURFACE, OUTLIER, ISOLATED_OUTLIER };

/** Whether the smallest eigenvector n0 of the symmetric \a covariance provably has
 * |n0 . c| <= \a bound, without decomposing it (the outlier test's most frequent
 * question: on a clean million, two thirds of the points reach it and none is an
 * outlier). A false answer proves nothing.
 *
 * The adjugate of the covariance is the sum of l1 l2 n0 n0^T, l0 l2 n1 n1^T and
 * l0 l1 n2 n2^T (eigenvalues l0 <= l1 <= l2), so its largest column is close to
 * n0 where l0 is small: call it m. With rho = m^T C m and r = C m - rho m, the
 * angle t between m and n0 has sin(t) <= |r| / (l1 - rho) (r's components along
 * n1 and n2 are (l_i - rho) times m's), and l1 is at least the smaller eigenvalue
 * mu1 of C restricted to the plane orthogonal to m (Cauchy's interlacing). So
 * |n0 . c| <= |m . c| + |c| sin(t) <= |m . c| + |c| |r| / (mu1 - rho). The margins
 * cover rounding in this bound and in the decomposition it stands in for. The
 * bound holds for any unit m, a poor one only proves less: the caller may give one
 * as \a direction (null: the largest adjugate column). */
bool
offsetProvablyWithin(const Eigen::Matrix3d& covariance,
                     const Eigen::Vector3d& c,
                     double bound,
                     const Eigen::Vector3d* direction)
{
  const Eigen::Matrix3d& C = covariance;
  Eigen::Vector3d m;
  if (direction)
    m = *direction;
  else if (!largestAdjugateColumn(C, &m))
    return false;
  const Eigen::Vector3d Cm = C * m;
  const double rho = m.dot(Cm);
  const double residual = (Cm - rho * m).norm();
  const Eigen::Vector3d u = m.unitOrthogonal(), v = m.cross(u);
  const double a = u.dot(C * u), b = u.dot(C * v), d = v.dot(C * v);
  const double mu1 = 0.5 * (a + d) - std::sqrt(0.25 * (a - d) * (a - d) + b * b);
  const double gap = mu1 - rho;
  if (!(gap > 1e-3 * C.trace()))
    return false;
  const double sine = residual / gap;
  return std::abs(m.dot(c)) + c.norm() * sine <= (1.0 - 1e-4) * bound;
}

/** Whether p is an outlier: it stands off the jet of its neighbours without it by
 * a quarter of their spacing and by 6 sigma of the noise about that jet: neither the
 * curvature, which the jet follows, nor p, which the jet leaves out, raises them.
 * Only a point off the plane of its neighbours, by more than their own spread
 * about it, is a candidate (the jet is the expensive part, and fails where two
 * sheets mix), and only a point above them rather than beside them, which is how a
 * point at a border sees its neighbours' fit, extrapolated, miss it; unless p is
 * isolated, its spacing three times its neighbours'. \a normal, if given, is a
 * unit normal of a plane near theirs (offsetProvablyWithin()). */
Verdict
isOutlier(const std::vector<Eigen::Vector3d>& points,
          const std::array<int, NEAREST>& list,
          int p,
          const Neighbourhoods& hoods,
          const Moments& moments,
          const Eigen::Vector3d* normal = nullptr)
{
  constexpr Verdict verdict = Verdict::SURFACE;
  const int k = hoods.near[p];
  if (k < 3)
    return verdict;
  const Scatter neighbours(moments.sum, moments.outer, k);
  // p is no farther from its neighbours' plane than from their centroid: a third
  // of the points are answered without the plane (on a clean million: the noise
  // analysis 0.93 -> 0.72 s). The margin keeps the answer the plane's own where the
  // two distances tie. Nor, provably, farther from their plane than a quarter
  // spacing, the decomposition spared: all but 2 of the rest on a clean million.
  const auto within = [&](double spacing) {
    const double bound = 0.25 * spacing;
    return !(neighbours.centroid.norm() > bound * (1.0 - 1e-9)) ||
           offsetProvablyWithin(
               neighbours.covariance, neighbours.centroid, bound, normal);
  };
  // Both answers hold for the median spacing if they hold for the least: all but
  // 7 points of a clean million are answered without the median (the analysis
  // 0.56 -> 0.49 s).
  const double least = leastSpacing(list, k, hoods);
  if (within(least))
    return verdict;
  const double around_spacing = aroundSpacing(list, k, hoods);
  if (around_spacing != least && within(around_spacing))
    return verdict;
  const bool isolated = hoods.spacing[p] > 3.0 * around_spacing;
  const Plane without = fitPlane(neighbours);
  const double offset = std::abs(without.normal.dot(without.centroid));
  // Beside its neighbours rather than above them: p's foot on their plane is off
  // their centroid by more than its height, or by more than 0.8 of their RMS spread.
  const double foot =
      (without.centroid - without.normal.dot(without.centroid) * without.normal).norm();
  const bool beside = foot > offset || foot > 0.8 * std::sqrt(without.spread);
  if (!(offset > 0.25 * around_spacing) || (beside && !isolated))
    return verdict;
  // Nor within the spread of its neighbours about their plane, unless isolated:
  // where two sheets closer than the spacing mix in the neighbourhood (a thin plate,
  // a tube a few samples round, clean) p is as far off it as they are, 0.8 to 3.5
  // times their RMS distance, and the jet through their zig-zag misses it by 6
  // sigmas; noise puts 0.3 % of the samples 3 RMS off.
  if (!isolated && !(offset > PLANE_OFFSET_RMS * std::sqrt(without.mean_square)))
    return verdict;
  // A jet of 9 neighbours at least (a flying pixel has fewer near ones than a
  // surface point): a plane of a few misses a curved surface's point by as much as
  // a pixel, so only an isolated point is judged by one.
  const Jet jet(points.data(), points[p], list.data(), k, false, 9);
  if (!jet.curved() && !isolated)
    return verdict;
  const double off = (jet.project(points[p]) - points[p]).norm();
  if (!(off > 0.25 * around_spacing && off > 6.0 * jet.sigma()))
    return verdict;
  return isolated ? Verdict::ISOLATED_OUTLIER : Verdict::OUTLIER;
}

/** The \a candidates judged outliers (\a verdicts, isOutlier()), less, if \a
 * sheets, those on a sheet of their own (onSheetOfItsOwn()). */
std::vector<int>
confirmOutliers(const std::vector<Eigen::Vector3d>& points,
                const std::vector<std::array<int, NEAREST>>& lists,
                const Neighbourhoods& hoods,
                const std::vector<int>& candidates,
                std::vector<Verdict> verdicts,
                bool sheets)
{
  const auto n = static_cast<std::ptrdiff_t>(candidates.size());
  // The outliers found that are not isolated: looked at again with what is round
  // them beyond their nearest neighbours (rare: a hash grid of the cells round
  // them, one pass over the points).
  std::vector<std::ptrdiff_t> near;
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> around;
  for (std::ptrdiff_t i = 0; i < n; ++i)
    if (sheets && verdicts[i] == Verdict::OUTLIER) {
      const int p = candidates[i];
      near.push_back(i);
      centres.push_back(points[p]);
      around.push_back(aroundSpacing(lists[p], hoods.near[p], hoods));
    }
  const double cell =
      near.empty() ? 0.0
                   : COMPANION_REACH * *std::max_element(around.begin(), around.end());
  if (cell > 0.0 && std::isfinite(cell)) {
    const LocalGrid grid(points, centres, cell);
    for (std::size_t j = 0; j < near.size(); ++j) {
      const int p = candidates[near[j]];
      if (onSheetOfItsOwn(points, lists[p], p, hoods, around[j], grid))
        verdicts[near[j]] = Verdict::SURFACE;
    }
  }
  std::vector<int> outliers;
  for (std::ptrdiff_t i = 0; i < n; ++i)
    if (verdicts[i] != Verdict::SURFACE)
      outliers.push_back(candidates[i]);
  return outliers;
}

/** Judge the \a candidates (isOutlier()) in parallel; returns the outliers
 * confirmed (confirmOutliers()). */
std::vector<int>
findOutliers(const std::vector<Eigen::Vector3d>& points,
             const std::vector<std::array<int, NEAREST>>& lists,
             const Neighbourhoods& hoods,
             const std::vector<int>& candidates,
             bool sheets,
             int threads)
{
  const auto n = static_cast<std::ptrdiff_t>(candidates.size());
  std::vector<Verdict> verdicts(n);
#pragma omp parallel for num_threads(threads) schedule(static, 4096)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const int p = candidates[i];
    const Moments moments(points.data(), points[p], lists[p].data(), hoods.near[p]);
    verdicts[i] = isOutlier(points, lists[p], p, hoods, moments);
  }
  return confirmOutliers(points, lists, hoods, candidates, std::move(verdicts), sheets);
}

} // namespace

NoiseAnalysis
analyzeNoise(const std::vector<Eigen::Vector3d>& points,
             const std::vector<std::array<int, NEAREST>>& nearest,
             int threads,
             const std::vector<std::uint8_t>& counted,
             bool not_noise,
             const std::vector<double>& mean_spacing)
{
  const auto n = static_cast<std::ptrdiff_t>(points.size());
  NoiseAnalysis out;
  out.level.assign(n, 0.0f);
  out.outlier.assign(n, 0);
  Neighbourhoods hoods(n);
  const bool known = mean_spacing.size() == points.size();
#pragma omp parallel for num_threads(threads) schedule(static, 4096)
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    const int v = static_cast<int>(p);
    describe(points,
             nearest[p],
             v,
             known ? mean_spacing[p] : spacingOf(points, nearest[p], v),
             hoods);
  }
  // Each point's level and its first verdict from one reading of its neighbours
  // (the verdict needs their spacings, all described first).
  std::vector<Verdict> verdicts(n, Verdict::SURFACE);
#pragma omp parallel for num_threads(threads) schedule(static, 4096)
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    const int k = hoods.near[p];
    if (k < 3)
      continue;
    const int* list = nearest[p].data();
    const Moments moments(points.data(), points[p], list, k);
    const Jet jet(points.data(), points[p], list, k, moments, true);
    out.level[p] = static_cast<float>(noiseLevel(jet));
    // The plane of the level's jet is the neighbours' with p: the direction of
    // the outlier test's bound, which then needs no adjugate (0.49 -> 0.46 s).
    verdicts[p] = isOutlier(points,
                            nearest[p],
                            static_cast<int>(p),
                            hoods,
                            moments,
                            jet.planar() ? &jet.normal() : nullptr);
  }
  if (counted.empty())
    out.cloud_level = median(out.level);
  else {
    std::vector<float> level;
    for (std::ptrdiff_t p = 0; p < n; ++p)
      if (counted[p])
        level.push_back(out.level[p]);
    out.cloud_level = median(std::move(level));
  }
  std::vector<int> all(n);
  for (std::ptrdiff_t p = 0; p < n; ++p)
    all[p] = static_cast<int>(p);
  const bool sheets = not_noise || out.cloud_level <= SHEET_NOISE_LEVEL;
  std::vector<int> found =
      confirmOutliers(points, nearest, hoods, all, std::move(verdicts), sheets);
  std::vector<int>().swap(all);

  // Outliers next to each other hide one another: they are looked for again among
  // the neighbours that are not outliers, until no new one is found. A point is
  // judged again only if its inputs changed: its list lost an outlier, or a near
  // neighbour's did (its spacing changed); the others would be judged as before.
  std::vector<std::array<int, NEAREST>> lists;
  for (int round = 1; round < OUTLIER_ROUNDS && !found.empty(); ++round) {
    for (const int p : found)
      out.outlier[p] = 1;
    if (lists.empty())
      lists = nearest;
    // The points whose lists hold a new outlier: their lists lose it and their
    // neighbourhoods are described again.
    std::vector<std::uint8_t> fresh(n, 0), dirty(n, 0);
    for (const int p : found)
      fresh[p] = 1;
#pragma omp parallel for num_threads(threads) schedule(static, 4096)
    for (std::ptrdiff_t p = 0; p < n; ++p) {
      auto& list = lists[p];
      if (out.outlier[p] || std::none_of(list.begin(), list.end(), [&](int q) {
            return q >= 0 && fresh[q];
          }))
        continue;
      const auto last = std::remove_if(
          list.begin(), list.end(), [&](int q) { return q < 0 || out.outlier[q]; });
      std::fill(last, list.end(), -1);
      const int v = static_cast<int>(p);
      describe(points, list, v, spacingOf(points, list, v), hoods);
      dirty[p] = 1;
    }
    // Then the points whose near neighbours' spacing changed.
    std::vector<int> candidates;
    for (std::ptrdiff_t p = 0; p < n; ++p) {
      if (out.outlier[p])
        continue;
      bool judge = dirty[p] != 0;
      for (int i = 0; i < hoods.near[p] && !judge; ++i)
        judge = dirty[lists[p][i]] != 0;
      if (judge)
        candidates.push_back(static_cast<int>(p));
    }
    found = findOutliers(points, lists, hoods, candidates, sheets, threads);
  }
  for (const int p : found)
    out.outlier[p] = 1;
  out.outliers = std::count(out.outlier.begin(), out.outlier.end(), 1);
  return out;
}

double
displacementKurtosis(const std::vector<Eigen::Vector3d>& before,
                     const std::vector<Eigen::Vector3d>& after,
                     const std::vector<std::uint8_t>& outlier)
{
  double m2 = 0.0, m4 = 0.0;
  std::size_t count = 0;
  for (std::size_t v = 0; v < before.size(); ++v) {
    if (!outlier.empty() && outlier[v])
      continue;
    const double d2 = (after[v] - before[v]).squaredNorm();
    m2 += d2;
    m4 += d2 * d2;
    ++count;
  }
  if (count == 0 || m2 <= 0.0)
    return 0.0;
  m2 /= static_cast<double>(count);
  m4 /= static_cast<double>(count);
  return m4 / (m2 * m2);
}

double
cloudNoiseLevel(const std::vector<Eigen::Vector3d>& points,
                const std::vector<std::array<int, NEAREST>>& nearest,
                const std::vector<std::uint8_t>& outlier,
                int threads,
                const std::vector<std::uint8_t>& counted)
{
  const auto samples = static_cast<std::ptrdiff_t>(
      (points.size() + RECHECK_STRIDE - 1) / RECHECK_STRIDE);
  std::vector<float> level(samples, std::numeric_limits<float>::quiet_NaN());
#pragma omp parallel for num_threads(threads) schedule(static, 1024)
  for (std::ptrdiff_t i = 0; i < samples; ++i) {
    const int p = static_cast<int>(i * RECHECK_STRIDE);
    if ((!outlier.empty() && outlier[p]) || (!counted.empty() && !counted[p]))
      continue;
    std::array<int, NEAREST> list;
    int c = 0;
    for (const int q : nearest[p])
      if (q >= 0 && (outlier.empty() || !outlier[q]))
        list[c++] = q;
    std::fill(list.begin() + c, list.end(), -1);
    const int k = nearNeighbours(points, list, p, spacingOf(points, list, p));
    if (k >= 3)
      level[i] = static_cast<float>(
          noiseLevel(Jet(points.data(), points[p], list.data(), k, true)));
  }
  level.erase(
      std::remove_if(level.begin(), level.end(), [](float l) { return std::isnan(l); }),
      level.end());
  return median(level);
}

double
medianPoleHeight(const VoronoiCells& cells,
                 const std::vector<double>& mean_spacing,
                 const std::vector<std::uint8_t>& outlier,
                 const std::vector<std::uint8_t>& counted)
{
  std::vector<double> height;
  height.reserve(cells.height_plus.size());
  for (std::size_t v = 0; v < cells.height_plus.size(); ++v) {
    if ((!outlier.empty() && outlier[v]) || (!counted.empty() && !counted[v]))
      continue;
    const double h = cells.height_plus[v] / mean_spacing[v];
    if (std::isfinite(h))
      height.push_back(h);
  }
  return median(std::move(height));
}

std::vector<Eigen::Vector3d>
smoothPoints(const std::vector<Eigen::Vector3d>& points,
             const std::vector<std::array<int, NEAREST>>& nearest,
             const std::vector<std::uint8_t>& outlier,
             int iterations,
             int threads)
{
  const auto n = static_cast<std::ptrdiff_t>(points.size());
  const auto is_outlier = [&](int q) { return !outlier.empty() && outlier[q]; };
  // The neighbourhoods: the K nearest of the two-ring, by distance, then id.
  constexpr int K = SMOOTHING_NEIGHBOURS;
  detail::LargeVector<int> neighbours(static_cast<std::size_t>(n) * K, -1);
  detail::LargeVector<int> size(n, 0);
  detail::forEachRange(
      n, detail::partsFor(n, threads), [&](std::size_t begin, std::size_t end, int) {
        TwoRing ring(points, nearest, outlier);
        for (std::size_t p = begin; p < end; ++p)
          if (!is_outlier(static_cast<int>(p)))
            size[p] = ring.gather(static_cast<int>(p), K, &neighbours[p * K]);
      });

  // Each round projects the previous round's points; the last writes the result.
  std::vector<Eigen::Vector3d> result(points.size());
  detail::LargeVector<Eigen::Vector3d> scratch(iterations > 1 ? points.size() : 0);
  const Eigen::Vector3d* from = points.data();
  for (int it = 0; it < iterations; ++it) {
    Eigen::Vector3d* const to =
        (iterations - it) % 2 == 1 ? result.data() : scratch.data();
#pragma omp parallel for num_threads(threads) schedule(static, 4096)
    for (std::ptrdiff_t p = 0; p < n; ++p)
      to[p] = Jet(from, from[p], &neighbours[p * K], size[p], true).project(from[p]);
    from = to;
  }
  return result;
}

} // namespace cocone
} // namespace pcl
