/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The edge incidences of a triangle list, grouped by edge (not installed).
 */

#pragma once

#include <pcl/surface/cocone/complex.h>

#include "parallel.h"

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

/** countingSort() of the corners (t, k) of \a triangles by key(triangles[t], k):
 * put(t, k, place).
 * \return per key b, where its corners begin; then the end (3 m) */
template <typename Key, typename Put>
LargeVector<std::uint32_t>
groupCorners(const std::vector<Triangle>& triangles,
             std::size_t buckets,
             int threads,
             const Key& key,
             const Put& put)
{
  return countingSort(
      3 * triangles.size(),
      buckets,
      threads,
      [&](std::size_t c) { return key(triangles[c / 3], static_cast<int>(c % 3)); },
      [&](std::size_t c, std::uint32_t place) {
        put(c / 3, static_cast<int>(c % 3), place);
      });
}

/** The incidences of the edges of \a triangles grouped by edge. Incidence (t, k) is
 * the edge from triangles[t][k] to triangles[t][(k + 1) % 3], packed as (higher end
 * point << 32 | t << 2 | k). A counting sort on the lower end point, then insertion
 * sorts inside its buckets, which hold a handful of incidences each: one scattering
 * pass. Within an edge the incidences are in triangle order. With several threads,
 * each sorts the buckets of a part of the vertices too: the same result.
 * \param[out] edges the distinct edges, end points ascending, by lower then higher
 * \param[out] first per edge e, its incidences [first[e], first[e + 1]) of the result
 */
inline LargeVector<std::uint64_t>
groupEdgeIncidences(const std::vector<Triangle>& triangles,
                    std::vector<std::array<int, 2>>& edges,
                    std::vector<std::size_t>& first,
                    int threads = 1)
{
  const std::size_t m = triangles.size();
  int highest = -1;
  for (const auto& t : triangles)
    highest = std::max({highest, t[0], t[1], t[2]});
  const std::size_t buckets = static_cast<std::size_t>(highest) + 1;
  LargeVector<std::uint64_t> word(3 * m);
  const LargeVector<std::uint32_t> start = groupCorners(
      triangles,
      buckets,
      threads,
      [](const Triangle& t, int k) { return std::min(t[k], t[(k + 1) % 3]); },
      [&](std::uint64_t t, std::uint64_t k, std::uint32_t place) {
        const std::uint64_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
        word[place] = std::max(a, b) << 32 | t << 2 | k;
      });
  const int parts = partsFor(3 * m, threads);
  // Sort the buckets of each part of the vertices, count its edges, then list them.
  const auto opens_edge = [&](std::size_t v, std::size_t i) {
    return i == start[v] || word[i] >> 32 != word[i - 1] >> 32;
  };
  std::vector<std::size_t> edges_before(parts + 1, 0);
  forEachRange(buckets, parts, [&](std::size_t begin, std::size_t end, int part) {
    std::size_t count = 0;
    for (std::size_t v = begin; v < end; ++v) {
      for (std::size_t i = start[v] + 1; i < start[v + 1]; ++i) {
        const std::uint64_t w = word[i];
        std::size_t j = i;
        for (; j > start[v] && word[j - 1] > w; --j)
          word[j] = word[j - 1];
        word[j] = w;
      }
      for (std::size_t i = start[v]; i < start[v + 1]; ++i)
        count += opens_edge(v, i);
    }
    edges_before[part + 1] = count;
  });
  std::partial_sum(edges_before.begin(), edges_before.end(), edges_before.begin());
  edges.resize(edges_before[parts]);
  first.resize(edges_before[parts] + 1);
  forEachRange(buckets, parts, [&](std::size_t begin, std::size_t end, int part) {
    std::size_t e = edges_before[part];
    for (std::size_t v = begin; v < end; ++v)
      for (std::size_t i = start[v]; i < start[v + 1]; ++i)
        if (opens_edge(v, i)) {
          first[e] = i;
          edges[e++] = {static_cast<int>(v), static_cast<int>(word[i] >> 32)};
        }
  });
  first.back() = word.size();
  return word;
}

/** Sort \a items by the vertex ids key(item) (lexicographically; the first id below
 * \a n): a counting sort on the first id, then each bucket, a handful of items, on
 * its own. The order of std::sort by the keys where they differ, in linear time, and
 * with several threads the same order.
 */
template <typename T, typename Key>
void
sortByVertexIds(std::vector<T>& items, std::size_t n, const Key& key, int threads = 1)
{
  std::vector<T> sorted(items.size());
  const LargeVector<std::uint32_t> start = countingSort(
      items.size(),
      n,
      threads,
      [&](std::size_t i) { return key(items[i])[0]; },
      [&](std::size_t i, std::uint32_t place) { sorted[place] = items[i]; });
  forEachRange(
      n, partsFor(items.size(), threads), [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t v = begin; v < end; ++v)
          std::sort(sorted.begin() + start[v],
                    sorted.begin() + start[v + 1],
                    [&](const T& a, const T& b) { return key(a) < key(b); });
      });
  items.swap(sorted);
}

} // namespace detail
} // namespace cocone
} // namespace pcl
