/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/hole_refinement.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/fair.h>
#include <CGAL/Polygon_mesh_processing/refine.h>
#include <CGAL/Surface_mesh.h>

#include "caller_ids.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace pcl {
namespace cocone {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

/** Rings of the mesh round a patch that the fairing holds fixed: two fix the
 * patch's position and its tangent plane at the rim (bilaplacian fairing). */
constexpr int FIXED_RINGS = 2;

std::uint64_t
directedKey(int a, int b)
{
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

/** The triangles at each vertex (compressed rows). */
struct Stars {
  std::vector<std::size_t> begin;
  std::vector<int> triangle;

  Stars(const std::vector<Triangle>& triangles, std::size_t vertices)
  : begin(vertices + 1, 0)
  {
    for (const auto& t : triangles)
      for (const int v : t)
        ++begin[static_cast<std::size_t>(v) + 1];
    for (std::size_t v = 0; v < vertices; ++v)
      begin[v + 1] += begin[v];
    triangle.resize(begin[vertices]);
    std::vector<std::size_t> at(begin.begin(), begin.end() - 1);
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (const int v : triangles[t])
        triangle[at[static_cast<std::size_t>(v)]++] = static_cast<int>(t);
  }

  template <typename F>
  void
  forStar(int v, const F& f) const
  {
    for (std::size_t i = begin[static_cast<std::size_t>(v)];
         i < begin[static_cast<std::size_t>(v) + 1];
         ++i)
      f(triangle[i]);
  }
};

/** The triangles \a rim bounds on the side away from the mesh it had (the rim has
 * that mesh on its left, so the patch runs along each rim edge backwards); empty
 * if they are no disk within \a limit triangles that the rim closes off. Each
 * triangle reached is marked \a stamp in \a mark (one entry per triangle). */
std::vector<int>
patchOf(const std::vector<int>& rim,
        const std::vector<Triangle>& triangles,
        const std::unordered_map<std::uint64_t, int>& by_edge,
        std::size_t limit,
        std::vector<int>& mark,
        int stamp)
{
  std::vector<std::uint64_t> rim_edges;
  for (std::size_t i = 0; i < rim.size(); ++i) {
    const int a = rim[i], b = rim[(i + 1) % rim.size()];
    rim_edges.push_back(directedKey(std::min(a, b), std::max(a, b)));
  }
  std::sort(rim_edges.begin(), rim_edges.end());
  std::vector<int> patch, stack;
  const auto visit = [&](int t) {
    if (mark[static_cast<std::size_t>(t)] != stamp) {
      mark[static_cast<std::size_t>(t)] = stamp;
      patch.push_back(t);
      stack.push_back(t);
    }
  };
  for (std::size_t i = 0; i < rim.size(); ++i) {
    const auto it = by_edge.find(directedKey(rim[(i + 1) % rim.size()], rim[i]));
    if (it == by_edge.end())
      return {}; // the rim is no longer closed on that side
    visit(it->second);
  }
  while (!stack.empty() && patch.size() <= limit) {
    const Triangle& t = triangles[static_cast<std::size_t>(stack.back())];
    stack.pop_back();
    for (int c = 0; c < 3; ++c) {
      const int a = t[c], b = t[(c + 1) % 3];
      if (std::binary_search(rim_edges.begin(),
                             rim_edges.end(),
                             directedKey(std::min(a, b), std::max(a, b))))
        continue;
      const auto it = by_edge.find(directedKey(b, a));
      if (it == by_edge.end())
        return {}; // a border inside: the rim closes nothing off
      visit(it->second);
    }
  }
  if (patch.size() > limit)
    return {};
  return patch;
}

} // namespace

HoleRefinement
refineFilledHoles(Result& result, int first_id)
{
  HoleRefinement out;
  if (result.filled_holes.empty() || result.triangles.empty())
    return out;
  const std::size_t vertices = result.positions.size();
  std::unordered_map<int, int> vertex_of_id;
  for (const auto& rim : result.filled_holes)
    for (const int id : rim)
      vertex_of_id.emplace(id, -1);
  for (std::size_t v = 0; v < result.representative.size(); ++v) {
    const auto it = vertex_of_id.find(result.representative[v]);
    if (it != vertex_of_id.end())
      it->second = static_cast<int>(v);
  }
  std::unordered_map<std::uint64_t, int> by_edge;
  by_edge.reserve(3 * result.triangles.size());
  for (std::size_t t = 0; t < result.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c)
      by_edge.emplace(
          directedKey(result.triangles[t][c], result.triangles[t][(c + 1) % 3]),
          static_cast<int>(t));
  const Stars stars(result.triangles, vertices);

  std::vector<std::uint8_t> dead(result.triangles.size(), 0);
  std::vector<Triangle> added_triangles;
  std::vector<Eigen::Vector3d> added_positions;
  // Per triangle: the hole whose patch or rings it is in (patchOf() marks).
  std::vector<int> local_of(vertices, -1), in_local(result.triangles.size(), -1);
  for (std::size_t h = 0; h < result.filled_holes.size(); ++h) {
    std::vector<int> rim;
    for (const int id : result.filled_holes[h])
      rim.push_back(vertex_of_id.at(id));
    if (std::find(rim.begin(), rim.end(), -1) != rim.end()) {
      ++out.kept;
      continue;
    }
    // A patch has about as many triangles as its rim has edges, more where it
    // replaced a band of the mesh (fillHolesFromMesh()).
    const int stamp = static_cast<int>(h);
    const std::vector<int> patch =
        patchOf(rim, result.triangles, by_edge, 8 * rim.size() + 64, in_local, stamp);
    bool usable = !patch.empty();
    for (const int t : patch)
      usable = usable && !dead[static_cast<std::size_t>(t)];
    if (!usable) {
      ++out.kept;
      continue;
    }
    // The patch and the rings round it, as a CGAL mesh.
    std::vector<int> faces = patch, ring_vertices;
    for (const int t : patch)
      for (const int v : result.triangles[static_cast<std::size_t>(t)])
        ring_vertices.push_back(v);
    for (int ring = 0; ring < FIXED_RINGS; ++ring) {
      const std::size_t from = faces.size();
      std::sort(ring_vertices.begin(), ring_vertices.end());
      ring_vertices.erase(std::unique(ring_vertices.begin(), ring_vertices.end()),
                          ring_vertices.end());
      for (const int v : ring_vertices)
        stars.forStar(v, [&](int t) {
          if (in_local[static_cast<std::size_t>(t)] != stamp) {
            in_local[static_cast<std::size_t>(t)] = stamp;
            faces.push_back(t);
          }
        });
      ring_vertices.clear();
      for (std::size_t f = from; f < faces.size(); ++f)
        for (const int v : result.triangles[static_cast<std::size_t>(faces[f])])
          ring_vertices.push_back(v);
    }
    Mesh mesh;
    std::vector<int> global; // per local vertex
    std::vector<Mesh::Face_index> patch_faces;
    bool built = true;
    for (std::size_t f = 0; f < faces.size() && built; ++f) {
      std::array<Mesh::Vertex_index, 3> corners;
      const Triangle& t = result.triangles[static_cast<std::size_t>(faces[f])];
      for (int c = 0; c < 3; ++c) {
        const auto v = static_cast<std::size_t>(t[c]);
        if (local_of[v] < 0) {
          local_of[v] = static_cast<int>(global.size());
          global.push_back(t[c]);
          const Eigen::Vector3d& p = result.positions[v];
          mesh.add_vertex(Kernel::Point_3(p.x(), p.y(), p.z()));
        }
        corners[c] = Mesh::Vertex_index(static_cast<Mesh::size_type>(local_of[v]));
      }
      const Mesh::Face_index face = mesh.add_face(corners[0], corners[1], corners[2]);
      built = face != Mesh::null_face();
      if (f < patch.size())
        patch_faces.push_back(face);
    }
    for (const int v : global)
      local_of[static_cast<std::size_t>(v)] = -1;
    std::vector<Mesh::Face_index> new_faces;
    std::vector<Mesh::Vertex_index> new_vertices;
    if (built)
      PMP::refine(mesh,
                  patch_faces,
                  std::back_inserter(new_faces),
                  std::back_inserter(new_vertices),
                  CGAL::parameters::density_control_factor(std::sqrt(2.0)));
    if (!built || new_vertices.empty() || !PMP::fair(mesh, new_vertices)) {
      ++out.kept;
      continue;
    }
    // The refined patch replaces the first one: the faces refine() made or changed,
    // which are the patch's (it neither splits nor flips an edge of the rim).
    for (const int t : patch)
      dead[static_cast<std::size_t>(t)] = 1;
    std::vector<int> id_of(mesh.number_of_vertices(), -1);
    for (std::size_t i = 0; i < global.size(); ++i)
      id_of[i] = global[i];
    for (const Mesh::Vertex_index v : new_vertices) {
      id_of[static_cast<std::size_t>(v)] =
          static_cast<int>(vertices + added_positions.size());
      const Kernel::Point_3& p = mesh.point(v);
      added_positions.emplace_back(p.x(), p.y(), p.z());
    }
    patch_faces.insert(patch_faces.end(), new_faces.begin(), new_faces.end());
    for (const Mesh::Face_index f : patch_faces) {
      Triangle t;
      int c = 0;
      for (const Mesh::Vertex_index v : mesh.vertices_around_face(mesh.halfedge(f)))
        t[c++] = id_of[static_cast<std::size_t>(v)];
      added_triangles.push_back(t);
    }
    ++out.holes;
    out.vertices += new_vertices.size();
  }
  if (out.holes == 0)
    return out;

  // The mesh with the refined patches; the added vertices after the input's.
  std::vector<Triangle> triangles;
  triangles.reserve(result.triangles.size() + added_triangles.size());
  for (std::size_t t = 0; t < result.triangles.size(); ++t)
    if (!dead[t])
      triangles.push_back(result.triangles[t]);
  triangles.insert(triangles.end(), added_triangles.begin(), added_triangles.end());
  result.triangles = std::move(triangles);
  const std::size_t added = added_positions.size();
  result.positions.insert(
      result.positions.end(), added_positions.begin(), added_positions.end());
  for (std::size_t k = 0; k < added; ++k)
    result.representative.push_back(first_id + static_cast<int>(k));
  result.boundary.resize(vertices + added, 0);
  result.umbrella_failed.resize(vertices + added, 0);
  std::vector<Eigen::Vector3d> facing(added, Eigen::Vector3d::Zero());
  for (const Triangle& t : added_triangles) {
    const Eigen::Vector3d n =
        (result.positions[t[1]] - result.positions[t[0]])
            .cross(result.positions[t[2]] - result.positions[t[0]]);
    for (const int v : t)
      if (static_cast<std::size_t>(v) >= vertices)
        facing[static_cast<std::size_t>(v) - vertices] += n;
  }
  for (const auto& n : facing)
    result.normals.push_back(n.normalized());
  result.added_vertices += added;
  detail::polygonsFromTriangles(result);
  return out;
}

} // namespace cocone
} // namespace pcl
