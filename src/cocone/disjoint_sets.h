/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Union-find with path halving. */
struct DisjointSets {
  std::vector<int> parent;

  explicit DisjointSets(std::size_t n = 0) { reset(n); }

  /** n singletons again, reusing the storage. */
  void
  reset(std::size_t n)
  {
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), 0);
  }

  int
  find(int x)
  {
    while (parent[x] != x)
      x = parent[x] = parent[parent[x]];
    return x;
  }

  void
  unite(int a, int b)
  {
    a = find(a);
    b = find(b);
    if (a != b)
      parent[std::max(a, b)] = std::min(a, b);
  }
};

} // namespace detail
} // namespace cocone
} // namespace pcl
