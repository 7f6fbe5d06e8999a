/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The advancing front in a translation unit of its own: its header alone takes
 * longer to compile than the rest of the hole filling.
 */

#include <pcl/surface/cocone/hole_filling.h>
#include <pcl/surface/cocone/mesh_checks.h>
#include <pcl/surface/cocone/repair.h>

#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "cocone_neighbours.h"
#include "points.h"

#include <algorithm>
#include <array>
#include <iterator>

namespace pcl {
namespace cocone {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/** CGAL's advancing front keeps its front in a std::set of (priority, address of
 * the edge's record): where priorities tie (all its stand-by candidates share one
 * value) the heap's addresses decide which edge grows first, so its output changed
 * with what the process allocated before (another cloud, another thread count).
 * The same vertex base with the front ordered by (priority, the edge's input ids):
 * the same points give the same mesh. */
template <typename Vb = CGAL::Triangulation_vertex_base_3<Kernel>>
class FrontVertex
: public CGAL::Advancing_front_surface_reconstruction_vertex_base_3<Kernel, Vb> {
  using Base = CGAL::Advancing_front_surface_reconstruction_vertex_base_3<Kernel, Vb>;

public:
  template <typename Tds>
  struct Rebind_TDS {
    using Other = FrontVertex<typename Vb::template Rebind_TDS<Tds>::Other>;
  };
  using Base::Base;

  /** A front edge: its priority and its record (an edge of the triangulation). */
  struct Radius_ptr_type {
    typename Base::criteria first;
    typename Base::IO_edge_type* second;

    Radius_ptr_type(typename Base::criteria priority, typename Base::IO_edge_type* edge)
    : first(priority), second(edge)
    {}

    /** The edge's vertices' input ids, smaller first. */
    std::pair<std::size_t, std::size_t>
    ids() const
    {
      const auto& e = second->first.first; // (cell, i, j)
      const std::size_t a = e.first->vertex(e.second)->info();
      const std::size_t b = e.first->vertex(e.third)->info();
      return std::minmax(a, b);
    }

    friend bool
    operator<(const Radius_ptr_type& a, const Radius_ptr_type& b)
    {
      if (a.first != b.first)
        return a.first < b.first;
      // The address last: two records of one edge did not tie in any test.
      const auto ia = a.ids(), ib = b.ids();
      return ia != ib ? ia < ib : a.second < b.second;
    }
  };
};

/** CGAL's advancing front cell with a time stamp: the triangulation then orders
 * cell handles by creation, not by address, where it reports each facet once
 * (from the cell that compares less), and so the facet the front starts from. */
template <typename Cb = CGAL::Delaunay_triangulation_cell_base_3<Kernel>>
class FrontCell
: public CGAL::Advancing_front_surface_reconstruction_cell_base_3<Kernel, Cb> {
  using Base = CGAL::Advancing_front_surface_reconstruction_cell_base_3<Kernel, Cb>;
  std::size_t time_stamp_ = static_cast<std::size_t>(-1);

public:
  template <typename Tds>
  struct Rebind_TDS {
    using Other = FrontCell<typename Cb::template Rebind_TDS<Tds>::Other>;
  };
  using Base::Base;
  using Has_timestamp = CGAL::Tag_true;

  std::size_t
  time_stamp() const
  {
    return time_stamp_;
  }

  void
  set_time_stamp(const std::size_t& stamp)
  {
    time_stamp_ = stamp;
  }
};

using FrontTriangulation = CGAL::Delaunay_triangulation_3<
    Kernel,
    CGAL::Triangulation_data_structure_3<FrontVertex<>, FrontCell<>>>;

/** CGAL's advancing front over the listed vertices, oriented. */
std::vector<Triangle>
advancingFront(const std::vector<Eigen::Vector3d>& points,
               const std::vector<int>& vertex,
               int threads)
{
  std::vector<Triangle> triangles;
  if (vertex.size() < 4)
    return triangles;
  // As CGAL::advancing_front_surface_reconstruction() with its default parameters,
  // on FrontTriangulation.
  std::vector<std::pair<Kernel::Point_3, std::size_t>> p;
  p.reserve(vertex.size());
  for (std::size_t i = 0; i < vertex.size(); ++i) {
    const Eigen::Vector3d& q = points[vertex[i]];
    p.emplace_back(Kernel::Point_3(q.x(), q.y(), q.z()), i);
  }
  FrontTriangulation dt(p.begin(), p.end());
  CGAL::Advancing_front_surface_reconstruction<FrontTriangulation> front(dt);
  front.run();
  std::vector<std::array<std::size_t, 3>> facets;
  CGAL::write_triple_indices(std::back_inserter(facets), front);
  triangles.reserve(facets.size());
  for (const auto& f : facets)
    triangles.push_back({vertex[f[0]], vertex[f[1]], vertex[f[2]]});
  // The advancing front's output is a manifold but not always oriented throughout.
  RepairCounts counts;
  repairManifold(points, triangles, counts, threads);
  return triangles;
}

/** A piece with no free samples round it whose triangles' vector area is at least
 * this share of their area is a sheet facing one way: the advancing front over its
 * vertices alone closes it never (the other side would need vertices of its own).
 * Measured over the tests, the quality table, the closed meshes and the range scans:
 * every piece the advancing front closed had a share of 0.05 or less, and free
 * samples; those without free samples that it did not close had 0.43 to 0.98, as
 * had the tiles of a saddle, whose cut loop left the whole tile (128,000 points, 3
 * to 4 s each) to it. */
constexpr double ONE_SIDED_SHARE = 0.5;

/** analyzeMesh() of triangles on the listed vertices (ascending), in time of their
 * number. */
MeshTopology
analyzeOn(const std::vector<int>& vertex, std::vector<Triangle> triangles)
{
  for (auto& t : triangles)
    for (int& v : t)
      v = static_cast<int>(std::lower_bound(vertex.begin(), vertex.end(), v) -
                           vertex.begin());
  return analyzeMesh(triangles, vertex.size());
}

} // namespace

std::vector<Triangle>
advancingFrontMesh(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<int>& island,
                   int threads)
{
  std::vector<std::vector<int>> vertices;
  for (std::size_t v = 0; v < island.size(); ++v)
    if (island[v] >= 0) {
      if (static_cast<std::size_t>(island[v]) >= vertices.size())
        vertices.resize(island[v] + 1);
      vertices[island[v]].push_back(static_cast<int>(v));
    }
  std::vector<Triangle> triangles;
  for (const std::vector<int>& vertex : vertices) {
    const std::vector<Triangle> part = advancingFront(points, vertex, threads);
    triangles.insert(triangles.end(), part.begin(), part.end());
  }
  return triangles;
}

HoleFilling
closePiecesWithAdvancingFront(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<double>& spacing,
                              const std::vector<CoconeTriangle>& cocone_triangles,
                              std::vector<Triangle>& triangles,
                              EdgeIncidences& incidences,
                              std::vector<std::vector<int>>& loops,
                              double reach,
                              std::size_t max_edges,
                              const std::vector<std::uint8_t>& true_border,
                              int threads)
{
  HoleFilling out;
  if (loops.empty())
    return out;
  const auto n = static_cast<int>(points.size());
  // The pieces (components through shared edges) and each one's vertices and Euler
  // characteristic; a vertex is in one piece at most (one fan each).
  std::size_t pieces = 0;
  const std::vector<int> piece_of_triangle =
      triangleComponents(incidences, triangles.size(), &pieces);
  std::vector<int> piece(n, -1);
  std::vector<long> euler(pieces, 0);
  std::vector<std::size_t> size(pieces, 0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const int p = piece_of_triangle[t];
    euler[p] += 1;
    for (const int v : triangles[t])
      if (piece[v] < 0) {
        piece[v] = p;
        ++size[p];
      }
  }
  for (std::size_t e = 0; e < incidences.edges.size(); ++e)
    euler[piece[incidences.edges[e][0]]] -= 1;
  for (std::size_t p = 0; p < pieces; ++p)
    euler[p] += static_cast<long>(size[p]);
  // A candidate: a piece whose loops are all undersampled holes, the longest about
  // as large as the piece (its vertices at most the square of its edges). A piece
  // much larger than its holes, however many, closes them locally (the patches) or
  // not at all; this also bounds the advancing front's cost.
  std::vector<int> loop_piece;
  std::vector<std::size_t> longest(pieces, 0), holes(pieces, 0);
  std::vector<std::uint8_t> rejected(pieces, 0);
  for (const auto& loop : loops) {
    const int p = piece[loop[0]];
    loop_piece.push_back(p);
    longest[p] = std::max(longest[p], loop.size());
    ++holes[p];
    rejected[p] |=
        loop.size() > max_edges ||
        (!true_border.empty() &&
         std::any_of(loop.begin(), loop.end(), [&](int v) { return true_border[v]; }));
  }
  const auto square = [](std::size_t k) {
    return static_cast<double>(k) * static_cast<double>(k);
  };
  std::vector<int> candidates;
  for (std::size_t p = 0; p < pieces; ++p)
    if (holes[p] > 0 && !rejected[p] &&
        static_cast<double>(size[p]) <= square(longest[p]))
      candidates.push_back(static_cast<int>(p));
  if (candidates.empty())
    return out;
  // Each candidate's vertices, with the free samples the co-cone triangles join to
  // them, directly or through other free samples: the samples in its holes, which
  // the advancing front needs to close them.
  std::vector<int> slot(pieces, -1);
  for (std::size_t i = 0; i < candidates.size(); ++i)
    slot[candidates[i]] = static_cast<int>(i);
  std::vector<std::vector<int>> region(candidates.size());
  for (int v = 0; v < n; ++v)
    if (piece[v] >= 0 && slot[piece[v]] >= 0)
      region[slot[piece[v]]].push_back(v);
  // Each candidate's vector area and area (twice), for the one-sided test below.
  std::vector<Eigen::Vector3d> vector_area(candidates.size(), Eigen::Vector3d::Zero());
  std::vector<double> area(candidates.size(), 0.0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const int i = slot[piece_of_triangle[t]];
    if (i < 0)
      continue;
    const Triangle& c = triangles[t];
    const Eigen::Vector3d normal =
        (points[c[1]] - points[c[0]]).cross(points[c[2]] - points[c[0]]);
    vector_area[i] += normal;
    area[i] += normal.norm();
  }
  // Per vertex its free co-cone neighbours.
  const detail::CoconeNeighbours free_around = detail::coconeNeighbours(
      cocone_triangles, n, [&](int b) { return piece[b] < 0; });
  std::vector<int> reached(n, -1);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    // At most the square of the longest loop's edges, as the piece.
    const double most = square(longest[candidates[i]]);
    auto& vertices = region[i];
    for (std::size_t k = 0;
         k < vertices.size() && static_cast<double>(vertices.size()) <= most;
         ++k)
      for (std::size_t j = free_around.first[vertices[k]];
           j < free_around.first[vertices[k] + 1];
           ++j) {
        const int b = free_around.neighbour[j];
        if (reached[b] != static_cast<int>(i)) {
          reached[b] = static_cast<int>(i);
          vertices.push_back(b);
        }
      }
    if (static_cast<double>(vertices.size()) > most ||
        (vertices.size() == size[candidates[i]] &&
         vector_area[i].norm() >= ONE_SIDED_SHARE * area[i]))
      vertices.clear();
  }
  std::vector<std::uint8_t> replaced(pieces, 0), taken(n, 0);
  std::vector<Triangle> added;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const int p = candidates[i];
    std::sort(region[i].begin(), region[i].end());
    const std::vector<Triangle> front = advancingFront(points, region[i], threads);
    if (front.empty())
      continue;
    // Closed, one piece, the piece's genus: its Euler characteristic with its
    // holes capped.
    const MeshTopology theirs = analyzeOn(region[i], front);
    bool ok = theirs.manifold() && theirs.components == 1 &&
              theirs.boundary_edges == 0 &&
              theirs.euler == euler[p] + static_cast<long>(holes[p]);
    ok = ok && std::all_of(front.begin(), front.end(), [&](const Triangle& t) {
           return detail::triangleWithinReach(points, spacing, reach, t);
         });
    // A free sample closes one piece at most.
    for (const int v : region[i])
      ok = ok && !taken[v];
    if (!ok)
      continue;
    for (const int v : region[i])
      taken[v] = 1;
    replaced[p] = 1;
    added.insert(added.end(), front.begin(), front.end());
    for (std::size_t l = 0; l < loops.size(); ++l)
      if (loop_piece[l] == p)
        out.rims.push_back(loops[l]);
    out.holes += holes[p];
    out.triangles += front.size();
  }
  if (added.empty())
    return out;
  // Out with the pieces replaced, in with the advancing front's triangles.
  std::vector<std::uint8_t> drop(triangles.size(), 0);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    drop[t] = replaced[piece_of_triangle[t]];
  removeTriangles(triangles, drop, &incidences);
  const std::size_t kept = triangles.size();
  triangles.insert(triangles.end(), added.begin(), added.end());
  incidences.add(triangles, kept);
  loops = boundaryLoops(incidences, points.size());
  return out;
}

} // namespace cocone
} // namespace pcl
