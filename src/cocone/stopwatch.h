/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 *
 * The stage timer of the pipeline and the tiling (not installed).
 */

#pragma once

#include <chrono>

namespace pcl {
namespace cocone {
namespace detail {

/** Wall-clock laps in milliseconds. */
class Stopwatch {
public:
  /** Milliseconds since the last call (or construction). */
  double
  lap()
  {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }

private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

} // namespace detail
} // namespace cocone
} // namespace pcl
