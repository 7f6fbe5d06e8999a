/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/umbrella.h>

#include <algorithm>

namespace pcl {
namespace cocone {

namespace {

/** Whether no edge at p is sharp to begin with: each has two triangles, which make
 * an angle above pi / 2 (most vertices). The cascade then deletes nothing, and the
 * umbrella is p's whole star. */
bool
wholeStar(const TriangleComplex& complex, int p)
{
  const std::size_t first = complex.vertexBegin(p), last = complex.vertexEnd(p);
  for (std::size_t i = first; i < last; ++i) {
    const int t = complex.vertexTriangle(i);
    for (int k = 0; k < 3; ++k) {
      const int e = complex.triangleEdges(t)[k];
      if (complex.triangle(t)[k] != p && // the edges at p are those opposite the others
          (complex.edgeEnd(e) - complex.edgeBegin(e) != 2 || complex.acutePair(e)))
        return false;
    }
  }
  return first != last;
}

/** HASUMBRELLA's cascade from the sharp edges at p; no triangle, no umbrella. */
bool
cascade(const TriangleComplex& complex, int p, std::vector<std::uint8_t>* kept)
{
  const std::size_t first = complex.vertexBegin(p), last = complex.vertexEnd(p);
  if (first == last)
    return false;
  // Every triangle at an edge pq contains p: the star is all the cascade can touch.
  // (The incidence list of a vertex is in ascending triangle order.)
  thread_local std::vector<int> star;
  thread_local std::vector<char> removed;
  thread_local std::vector<int> pending;
  star.clear();
  for (std::size_t i = first; i < last; ++i)
    star.push_back(complex.vertexTriangle(i));
  removed.assign(star.size(), 0);
  const auto alive = [&](int t) {
    const auto it = std::lower_bound(star.begin(), star.end(), t);
    return it != star.end() && *it == t && !removed[it - star.begin()];
  };
  std::size_t remaining = star.size();

  pending.clear();
  for (const int t : star)
    for (int k = 0; k < 3; ++k)
      if (complex.triangle(t)[k] != p) // the edges at p are those opposite the others
        pending.push_back(complex.triangleEdges(t)[k]);
  std::sort(pending.begin(), pending.end());
  pending.erase(std::unique(pending.begin(), pending.end()), pending.end());
  std::reverse(pending.begin(), pending.end());

  while (!pending.empty()) {
    const int e = pending.back();
    pending.pop_back();
    if (!complex.isSharp(e, alive))
      continue;
    for (std::size_t i = complex.edgeBegin(e); i < complex.edgeEnd(e); ++i) {
      const int t = complex.edgeTriangle(i);
      if (!alive(t))
        continue;
      removed[std::lower_bound(star.begin(), star.end(), t) - star.begin()] = 1;
      if (--remaining == 0)
        return false;
      for (int k = 0; k < 3; ++k) {
        const int e2 = complex.triangleEdges(t)[k];
        if (complex.triangle(t)[k] != p && e2 != e)
          pending.push_back(e2);
      }
    }
  }
  if (kept)
    for (std::size_t i = 0; i < star.size(); ++i)
      if (!removed[i])
        __atomic_fetch_add(&(*kept)[star[i]], 1, __ATOMIC_RELAXED); // stars overlap
  return true;
}

} // namespace

bool
hasUmbrella(const TriangleComplex& complex, int p, std::vector<std::uint8_t>* kept)
{
  if (!wholeStar(complex, p))
    return cascade(complex, p, kept);
  for (std::size_t i = complex.vertexBegin(p); kept && i < complex.vertexEnd(p); ++i)
    __atomic_fetch_add(&(*kept)[complex.vertexTriangle(i)], 1, __ATOMIC_RELAXED);
  return true;
}

std::vector<std::uint8_t>
umbrellaFailures(const TriangleComplex& complex,
                 const std::vector<std::uint8_t>& boundary,
                 std::vector<std::uint8_t>* umbrella_triangles,
                 int threads)
{
  std::vector<std::uint8_t> failed(boundary.size(), 0);
  // Per vertex: its umbrella is its whole star; per triangle, how many of the other
  // umbrellas keep it.
  std::vector<std::uint8_t> whole(boundary.size(), 0), kept;
  if (umbrella_triangles)
    kept.assign(complex.numTriangles(), 0);
  const auto n = static_cast<std::ptrdiff_t>(boundary.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1024)
  for (std::ptrdiff_t p = 0; p < n; ++p) {
    if (boundary[p])
      continue;
    if (wholeStar(complex, static_cast<int>(p)))
      whole[p] = 1;
    else
      failed[p] =
          !cascade(complex, static_cast<int>(p), umbrella_triangles ? &kept : nullptr);
  }
  if (umbrella_triangles) {
    umbrella_triangles->resize(complex.numTriangles());
    const auto m = static_cast<std::ptrdiff_t>(complex.numTriangles());
#pragma omp parallel for num_threads(threads) schedule(static, 16384)
    for (std::ptrdiff_t t = 0; t < m; ++t) {
      const auto& v = complex.triangle(static_cast<int>(t));
      (*umbrella_triangles)[t] = kept[t] + whole[v[0]] + whole[v[1]] + whole[v[2]] == 3;
    }
  }
  return failed;
}

} // namespace cocone
} // namespace pcl
