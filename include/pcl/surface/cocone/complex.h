/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {

using Triangle = std::array<int, 3>;

/** The corner of \a t that is neither \a a nor \a b (two of its corners). */
inline int
thirdCorner(const Triangle& t, int a, int b)
{
  return t[0] != a && t[0] != b ? t[0] : t[1] != a && t[1] != b ? t[1] : t[2];
}

/** \brief A triangle complex with its edges and incidences, as flat arrays.
 *
 * Stages 5-7 (umbrella check, pruning, walk) work on the candidate triangles
 * through this structure. Of an edge of two triangles, whether they make an angle
 * below pi / 2 is kept; at the rare edges of more, their angles about the edge, which
 * give their circular order, are computed when ISSHARP asks.
 */
class TriangleComplex {
public:
  /** \param[in] points vertex positions
   *  \param[in] triangles the triangles (any vertex order; duplicates not allowed)
   *  \param[in] threads threads for the angles about the edges */
  TriangleComplex(const std::vector<Eigen::Vector3d>& points,
                  std::vector<Triangle> triangles,
                  int threads = 1);

  /** Number of triangles. */
  std::size_t
  numTriangles() const
  {
    return triangles_.size();
  }

  /** Number of edges. */
  std::size_t
  numEdges() const
  {
    return edges_.size();
  }

  /** Vertex positions. */
  const std::vector<Eigen::Vector3d>&
  points() const
  {
    return points_;
  }

  /** Vertex ids of triangle t, ascending. */
  const Triangle&
  triangle(int t) const
  {
    return triangles_[t];
  }

  /** Edge ids of triangle t; edge k is opposite vertex k. */
  const std::array<int, 3>&
  triangleEdges(int t) const
  {
    return triangle_edges_[t];
  }

  /** End points of edge e, ascending. */
  const std::array<int, 2>&
  edge(int e) const
  {
    return edges_[e];
  }

  /** Range [first, last) of incidences of edge e in edgeTriangle(). */
  std::size_t
  edgeBegin(int e) const
  {
    return edge_first_[e];
  }

  /** End of the incidences of edge e (see edgeBegin()). */
  std::size_t
  edgeEnd(int e) const
  {
    return edge_first_[e + 1];
  }

  /** Triangle of incidence i. */
  int
  edgeTriangle(std::size_t i) const
  {
    return edge_triangles_[i];
  }

  /** Range of triangles incident to vertex v in vertexTriangle(). */
  std::size_t
  vertexBegin(int v) const
  {
    return vertex_first_[v];
  }

  /** End of the triangles of vertex v (see vertexBegin()). */
  std::size_t
  vertexEnd(int v) const
  {
    return vertex_first_[v + 1];
  }

  /** Triangle of vertex incidence i. */
  int
  vertexTriangle(std::size_t i) const
  {
    return vertex_triangles_[i];
  }

  /** For an edge of exactly two triangles: whether they make an angle below pi / 2
   * (their directions from the edge, orthogonal to it, have a positive dot product).
   */
  bool
  acutePair(int e) const
  {
    return acute_pair_[e] != 0;
  }

  /** ISSHARP: edge e is sharp among the triangles for which alive(t) is true if it has
   * exactly one, or two consecutive ones (in circular order) with an angular gap of
   * more than 3 pi / 2 between them. No triangle: not sharp. */
  template <typename Alive>
  bool
  isSharp(int e, const Alive& alive) const;

private:
  /** The apex of the triangle of incidence i of edge e, from the edge's first end. */
  Eigen::Vector3d
  apexFrom(int e, std::size_t i) const;

  /** The angles about edge e, in [-pi, pi] in a frame of the edge, of its
   * incidences in order. */
  void
  edgeAngles(int e, std::vector<double>& angles) const;

  const std::vector<Eigen::Vector3d>& points_;
  std::vector<Triangle> triangles_;
  std::vector<std::array<int, 3>> triangle_edges_;
  std::vector<std::array<int, 2>> edges_;
  std::vector<std::size_t> edge_first_;
  std::vector<int> edge_triangles_;
  /** Per edge of two triangles: they make an angle below pi / 2. */
  std::vector<std::uint8_t> acute_pair_;
  std::vector<std::size_t> vertex_first_;
  std::vector<int> vertex_triangles_;
};

/** \brief Largest circular gap between angles in [-pi, pi] (radians): 2 pi for
 * fewer than two. */
double
largestAngularGap(const std::vector<double>& angles);

/** \brief largestAngularGap() of the angles of plane directions (x, y) from the x
 * axis, as atan2 (y, x) gives them (the zero vector at angle 0), with one atan2 in all:
 * the directions are ordered and their gaps compared by a pseudo-angle. */
double
largestDirectionGap(const std::vector<Eigen::Vector2d>& directions);

template <typename Alive>
bool
TriangleComplex::isSharp(int e, const Alive& alive) const
{
  const std::size_t first = edgeBegin(e);
  if (edgeEnd(e) - first == 2) {
    // The gap between two is above 3 pi / 2 when the angle they make is below pi / 2.
    const bool a = alive(edge_triangles_[first]), b = alive(edge_triangles_[first + 1]);
    return a != b || (a && acute_pair_[e]);
  }
  thread_local std::vector<double> all, angles;
  edgeAngles(e, all);
  angles.clear();
  for (std::size_t i = first; i < edgeEnd(e); ++i)
    if (alive(edge_triangles_[i]))
      angles.push_back(all[i - first]);
  if (angles.empty())
    return false;
  if (angles.size() == 1)
    return true;
  return largestAngularGap(angles) > 1.5 * 3.14159265358979323846;
}

} // namespace cocone
} // namespace pcl
