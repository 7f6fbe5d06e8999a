/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Splitting a loop among threads (not installed).
 */

#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <cstddef>
#include <new>

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

} // namespace detail
} // namespace cocone
} // namespace pcl
