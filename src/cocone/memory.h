/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * Handing freed memory back to the system (not installed).
 */

#pragma once

#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace pcl {
namespace cocone {
namespace detail {

/** Return the free pages of the heap to the system. glibc serves blocks below its
 * mmap threshold from the heap, and that threshold rises to the size of any large
 * block freed (up to 32 MB), so the per-vertex arrays a stage frees stay resident
 * unless trimmed; where they are freed next to the peak, this lowers the peak. */
inline void
releaseFreedMemory()
{
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

} // namespace detail
} // namespace cocone
} // namespace pcl
