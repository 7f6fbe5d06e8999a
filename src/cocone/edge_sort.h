/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Stable sort of edge records by their edge key (not installed).
 */

#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Sort items by their member `key`, an edge key (lower vertex id << 32 | higher
 * vertex id), stably. A counting sort on the lower id, then insertion sorts inside
 * its buckets, which hold a handful of items each. Edge keys of a triangle list are
 * sorted this way several times per reconstruction: one scattering pass, where a
 * radix sort took four and std::sort's comparisons dominated. */
template <typename Item>
void
sortByEdgeKey(std::vector<Item>& items)
{
  if (items.size() < 2)
    return;
  std::uint64_t highest = 0;
  for (const auto& it : items)
    highest = std::max(highest, it.key >> 32);
  std::vector<std::size_t> first(highest + 2, 0);
  for (const auto& it : items)
    ++first[(it.key >> 32) + 1];
  for (std::size_t v = 1; v < first.size(); ++v)
    first[v] += first[v - 1];
  std::vector<Item> sorted(items.size());
  {
    std::vector<std::size_t> fill(first.begin(), first.end() - 1);
    for (const auto& it : items)
      sorted[fill[it.key >> 32]++] = it;
  }
  for (std::size_t v = 0; v + 1 < first.size(); ++v)
    for (std::size_t i = first[v] + 1; i < first[v + 1]; ++i) {
      const Item it = sorted[i];
      std::size_t j = i;
      for (; j > first[v] && sorted[j - 1].key > it.key; --j)
        sorted[j] = sorted[j - 1];
      sorted[j] = it;
    }
  items.swap(sorted);
}

} // namespace detail
} // namespace cocone
} // namespace pcl
