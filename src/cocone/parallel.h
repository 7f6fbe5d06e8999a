/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Splitting a loop among threads, tasks handed to the first thread free, a counting
 * sort on them, and sets that threads unite at once (not installed).
 */

#pragma once

#include "allocator.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <mutex>
#include <new>
#include <system_error>
#include <thread>
#include <vector>

namespace pcl {
namespace cocone {
namespace detail {

/** Parts for \a threads threads to split \a items into: some sixty thousand items a
 * part at least. */
inline int
partsFor(std::size_t items, int threads)
{
  return static_cast<int>(
      std::clamp<std::size_t>(items / 65536, 1, static_cast<std::size_t>(threads)));
}

/** Run body(begin, end, part) for the \a parts equal runs of [0, count), on up to
 * \a parts threads. A part's number is its own (per-part state can be indexed by
 * it), whatever the number of threads the system grants. std::bad_alloc in a part
 * is thrown again after all are done: an exception must not leave a parallel
 * region. */
template <typename Body>
void
forEachRange(std::size_t count, int parts, const Body& body)
{
  bool failed = false;
#pragma omp parallel num_threads(parts)
  {
#ifdef _OPENMP
    const int thread = omp_get_thread_num(), team = omp_get_num_threads();
#else
    const int thread = 0, team = 1;
#endif
    for (int part = thread; part < parts; part += team) {
      try {
        body(count * part / parts, count * (part + 1) / parts, part);
      }
      catch (const std::bad_alloc&) {
        __atomic_store_n(&failed, true, __ATOMIC_RELAXED);
      }
    }
  }
  if (failed)
    throw std::bad_alloc();
}

/** Run body(t) for every task t in [0, count) on up to \a workers threads, the
 * caller's one of them, the next task to the first thread free. What a task throws
 * stops the handing out of tasks and is thrown here once every thread is done: an
 * exception must not leave a thread. The tasks go out in ascending order, so every
 * task below a failed one has run, and what is thrown is the lowest failing task's,
 * whatever the threads. A thread the system does not grant leaves its tasks to the
 * others. */
template <typename Body>
void
forEachTask(std::size_t count, int workers, const Body& body)
{
  std::atomic<std::size_t> next{0};
  std::mutex failing;
  std::exception_ptr failure;
  std::size_t failed = std::numeric_limits<std::size_t>::max();
  const auto work = [&] {
    for (std::size_t t = next++; t < count; t = next++) {
      try {
        body(t);
      }
      catch (...) {
        const std::lock_guard<std::mutex> lock(failing);
        if (t < failed) {
          failed = t;
          failure = std::current_exception();
        }
        next = count;
      }
    }
  };
  // The caller works too: workers - 1 threads more, none beyond the tasks.
  const std::size_t extra = std::min<std::size_t>(
      static_cast<std::size_t>(std::max(workers, 1)) - 1, count > 0 ? count - 1 : 0);
  std::vector<std::thread> pool;
  try {
    pool.reserve(extra);
    while (pool.size() < extra)
      pool.emplace_back(work);
  }
  catch (const std::system_error&) {
  }
  catch (const std::bad_alloc&) {
  }
  work();
  for (auto& thread : pool)
    thread.join();
  if (failure)
    std::rethrow_exception(failure);
}

/** A stable counting sort of the items [0, count) by key(i), below \a buckets: calls
 * put(i, place) for every item, where the places of one key are together and in
 * ascending order of the items. With several threads, each counts and places a part
 * of the items: the same places.
 * \return per key b, where its items begin; then the end (count) */
template <typename Key, typename Put>
LargeVector<std::uint32_t>
countingSort(
    std::size_t count, std::size_t buckets, int threads, const Key& key, const Put& put)
{
  const int parts = partsFor(count, threads);
  // Per part and key: its count of items, then where the first of them goes (the
  // parts in order within a key).
  std::vector<std::vector<std::uint32_t>> place(parts);
  for (auto& p : place)
    p.resize(buckets);
  forEachRange(count, parts, [&](std::size_t begin, std::size_t end, int part) {
    auto& counted = place[part];
    std::fill(counted.begin(), counted.end(), 0);
    for (std::size_t i = begin; i < end; ++i)
      ++counted[key(i)];
  });
  LargeVector<std::uint32_t> start(buckets + 1);
  std::uint32_t total = 0;
  for (std::size_t b = 0; b < buckets; ++b) {
    start[b] = total;
    for (auto& p : place) {
      const std::uint32_t here = p[b];
      p[b] = total;
      total += here;
    }
  }
  start[buckets] = total;
  forEachRange(count, parts, [&](std::size_t begin, std::size_t end, int part) {
    auto& next = place[part];
    for (std::size_t i = begin; i < end; ++i)
      put(i, next[key(i)]++);
  });
  return start;
}

/** Disjoint sets of 0 .. n - 1 that several threads unite at once without locks,
 * with a parity per element relative to the root of its set (a two-colouring that
 * the unions constrain). The root of a set is its lowest element, as the larger of
 * two roots is linked below the smaller: the roots, and the parities in a set whose
 * constraints agree, do not depend on the order of the unions. */
class ConcurrentParitySets {
public:
  explicit ConcurrentParitySets(std::size_t n, int threads)
  : link_(n), concurrent_(threads > 1)
  {
    const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for num_threads(threads) schedule(static, 65536)
    for (std::ptrdiff_t i = 0; i < count; ++i)
      link_[i] = static_cast<std::uint64_t>(i) << 1;
  }

  struct Found {
    int root;
    int parity; ///< of the element relative to the root
  };

  Found
  find(int t)
  {
    int parity = 0;
    for (;;) {
      const std::uint64_t up = load(t);
      const int parent = static_cast<int>(up >> 1);
      if (parent == t)
        return {t, parity};
      const std::uint64_t above = load(parent);
      const int grandparent = static_cast<int>(above >> 1);
      if (grandparent == parent)
        return {parent, parity ^ static_cast<int>(up & 1)};
      // Halve the path: any ancestor, with the parity to it, keeps t in its set.
      const std::uint64_t halved = (up ^ above) & 1;
      __atomic_store_n(
          &link_[t], static_cast<std::uint64_t>(grandparent) << 1 | halved, RELAXED);
      parity ^= static_cast<int>(halved);
      t = grandparent;
    }
  }

  /** Join the sets of a and b, their parities to differ by \a odd (0 or 1); a
   * constraint against the parities of a set already joined is not recorded. */
  void
  unite(int a, int b, int odd)
  {
    for (;;) {
      Found x = find(a), y = find(b);
      if (x.root == y.root)
        return;
      if (x.root > y.root)
        std::swap(x, y);
      std::uint64_t expected = static_cast<std::uint64_t>(y.root) << 1;
      const std::uint64_t below = static_cast<std::uint64_t>(x.root) << 1 |
                                  static_cast<std::uint64_t>(x.parity ^ y.parity ^ odd);
      if (!concurrent_) { // no locked instruction where no other thread links
        link_[y.root] = below;
        return;
      }
      if (__atomic_compare_exchange_n(
              &link_[y.root], &expected, below, false, RELAXED, RELAXED))
        return;
    }
  }

private:
  static constexpr int RELAXED = __ATOMIC_RELAXED;

  std::uint64_t
  load(int t) const
  {
    return __atomic_load_n(&link_[t], RELAXED);
  }

  std::vector<std::uint64_t> link_;
  bool concurrent_;
};

} // namespace detail
} // namespace cocone
} // namespace pcl
