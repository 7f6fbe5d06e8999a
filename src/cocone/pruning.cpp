/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/pruning.h>

namespace pcl {
namespace cocone {

std::vector<std::uint8_t>
prune(const TriangleComplex& complex,
      const std::vector<std::uint8_t>& boundary,
      std::size_t* removed,
      const std::vector<std::uint8_t>& keep)
{
  const std::size_t m = complex.numTriangles();
  std::vector<std::uint8_t> alive(m, 1);
  const auto is_alive = [&](int t) { return alive[t] != 0; };
  const auto is_protected = [&](int t) {
    const auto& v = complex.triangle(t);
    return boundary[v[0]] || boundary[v[1]] || boundary[v[2]] ||
           (!keep.empty() && keep[t]);
  };
  std::size_t count = 0;
  std::vector<int> pending;
  pending.reserve(complex.numEdges());
  for (int e = static_cast<int>(complex.numEdges()) - 1; e >= 0; --e)
    pending.push_back(e);
  while (!pending.empty()) {
    const int e = pending.back();
    pending.pop_back();
    if (!complex.isSharp(e, is_alive))
      continue;
    for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i) {
      const int t = complex.edgeTriangle(i);
      if (!alive[t] || is_protected(t))
        continue;
      alive[t] = 0;
      ++count;
      for (const int e2 : complex.triangleEdges(t))
        if (e2 != e)
          pending.push_back(e2);
    }
  }
  if (removed)
    *removed = count;
  return alive;
}

} // namespace cocone
} // namespace pcl
