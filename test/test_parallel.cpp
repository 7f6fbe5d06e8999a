/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Tasks on threads (the tiles, the two scales): each task once, and an exception
 * in a task thrown to the caller, the same whatever the threads. The allocator of
 * the large arrays.
 */

#include <gtest/gtest.h>

#include "parallel.h"

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

using pcl::cocone::detail::forEachTask;
using pcl::cocone::detail::LargeVector;

TEST(Parallel, EveryTaskRunsOnce)
{
  for (const int workers : {0, 1, 2, 3, 8})
    for (const std::size_t count : {0, 1, 2, 5, 100}) {
      std::vector<std::atomic<int>> runs(count);
      forEachTask(count, workers, [&](std::size_t t) { ++runs[t]; });
      for (std::size_t t = 0; t < count; ++t)
        EXPECT_EQ(runs[t].load(), 1)
            << "task " << t << " of " << count << ", " << workers << " workers";
    }
}

TEST(Parallel, TheLowestFailingTaskIsThrownWhateverTheThreads)
{
  for (const int workers : {1, 2, 3, 8}) {
    std::vector<std::atomic<int>> runs(40);
    try {
      forEachTask(runs.size(), workers, [&](std::size_t t) {
        ++runs[t];
        if (t == 9 || t == 17 || t == 30)
          throw std::runtime_error("task " + std::to_string(t));
      });
      ADD_FAILURE() << "nothing thrown with " << workers << " workers";
    }
    catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "task 9") << workers << " workers";
    }
    for (std::size_t t = 0; t <= 9; ++t)
      EXPECT_EQ(runs[t].load(), 1) << "task " << t << ", " << workers << " workers";
    if (workers == 1) { // one thread stops at the failure
      EXPECT_EQ(runs[10].load(), 0);
    }
  }
}

TEST(Parallel, OutOfMemoryInATaskReachesTheCaller)
{
  EXPECT_THROW(forEachTask(4,
                           2,
                           [](std::size_t t) {
                             if (t == 3)
                               throw std::bad_alloc();
                           }),
               std::bad_alloc);
}

TEST(LargeAllocator, ArraysKeepTheirValuesAcrossTheMappedSize)
{
  // 40 MB: mapped on its own (32 MB or more), aligned to a huge page outside
  // AddressSanitizer; grown past its capacity, then shrunk below the mapped size.
  constexpr std::size_t n = 5000000;
  LargeVector<std::uint64_t> values(n);
  for (std::size_t i = 0; i < n; ++i)
    values[i] = i * 2654435761u;
#ifndef COCONE_UNDER_ASAN
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(values.data()) %
                pcl::cocone::detail::HUGE_PAGE,
            0u);
#endif
  values.reserve(values.capacity() + 1);
  values.push_back(7);
  values.resize(1000);
  values.shrink_to_fit();
  ASSERT_EQ(values.size(), 1000u);
  for (std::size_t i = 0; i < values.size(); ++i)
    ASSERT_EQ(values[i], i * 2654435761u) << i;
  LargeVector<std::uint64_t> copy(n, 3);
  copy.swap(values);
  EXPECT_EQ(values.size(), n);
  EXPECT_EQ(values[n - 1], 3u);
  EXPECT_EQ(copy[999], std::uint64_t{999} * 2654435761u);
}
