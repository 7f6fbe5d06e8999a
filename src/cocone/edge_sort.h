/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The edge incidences of a triangle list, grouped by edge (not installed).
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Triangle of a grouped incidence word (see groupEdgeIncidences()). */
inline int
incidenceTriangle(std::uint64_t word)
{
  return static_cast<int>((word & 0xffffffffu) >> 2);
}

/** Corner k of a grouped incidence word: the edge runs from corner k to k + 1. */
inline int
incidenceCorner(std::uint64_t word)
{
  return static_cast<int>(word & 3u);
}

/** The incidences of the edges of \a triangles grouped by edge. Incidence (t, k) is
 * the edge from triangles[t][k] to triangles[t][(k + 1) % 3], packed as (higher end
 * point << 32 | t << 2 | k). A counting sort on the lower end point, then insertion
 * sorts inside its buckets, which hold a handful of incidences each: one scattering
 * pass. Within an edge the incidences are in triangle order.
 * \param[out] edges the distinct edges, end points ascending, by lower then higher
 * \param[out] first per edge e, its incidences [first[e], first[e + 1]) of the result
 */
inline std::vector<std::uint64_t>
groupEdgeIncidences(const std::vector<Triangle>& triangles,
                    std::vector<std::array<int, 2>>& edges,
                    std::vector<std::size_t>& first)
{
  int highest = -1;
  for (const auto& t : triangles)
    highest = std::max({highest, t[0], t[1], t[2]});
  std::vector<std::uint32_t> start(static_cast<std::size_t>(highest) + 2, 0);
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k)
      ++start[std::min(t[k], t[(k + 1) % 3]) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint64_t> word(3 * triangles.size());
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (std::uint64_t k = 0; k < 3; ++k) {
        const std::uint64_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
        word[fill[std::min(a, b)]++] = std::max(a, b) << 32 | t << 2 | k;
      }
  }
  std::size_t count = 0;
  for (std::size_t v = 0; v + 1 < start.size(); ++v) {
    for (std::size_t i = start[v] + 1; i < start[v + 1]; ++i) {
      const std::uint64_t w = word[i];
      std::size_t j = i;
      for (; j > start[v] && word[j - 1] > w; --j)
        word[j] = word[j - 1];
      word[j] = w;
    }
    for (std::size_t i = start[v]; i < start[v + 1]; ++i)
      count += i == start[v] || word[i] >> 32 != word[i - 1] >> 32;
  }
  edges.clear();
  edges.reserve(count);
  first.clear();
  first.reserve(count + 1);
  for (std::size_t v = 0; v + 1 < start.size(); ++v)
    for (std::size_t i = start[v]; i < start[v + 1]; ++i)
      if (i == start[v] || word[i] >> 32 != word[i - 1] >> 32) {
        first.push_back(i);
        edges.push_back({static_cast<int>(v), static_cast<int>(word[i] >> 32)});
      }
  first.push_back(word.size());
  return word;
}

/** Sort \a items by the vertex ids key(item) (lexicographically; the first id below
 * \a n): a counting sort on the first id, then each bucket, a handful of items, on
 * its own. The order of std::sort by the keys where they differ, in linear time. */
template <typename T, typename Key>
void
sortByVertexIds(std::vector<T>& items, std::size_t n, const Key& key)
{
  std::vector<std::uint32_t> start(n + 1, 0);
  for (const T& x : items)
    ++start[key(x)[0] + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<T> sorted(items.size());
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (const T& x : items)
      sorted[fill[key(x)[0]]++] = x;
  }
  for (std::size_t v = 0; v < n; ++v)
    std::sort(sorted.begin() + start[v],
              sorted.begin() + start[v + 1],
              [&](const T& a, const T& b) { return key(a) < key(b); });
  items.swap(sorted);
}

} // namespace detail
} // namespace cocone
} // namespace pcl
