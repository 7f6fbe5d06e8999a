/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Stable radix sort by a 64-bit key (not installed).
 */

#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Sort items by their member `key` (std::uint64_t), stably: items with equal keys
 * keep their order. Edge keys of a triangle list are sorted this way many times per
 * reconstruction, where std::sort's comparisons dominated. */
template <typename Item>
void
radixSortByKey(std::vector<Item>& items)
{
  if (items.size() < 2)
    return;
  std::uint64_t all = 0;
  for (const auto& it : items)
    all |= it.key;
  std::vector<Item> buffer(items.size());
  for (int shift = 0; shift < 64; shift += 16) {
    if (((all >> shift) & 0xffff) == 0)
      continue; // every key has zeros in these bits
    std::vector<std::size_t> count(65537, 0);
    for (const auto& it : items)
      ++count[((it.key >> shift) & 0xffff) + 1];
    for (std::size_t d = 1; d < count.size(); ++d)
      count[d] += count[d - 1];
    for (const auto& it : items)
      buffer[count[(it.key >> shift) & 0xffff]++] = it;
    items.swap(buffer);
  }
}

} // namespace detail
} // namespace cocone
} // namespace pcl
