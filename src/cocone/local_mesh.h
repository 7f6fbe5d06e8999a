/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <pcl/surface/cocone/complex.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** An oriented manifold mesh changed in place by a stage (the hole filling's
 * meshes, the handle cutting): triangles taken out are marked dead and the list and
 * its incidences brought up to date once, at the end (commit()); each vertex knows
 * its triangles. */
class LocalMesh {
public:
  LocalMesh(std::vector<Triangle>& triangles, std::size_t num_vertices)
  : triangles_(triangles)
  , dead_(triangles.size(), 0)
  , first_(num_vertices + 1, 0)
  , added_(num_vertices)
  , uses_(num_vertices, 0)
  {
    // The stars in compressed rows, the triangles added later in a list per vertex:
    // a stage builds this over the whole mesh for a few holes (per attempt of the
    // hole reopening), and a vector per vertex took most of that time.
    for (const auto& t : triangles)
      for (const int v : t)
        ++uses_[v];
    for (std::size_t v = 0; v < num_vertices; ++v)
      first_[v + 1] = first_[v] + static_cast<std::size_t>(uses_[v]);
    star_.resize(first_[num_vertices]);
    std::vector<std::size_t> next(first_.begin(), first_.end() - 1);
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (const int v : triangles[t])
        star_[next[v]++] = static_cast<int>(t);
  }

  const std::vector<Triangle>&
  triangles() const
  {
    return triangles_;
  }
  const std::vector<std::uint8_t>&
  dead() const
  {
    return dead_;
  }
  /** The live triangles at vertex v. */
  template <typename Body>
  void
  forStar(int v, const Body& body) const
  {
    for (std::size_t i = first_[v]; i < first_[v + 1]; ++i)
      if (!dead_[star_[i]])
        body(star_[i]);
    for (const int t : added_[v])
      if (!dead_[t])
        body(t);
  }
  /** Number of live triangles using vertex v. */
  int
  uses(int v) const
  {
    return uses_[v];
  }
  /** The live triangle that traverses the directed edge a -> b, or -1. */
  int
  traversing(int a, int b) const
  {
    int found = -1;
    forStar(a, [&](int t) {
      for (int c = 0; c < 3; ++c)
        if (triangles_[t][c] == a && triangles_[t][(c + 1) % 3] == b)
          found = t;
    });
    return found;
  }
  void
  kill(int t)
  {
    dead_[t] = 1;
    for (const int v : triangles_[t])
      --uses_[v];
  }
  /** Undo kill(t). */
  void
  revive(int t)
  {
    dead_[t] = 0;
    for (const int v : triangles_[t])
      ++uses_[v];
  }
  void
  add(const Triangle& t)
  {
    const int id = static_cast<int>(triangles_.size());
    triangles_.push_back(t);
    dead_.push_back(0);
    for (const int v : t) {
      added_[v].push_back(id);
      ++uses_[v];
    }
  }

  /** The list without its dead triangles, and \a incidences, the grouping of its
   * first \a grouped triangles, brought up to date with it: out with the triangles
   * taken out, in with those added. */
  void
  commit(std::size_t grouped, EdgeIncidences& incidences)
  {
    incidences.remove(
        std::vector<std::uint8_t>(dead_.begin(), dead_.begin() + grouped));
    std::size_t survivors = 0;
    for (std::size_t t = 0; t < grouped; ++t)
      survivors += !dead_[t];
    std::vector<Triangle> kept;
    kept.reserve(triangles_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t)
      if (!dead_[t])
        kept.push_back(triangles_[t]);
    triangles_ = std::move(kept);
    incidences.add(triangles_, survivors);
  }

private:
  std::vector<Triangle>& triangles_;
  std::vector<std::uint8_t> dead_;
  std::vector<std::size_t> first_; ///< per vertex, its first entry in star_
  std::vector<int> star_;
  std::vector<std::vector<int>> added_;
  std::vector<int> uses_;
};

} // namespace detail
} // namespace cocone
} // namespace pcl
