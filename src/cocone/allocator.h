/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The allocator of the stages' large per-point and per-cell arrays (not installed).
 */

#pragma once

#ifdef __linux__
#include <sys/mman.h>
#endif

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#define COCONE_UNDER_ASAN
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define COCONE_UNDER_ASAN
#endif
#endif

// Large arrays are mapped on their own where the system takes the advice of huge
// pages, and not under AddressSanitizer, whose heap checks them.
#if defined(__linux__) && defined(MADV_HUGEPAGE) && !defined(COCONE_UNDER_ASAN)
#define COCONE_MAP_LARGE_ARRAYS
#endif

namespace pcl {
namespace cocone {
namespace detail {

/** The size of a huge page on x86-64 and arm64: the alignment of a mapped array. */
constexpr std::size_t HUGE_PAGE = std::size_t(2) << 20;
/** Arrays of at least this many bytes are mapped on their own: glibc maps a block
 * this large afresh on every allocation anyway (the most its dynamic mmap threshold
 * grows to), while smaller blocks reuse the freed memory of its heap, whose pages
 * are already there (mapped from 2 MB on, the arrays below took about as many
 * faults, and more once the triangle complex's were mapped too). */
constexpr std::size_t MAPPED_BYTES = std::size_t(32) << 20;

/** The allocator of large arrays: arrays of MAPPED_BYTES or more are mapped on
 * their own, aligned to a huge page, with the advice to back them with transparent
 * huge pages.
 *
 * Why: the stages' per-point and per-cell arrays are written in an order that
 * follows the points rather than the addresses, and a large one is new memory every
 * time, so every 4 KB page of it is a page fault (about 5 microseconds each on a
 * virtual machine) and a miss of the TLB. Measured on tori of 1M points, one
 * thread, the page faults of a run: clean 492,000 -> 230,000, with noise of 0.5
 * spacings 534,000 -> 277,000 (every allocation in huge pages, glibc's tunable:
 * 24,000); the runs 0 to 15 % shorter, interleaved on a shared machine. Where the
 * kernel gives no huge pages (transparent huge pages off) the advice is ignored. Under
 * AddressSanitizer the arrays stay in its heap, where it checks them. */
template <typename T>
struct LargeAllocator {
  using value_type = T;

  LargeAllocator() = default;
  template <typename U>
  LargeAllocator(const LargeAllocator<U>&) noexcept
  {}

  T*
  allocate(std::size_t n)
  {
#ifdef COCONE_MAP_LARGE_ARRAYS
    if (mapped(n)) {
      // A huge page more than asked, of which the part aligned to one is kept.
      const std::size_t size = roundUp(n * sizeof(T));
      void* const map = mmap(nullptr,
                             size + HUGE_PAGE,
                             PROT_READ | PROT_WRITE,
                             MAP_PRIVATE | MAP_ANONYMOUS,
                             -1,
                             0);
      if (map == MAP_FAILED)
        throw std::bad_alloc();
      char* const start = static_cast<char*>(map);
      const std::size_t skew = roundUp(reinterpret_cast<std::uintptr_t>(map)) -
                               reinterpret_cast<std::uintptr_t>(map);
      char* const aligned = start + skew;
      if (skew > 0)
        munmap(start, skew);
      munmap(aligned + size, HUGE_PAGE - skew);
      madvise(aligned, size, MADV_HUGEPAGE);
      return reinterpret_cast<T*>(aligned);
    }
#endif
    return std::allocator<T>().allocate(n);
  }

  void
  deallocate(T* p, std::size_t n) noexcept
  {
#ifdef COCONE_MAP_LARGE_ARRAYS
    if (mapped(n)) {
      munmap(p, roundUp(n * sizeof(T)));
      return;
    }
#endif
    std::allocator<T>().deallocate(p, n);
  }

  template <typename U>
  bool
  operator==(const LargeAllocator<U>&) const noexcept
  {
    return true;
  }
  template <typename U>
  bool
  operator!=(const LargeAllocator<U>&) const noexcept
  {
    return false;
  }

private:
  /** Whether n elements are mapped on their own (and the sizes below do not wrap). */
  static constexpr bool
  mapped(std::size_t n)
  {
    return n >= MAPPED_BYTES / sizeof(T) && n <= (SIZE_MAX - 2 * HUGE_PAGE) / sizeof(T);
  }
  static constexpr std::size_t
  roundUp(std::size_t bytes)
  {
    return (bytes + HUGE_PAGE - 1) / HUGE_PAGE * HUGE_PAGE;
  }
};

/** A vector of a stage's per-point or per-cell values (see LargeAllocator). */
template <typename T>
using LargeVector = std::vector<T, LargeAllocator<T>>;

/** A large allocator that default-initializes: a vector of trivial elements sized
 * ahead of use costs no memory until they are written. */
template <typename T>
struct DefaultInitAllocator : LargeAllocator<T> {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept
  {}
  template <typename U>
  void
  construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value)
  {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void
  construct(U* p, Args&&... args)
  {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

} // namespace detail
} // namespace cocone
} // namespace pcl
