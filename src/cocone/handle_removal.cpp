/*
 * pcl_cocone_boundary: boundary-aware Co-cone surface reconstruction for PCL.
 * SPDX-License-Identifier: GPL-3.0-or-later
 */

#include <pcl/surface/cocone/handle_removal.h>
#include <pcl/surface/cocone/mesh_checks.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <Eigen/Geometry>

#include "least_perimeter.h"
#include "local_mesh.h"
#include "parallel.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <tuple>
#include <utility>

namespace pcl {
namespace cocone {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/** How far from its short cycle a handle no sample resolves closes (its two sides
 * meet), in triangles each way. Measured on the closed meshes with noise 0 to 0.5
 * spacings: the spurious handles' sides meet 9 to 31 triangles round, counting both
 * ways; the kitten's true handle, whose short cycle has 3 edges too, 1956. (The
 * casting's true rings meet 18 to 29 round, but their short cycles have 6 to 9
 * edges: the cycle's length tells those.) */
constexpr int MAX_HANDLE_DEPTH = 32;

/** A neck's surface opens out on both sides, as a surface does and a tube does
 * not: the triangles in the NECK_RINGS-th ring round its cycle are at least
 * NECK_OPENING times those of the first ring, and those in ring 2 NECK_RINGS at least
 * NECK_GROWTH times those in ring NECK_RINGS (a tube's rings stay alike once round
 * it, a pinched one's too). Measured on two touching spheres of 1,000 to 3,000
 * samples and the Power Crust hotdogs with noise of 0.5 spacings: the necks open 3
 * to 8 times by the sixth ring and grow 1.7 to 2.8 times more by the twelfth; a
 * noisy coarse knotted tube pinched to a 3-edge cycle opens 3.3 times, then grows
 * 0.6 to 1.0 times. */
constexpr int NECK_RINGS = 6;
constexpr double NECK_OPENING = 2.0;
constexpr double NECK_GROWTH = 1.4;

/** Each side of a neck goes on for NECK_SIDE_RINGS rings at least: a body of its
 * own, not a blister that noise pinched off or an ear's tip. Measured on the same
 * clouds: the short separating cycles that widen on both sides but bound such a
 * part end within 26 rings on one side (most within 7 to 14); the touching
 * spheres' go on for 35 rings (500 samples a sphere) to 64. */
constexpr int NECK_SIDE_RINGS = 32;

/** Rounds of cuts at most: each takes the handles no earlier cut of the round
 * touched. */
constexpr int MAX_ROUNDS = 8;

Kernel::Point_3
toCgal(const Eigen::Vector3d& p)
{
  return {p.x(), p.y(), p.z()};
}

/** SplitMix64's output function: a fixed, well spread key per generator. */
std::uint64_t
splitMix(std::uint64_t x)
{
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/** The vertices' edges (ids of the incidences), in CSR form. */
struct VertexEdges {
  std::vector<std::size_t> first;
  std::vector<std::uint32_t> edge;

  VertexEdges(const EdgeIncidences& inc, std::size_t num_vertices)
  : first(num_vertices + 1, 0), edge(2 * inc.edges.size())
  {
    for (const auto& e : inc.edges) {
      ++first[e[0] + 1];
      ++first[e[1] + 1];
    }
    for (std::size_t v = 0; v < num_vertices; ++v)
      first[v + 1] += first[v];
    std::vector<std::size_t> next(first.begin(), first.end() - 1);
    for (std::size_t e = 0; e < inc.edges.size(); ++e)
      for (const int v : inc.edges[e])
        edge[next[v]++] = static_cast<std::uint32_t>(e);
  }
};

/** The other end of edge \a e from its end \a x. */
inline int
otherEnd(const EdgeIncidences& inc, std::uint32_t e, int x)
{
  return inc.edges[e][0] == x ? inc.edges[e][1] : inc.edges[e][0];
}

/** Per edge, the Z2 cohomology class of the mesh with each border loop capped by a
 * disk, hashed to 64 bits: summed over a cycle's edges it is zero where the cycle
 * separates the surface, and, but with odds of 2^-64, not zero where it does not.
 * Tree-cotree (Eppstein 2003): the edges in neither a spanning forest of the
 * vertices nor the spanning forest of the triangles and caps across the other edges
 * are 2g per component, the generators; each gets a key, and an edge carries the
 * keys of the generators whose dual loop (its own dual edge and the dual forest's
 * path between its two sides) crosses it. Empty if no component has a handle.
 * \a in_handled marks the vertices of the components that have one. */
std::vector<std::uint64_t>
cohomologyHashes(const EdgeIncidences& inc,
                 const VertexEdges& at,
                 std::size_t num_triangles,
                 const std::vector<std::vector<int>>& loops,
                 std::vector<std::uint8_t>& in_handled)
{
  const std::size_t num_vertices = at.first.size() - 1, num_edges = inc.edges.size();
  // The dual forest's nodes: the triangles, then one cap per border loop.
  std::vector<std::array<int, 2>> sides(num_edges);
  for (std::size_t e = 0; e < num_edges; ++e) {
    if (inc.count(e) > 2)
      return {};
    sides[e] = {inc.triangle[inc.first[e]],
                inc.count(e) == 2 ? inc.triangle[inc.first[e] + 1] : -1};
  }
  for (std::size_t l = 0; l < loops.size(); ++l)
    for (std::size_t i = 0; i < loops[l].size(); ++i) {
      const auto e = inc.find(loops[l][i], loops[l][(i + 1) % loops[l].size()]);
      if (e < 0 || inc.count(static_cast<std::size_t>(e)) != 1 || sides[e][1] >= 0)
        return {}; // not the loops of a manifold
      sides[e][1] = static_cast<int>(num_triangles + l);
    }
  for (const auto& side : sides)
    if (side[1] < 0)
      return {}; // a border edge on no loop: not a manifold
  // The vertices' spanning forest, breadth first; its components.
  std::vector<std::uint8_t> in_tree(num_edges, 0);
  std::vector<int> component(num_vertices, -1);
  std::vector<int> queue;
  int components = 0;
  for (std::size_t s = 0; s < num_vertices; ++s) {
    if (component[s] >= 0 || at.first[s] == at.first[s + 1])
      continue;
    component[s] = components;
    queue.assign(1, static_cast<int>(s));
    for (std::size_t q = 0; q < queue.size(); ++q)
      for (std::size_t i = at.first[queue[q]]; i < at.first[queue[q] + 1]; ++i) {
        const std::uint32_t e = at.edge[i];
        const int w = otherEnd(inc, e, queue[q]);
        if (component[w] < 0) {
          component[w] = components;
          in_tree[e] = 1;
          queue.push_back(w);
        }
      }
    ++components;
  }
  // The dual forest across the other edges, breadth first.
  const std::size_t num_nodes = num_triangles + loops.size();
  std::vector<std::size_t> first(num_nodes + 1, 0);
  for (std::size_t e = 0; e < num_edges; ++e)
    if (!in_tree[e]) {
      ++first[sides[e][0] + 1];
      ++first[sides[e][1] + 1];
    }
  for (std::size_t n = 0; n < num_nodes; ++n)
    first[n + 1] += first[n];
  std::vector<std::uint32_t> across(first.back());
  {
    std::vector<std::size_t> next(first.begin(), first.end() - 1);
    for (std::size_t e = 0; e < num_edges; ++e)
      if (!in_tree[e])
        for (const int n : sides[e])
          across[next[n]++] = static_cast<std::uint32_t>(e);
  }
  std::vector<int> parent_edge(num_nodes, -1), parent(num_nodes, -1);
  std::vector<std::uint8_t> reached(num_nodes, 0), in_cotree(num_edges, 0);
  std::vector<int> order;
  order.reserve(num_nodes);
  for (std::size_t s = 0; s < num_nodes; ++s) {
    if (reached[s])
      continue;
    reached[s] = 1;
    const std::size_t from = order.size();
    order.push_back(static_cast<int>(s));
    for (std::size_t q = from; q < order.size(); ++q)
      for (std::size_t i = first[order[q]]; i < first[order[q] + 1]; ++i) {
        const std::uint32_t e = across[i];
        const int n = sides[e][0] == order[q] ? sides[e][1] : sides[e][0];
        if (!reached[n]) {
          reached[n] = 1;
          in_cotree[e] = 1;
          parent[n] = order[q];
          parent_edge[n] = static_cast<int>(e);
          order.push_back(n);
        }
      }
  }
  // The generators' keys, summed over each node's subtree: a cotree edge is on a
  // generator's dual loop where one of the generator's sides is below it.
  std::vector<std::uint64_t> hash(num_edges, 0), below(num_nodes, 0);
  bool any = false;
  in_handled.assign(num_vertices, 0);
  std::vector<std::uint8_t> handled(static_cast<std::size_t>(components), 0);
  for (std::size_t e = 0; e < num_edges; ++e)
    if (!in_tree[e] && !in_cotree[e]) {
      hash[e] = splitMix(e) | 1;
      below[sides[e][0]] ^= hash[e];
      below[sides[e][1]] ^= hash[e];
      handled[component[inc.edges[e][0]]] = 1;
      any = true;
    }
  if (!any)
    return {};
  for (auto n = order.rbegin(); n != order.rend(); ++n)
    if (parent[*n] >= 0) {
      hash[parent_edge[*n]] = below[*n];
      below[parent[*n]] ^= below[*n];
    }
  for (std::size_t v = 0; v < num_vertices; ++v)
    in_handled[v] = component[v] >= 0 && handled[component[v]];
  return hash;
}

/** A cycle of mesh edges, its vertices from the lowest id on, towards the lower of
 * that vertex's two neighbours on it. */
struct Cycle {
  std::vector<int> vertices;
  double length = 0.0;

  bool
  operator<(const Cycle& other) const
  {
    const std::size_t edges = vertices.size(), other_edges = other.vertices.size();
    return std::tie(edges, length, vertices) <
           std::tie(other_edges, other.length, other.vertices);
  }
};

/** Sort \a cycles shortest first (fewest edges, then length) and keep each once
 * (the same cycle is found from each of its vertices). */
void
sortOnce(std::vector<Cycle>& cycles)
{
  std::sort(cycles.begin(), cycles.end());
  cycles.erase(std::unique(cycles.begin(),
                           cycles.end(),
                           [](const Cycle& a, const Cycle& b) {
                             return a.vertices == b.vertices;
                           }),
               cycles.end());
}

/** A breadth-first ball of mesh edges round a root: per node its vertex, depth,
 * tree parent, first hop from the root (its branch), and the hash sum and length of
 * its tree path. Two paths of different branches and an edge between their ends
 * make a cycle through the root. */
class EdgeBall {
public:
  struct Node {
    int vertex, depth, parent, branch;
    std::uint64_t hash;
    double length;
  };

  explicit EdgeBall(std::size_t num_vertices) : slot_(num_vertices, -1) {}

  /** The ball of \a root up to \a depth_limit edges through the vertices \a admit
   * lets in, with the edges' \a hash (none if empty); the previous ball cleared. */
  template <typename Admit>
  void
  grow(int root,
       int depth_limit,
       const std::vector<Eigen::Vector3d>& points,
       const EdgeIncidences& inc,
       const VertexEdges& at,
       const std::vector<std::uint64_t>& hash,
       const Admit& admit)
  {
    for (const Node& n : nodes_)
      slot_[n.vertex] = -1;
    nodes_.assign(1, {root, 0, -1, -1, 0, 0.0});
    slot_[root] = 0;
    for (std::size_t q = 0; q < nodes_.size(); ++q) {
      if (nodes_[q].depth == depth_limit)
        continue;
      const int x = nodes_[q].vertex;
      for (std::size_t i = at.first[x]; i < at.first[x + 1]; ++i) {
        const std::uint32_t e = at.edge[i];
        const int w = otherEnd(inc, e, x);
        if (slot_[w] >= 0 || !admit(w))
          continue;
        slot_[w] = static_cast<int>(nodes_.size());
        nodes_.push_back({w,
                          nodes_[q].depth + 1,
                          static_cast<int>(q),
                          q == 0 ? w : nodes_[q].branch,
                          nodes_[q].hash ^ (hash.empty() ? 0 : hash[e]),
                          nodes_[q].length + (points[w] - points[x]).norm()});
      }
    }
  }

  const std::vector<Node>&
  nodes() const
  {
    return nodes_;
  }

  /** Call \a f(a, b, e) for every edge e of the mesh between nodes a < b of the
   * ball (tree edges too), in the order of a, then of a's edges. */
  template <typename F>
  void
  forEachEdge(const EdgeIncidences& inc, const VertexEdges& at, const F& f) const
  {
    for (std::size_t a = 0; a < nodes_.size(); ++a) {
      const int x = nodes_[a].vertex;
      for (std::size_t i = at.first[x]; i < at.first[x + 1]; ++i) {
        const std::uint32_t e = at.edge[i];
        const int b = slot_[otherEnd(inc, e, x)];
        if (b > static_cast<int>(a))
          f(a, b, e);
      }
    }
  }

  /** The node of vertex \a v, -1 outside the ball. */
  int
  slot(int v) const
  {
    return slot_[v];
  }

  /** The cycle of the tree paths to nodes \a a and \a b and the edge between their
   * ends, \a length long, its vertices from the lowest on (Cycle). */
  Cycle
  cycle(int a, int b, double length) const
  {
    Cycle c;
    c.length = length;
    auto& v = c.vertices;
    for (int n = b; n > 0; n = nodes_[n].parent)
      v.push_back(nodes_[n].vertex);
    v.push_back(nodes_[0].vertex);
    std::reverse(v.begin(), v.end());
    for (int n = a; n > 0; n = nodes_[n].parent)
      v.push_back(nodes_[n].vertex);
    std::rotate(v.begin(), std::min_element(v.begin(), v.end()), v.end());
    if (v[1] > v.back())
      std::reverse(v.begin() + 1, v.end());
    return c;
  }

private:
  std::vector<int> slot_;
  std::vector<Node> nodes_;
};

/** Per vertex, the shortest cycle through it of at most \a max_edges edges whose
 * hash sum is not zero: two paths of a breadth-first tree from the vertex, leaving
 * it by different edges, and an edge between their ends. The shortest
 * non-separating cycle through a vertex is of that form for any shortest-path tree
 * (Erickson and Har-Peled 2004), and a lasso's loop is found from its knot. */
std::vector<Cycle>
shortCycles(const std::vector<Eigen::Vector3d>& points,
            const EdgeIncidences& inc,
            const VertexEdges& at,
            const std::vector<std::uint64_t>& hash,
            const std::vector<std::uint8_t>& in_handled,
            std::size_t max_edges,
            int threads)
{
  const std::size_t num_vertices = at.first.size() - 1;
  const int depth_limit = static_cast<int>(max_edges / 2);
  // A cycle whose sum is not zero has an edge whose hash is not, and its vertices
  // lie within depth_limit edges of that edge's ends: the seeds (on a fine mesh of
  // a torus, the few thousand vertices along the dual loops of its two generators).
  std::vector<std::uint8_t> seed(num_vertices, 0);
  for (std::size_t e = 0; e < inc.edges.size(); ++e)
    if (hash[e] != 0)
      seed[inc.edges[e][0]] = seed[inc.edges[e][1]] = 1;
  for (int ring = 0; ring < depth_limit; ++ring) {
    std::vector<std::uint8_t> grown = seed;
    for (const auto& e : inc.edges)
      if (seed[e[0]] || seed[e[1]])
        grown[e[0]] = grown[e[1]] = 1;
    seed = std::move(grown);
  }
  const int parts = detail::partsFor(num_vertices, threads);
  std::vector<std::vector<Cycle>> found(parts);
  detail::forEachRange(
      num_vertices, parts, [&](std::size_t begin, std::size_t end, int part) {
        EdgeBall ball(num_vertices);
        const auto admit = [&](int w) { return in_handled[w] != 0; };
        for (std::size_t s = begin; s < end; ++s) {
          if (!seed[s] || !in_handled[s])
            continue;
          ball.grow(static_cast<int>(s), depth_limit, points, inc, at, hash, admit);
          const auto& nodes = ball.nodes();
          std::size_t best_edges = max_edges + 1;
          double best_length = 0.0;
          std::array<int, 2> best_ends{-1, -1};
          ball.forEachEdge(inc, at, [&](std::size_t a, int b, std::uint32_t e) {
            if (nodes[a].branch == nodes[b].branch ||
                nodes[b].parent == static_cast<int>(a) ||
                (nodes[a].hash ^ nodes[b].hash ^ hash[e]) == 0)
              return;
            const std::size_t edges = static_cast<std::size_t>(nodes[a].depth) +
                                      static_cast<std::size_t>(nodes[b].depth) + 1;
            const double length =
                nodes[a].length + nodes[b].length +
                (points[nodes[b].vertex] - points[nodes[a].vertex]).norm();
            if (edges < best_edges || (edges == best_edges && length < best_length)) {
              best_edges = edges;
              best_length = length;
              best_ends = {static_cast<int>(a), b};
            }
          });
          if (best_ends[0] >= 0)
            found[part].push_back(ball.cycle(best_ends[0], best_ends[1], best_length));
        }
      });
  std::vector<Cycle> cycles;
  for (auto& f : found)
    std::move(f.begin(), f.end(), std::back_inserter(cycles));
  sortOnce(cycles);
  return cycles;
}

/** Whether ab (either way) is an edge of \a cycle. */
bool
isCycleEdge(const std::vector<int>& cycle, int a, int b)
{
  const std::size_t k = cycle.size();
  for (std::size_t i = 0; i < k; ++i) {
    const int c = cycle[i], d = cycle[(i + 1) % k];
    if ((a == c && b == d) || (a == d && b == c))
      return true;
  }
  return false;
}

/** How far round \a cycle its two sides meet: a breadth-first search from the
 * triangle on each side of its first edge, across every edge but the cycle's, in
 * turns, until the two meet; the triangles on the shortest way found from one side
 * to the other. -1 if one side runs out first (the cycle separates) or neither
 * meets the other within \a max_depth triangles of the cycle; so the cost is that
 * of the smaller side or of the way round the handle, at most two balls of that
 * radius. */
int
waySidesMeet(const detail::LocalMesh& mesh,
             const std::vector<int>& cycle,
             int max_depth,
             std::vector<int>& depth)
{
  const auto on_cycle = [&](int a, int b) { return isCycleEdge(cycle, a, b); };
  // depth: 0 unreached, +d on the left at d - 1 triangles off, -d on the right.
  depth.resize(mesh.triangles().size(), 0);
  std::array<std::vector<int>, 2> queue{
      std::vector<int>{mesh.traversing(cycle[0], cycle[1])},
      std::vector<int>{mesh.traversing(cycle[1], cycle[0])}};
  std::array<std::size_t, 2> head{0, 0};
  int way = -1;
  if (queue[0][0] >= 0 && queue[1][0] >= 0) {
    depth[queue[0][0]] = 1;
    depth[queue[1][0]] = -1;
    for (int s = 0; way < 0; s ^= 1) {
      if (head[s] == queue[s].size())
        break;
      const int t = queue[s][head[s]++];
      const int d = std::abs(depth[t]);
      if (d > max_depth)
        break;
      for (int c = 0; c < 3 && way < 0; ++c) {
        const int a = mesh.triangles()[t][c], b = mesh.triangles()[t][(c + 1) % 3];
        if (on_cycle(a, b))
          continue;
        const int n = mesh.traversing(b, a);
        if (n < 0 || (depth[n] != 0 && (depth[n] > 0) == (s == 0)))
          continue;
        if (depth[n] != 0)
          way = d + std::abs(depth[n]);
        else {
          depth[n] = s == 0 ? d + 1 : -(d + 1);
          queue[s].push_back(n);
        }
      }
    }
  }
  for (const auto& q : queue)
    for (const int t : q)
      if (t >= 0)
        depth[t] = 0;
  return way;
}

/** Cut \a mesh along \a cycle (directed): the triangles on its left, the fans of
 * its vertices between its edges, taken out; the cycle and the band's outer loop
 * closed by least-perimeter patches of their vertices. False, and the mesh
 * unchanged, where the band is no annulus between the cycle (clear of \a touched,
 * which the caller checks) and a simple loop of other vertices clear of the mesh's
 * borders and of earlier cuts (\a touched), or a
 * patch needs an edge the mesh has or a degenerate triangle. */
bool
cutAlong(const std::vector<Eigen::Vector3d>& points,
         detail::LocalMesh& mesh,
         const std::vector<int>& cycle,
         std::vector<std::uint8_t>& touched,
         detail::LeastPerimeterScratch& scratch)
{
  const std::size_t k = cycle.size();
  std::vector<int> band;
  for (std::size_t i = 0; i < k; ++i) {
    const int v = cycle[i], prev = cycle[(i + k - 1) % k];
    int to = cycle[(i + 1) % k];
    for (int turns = 0;; ++turns) {
      const int t = mesh.traversing(v, to);
      if (t < 0 || turns > 64)
        return false;
      band.push_back(t);
      const Triangle& tri = mesh.triangles()[t];
      const int c =
          static_cast<int>(std::find(tri.begin(), tri.end(), v) - tri.begin());
      to = tri[(c + 2) % 3];
      if (to == prev)
        break;
    }
  }
  std::sort(band.begin(), band.end());
  band.erase(std::unique(band.begin(), band.end()), band.end());
  const auto in_band = [&](int t) {
    return t >= 0 && std::binary_search(band.begin(), band.end(), t);
  };
  // The band's boundary: its half-edges whose twin is outside it, each with one.
  std::vector<std::array<int, 2>> rim;
  for (const int t : band)
    for (int c = 0; c < 3; ++c) {
      const int a = mesh.triangles()[t][c], b = mesh.triangles()[t][(c + 1) % 3];
      const int twin = mesh.traversing(b, a);
      if (twin < 0)
        return false; // a border
      if (!in_band(twin))
        rim.push_back({a, b});
    }
  const auto on_cycle = [&](int v) {
    return std::find(cycle.begin(), cycle.end(), v) != cycle.end();
  };
  // The cycle's own edges, then the outer loop through the other vertices.
  std::vector<int> outer;
  for (std::size_t i = 0; i < k; ++i) {
    const std::array<int, 2> own{cycle[i], cycle[(i + 1) % k]};
    const auto it = std::find(rim.begin(), rim.end(), own);
    if (it == rim.end())
      return false;
    rim.erase(it);
  }
  if (rim.size() < 3)
    return false;
  std::sort(rim.begin(), rim.end());
  for (std::size_t i = 0; i + 1 < rim.size(); ++i)
    if (rim[i][0] == rim[i + 1][0])
      return false; // the band's outer boundary is not a simple loop
  outer.push_back(rim[0][0]);
  while (outer.size() <= rim.size()) {
    const auto it =
        std::lower_bound(rim.begin(), rim.end(), std::array<int, 2>{outer.back(), -1});
    if (it == rim.end() || (*it)[0] != outer.back())
      return false;
    if ((*it)[1] == outer[0])
      break;
    outer.push_back((*it)[1]);
  }
  if (outer.size() != rim.size())
    return false; // more than one outer loop
  for (const int v : outer)
    if (on_cycle(v) || touched[v])
      return false;
  for (const int t : band)
    for (const int v : mesh.triangles()[t])
      if (!on_cycle(v) && std::find(outer.begin(), outer.end(), v) == outer.end())
        return false; // a vertex inside the band would leave the mesh
  for (const int t : band)
    mesh.kill(t);
  // Each loop closed in the direction of the band's half-edges on it, as the band's
  // triangles ran: the patches face as the mesh.
  std::vector<Triangle> patches;
  bool closed = true;
  for (const std::vector<int>* loop :
       {&cycle, static_cast<const std::vector<int>*>(&outer)}) {
    const std::size_t n = loop->size();
    const auto valid = [&](std::size_t i, std::size_t m, std::size_t j) {
      const auto new_edge = [&](std::size_t x, std::size_t y) {
        const int a = (*loop)[x], b = (*loop)[y];
        return y == x + 1 || (x == 0 && y == n - 1) ||
               (mesh.traversing(a, b) < 0 && mesh.traversing(b, a) < 0);
      };
      return new_edge(i, m) && new_edge(m, j) && new_edge(i, j) &&
             !CGAL::collinear(toCgal(points[(*loop)[i]]),
                              toCgal(points[(*loop)[m]]),
                              toCgal(points[(*loop)[j]]));
    };
    if (!detail::leastPerimeterTriangulation(points, *loop, valid, patches, scratch)) {
      closed = false;
      break;
    }
  }
  if (!closed) {
    for (const int t : band)
      mesh.revive(t);
    return false;
  }
  for (const Triangle& t : patches)
    mesh.add(t);
  for (const int v : cycle)
    touched[v] = 1;
  for (const int v : outer)
    touched[v] = 1;
  return true;
}

/** Cut along each of \a cycles (shortest first) that \a accept(mesh, cycle) takes
 * and no earlier cut touched (cutAlong(), either way round), \a incidences brought
 * up to date; returns the number cut. */
template <typename Accept>
std::size_t
cutCycles(const std::vector<Eigen::Vector3d>& points,
          std::vector<Triangle>& triangles,
          EdgeIncidences& incidences,
          const std::vector<Cycle>& cycles,
          std::vector<std::uint8_t>& touched,
          const Accept& accept)
{
  const std::size_t before = triangles.size();
  detail::LocalMesh mesh(triangles, points.size());
  detail::LeastPerimeterScratch scratch;
  std::size_t cut = 0;
  for (const Cycle& cycle : cycles) {
    if (std::any_of(cycle.vertices.begin(),
                    cycle.vertices.end(),
                    [&](int v) { return touched[v] != 0; }) ||
        !accept(mesh, cycle))
      continue;
    const std::vector<int> reversed(cycle.vertices.rbegin(), cycle.vertices.rend());
    if (cutAlong(points, mesh, cycle.vertices, touched, scratch) ||
        cutAlong(points, mesh, reversed, touched, scratch))
      ++cut;
  }
  if (cut > 0)
    mesh.commit(before, incidences);
  return cut;
}

/** One round of cutShortHandles(): the candidates on the mesh as it is, each cut
 * unless an earlier cut of the round touched it. */
std::size_t
cutRound(const std::vector<Eigen::Vector3d>& points,
         std::vector<Triangle>& triangles,
         EdgeIncidences& incidences,
         std::size_t min_tunnel_samples,
         int threads)
{
  const std::size_t num_vertices = points.size();
  const std::vector<std::vector<int>> loops = boundaryLoops(incidences, num_vertices);
  // Every component of genus 0 (the common case, a disk or a sphere with holes):
  // V - E + F + loops = 2 per component, and nothing to cut.
  std::size_t components = 0;
  triangleComponents(incidences, triangles.size(), &components);
  const std::vector<std::uint8_t> used = usedVertices(triangles, num_vertices);
  const auto vertices = static_cast<long>(std::count(used.begin(), used.end(), 1));
  if (vertices - static_cast<long>(incidences.edges.size()) +
          static_cast<long>(triangles.size() + loops.size()) ==
      2 * static_cast<long>(components))
    return 0;
  const VertexEdges at(incidences, num_vertices);
  std::vector<std::uint8_t> in_handled;
  const std::vector<std::uint64_t> hash =
      cohomologyHashes(incidences, at, triangles.size(), loops, in_handled);
  if (hash.empty())
    return 0;
  // Borders and what lies a ring off them are no place to cut (a cycle through a
  // border's vertices may not separate the capped surface where it separates the
  // mesh): the cycles keep off them, and a border vertex counts as touched.
  std::vector<std::uint8_t> touched(num_vertices, 0);
  for (const auto& loop : loops)
    for (const int v : loop) {
      touched[v] = 1;
      in_handled[v] = 0;
    }
  const std::vector<Cycle> cycles = shortCycles(
      points, incidences, at, hash, in_handled, min_tunnel_samples - 1, threads);
  if (cycles.empty())
    return 0;
  std::vector<int> depth;
  return cutCycles(points,
                   triangles,
                   incidences,
                   cycles,
                   touched,
                   [&](const auto& mesh, const Cycle& c) {
                     return waySidesMeet(mesh, c.vertices, MAX_HANDLE_DEPTH, depth) >=
                            0;
                   });
}

/** Per side of \a cycle (0: its left, 1: its right), the triangles in each of the
 * first \a rings rings round it: ring 1 the triangles on that side of its edges,
 * ring d + 1 those next to ring d across an edge not on the cycle. Empty where the
 * two sides meet within the rings (the cycle does not separate there), one reaches
 * a border or one runs out before them (a small disk, the common case: the sides
 * grow a ring each in turn, so that costs the disk's rings only). */
std::array<std::vector<int>, 2>
sideRings(const detail::LocalMesh& mesh,
          const std::vector<int>& cycle,
          int rings,
          std::vector<int>& depth)
{
  const std::size_t k = cycle.size();
  const auto on_cycle = [&](int a, int b) { return isCycleEdge(cycle, a, b); };
  // depth: 0 unreached, +d on the left in ring d, -d on the right.
  depth.resize(mesh.triangles().size(), 0);
  std::array<std::vector<int>, 2> reached, count;
  std::array<std::size_t, 2> ring_begin{0, 0};
  bool separate = true;
  for (int s = 0; s < 2 && separate; ++s)
    for (std::size_t i = 0; i < k && separate; ++i) {
      const int a = cycle[i], b = cycle[(i + 1) % k];
      const int t = s == 0 ? mesh.traversing(a, b) : mesh.traversing(b, a);
      if (t < 0 || (depth[t] != 0 && (depth[t] > 0) != (s == 0)))
        separate = false;
      else if (depth[t] == 0) {
        depth[t] = s == 0 ? 1 : -1;
        reached[s].push_back(t);
      }
    }
  for (int d = 1; d <= rings && separate; ++d)
    for (int s = 0; s < 2 && separate; ++s) {
      const std::size_t end = reached[s].size();
      count[s].push_back(static_cast<int>(end - ring_begin[s]));
      if (end == ring_begin[s]) {
        separate = false; // the side ran out: a disk
        break;
      }
      for (std::size_t q = ring_begin[s]; q < end && separate && d < rings; ++q) {
        const int t = reached[s][q];
        for (int c = 0; c < 3; ++c) {
          const int a = mesh.triangles()[t][c], b = mesh.triangles()[t][(c + 1) % 3];
          if (on_cycle(a, b))
            continue;
          const int n = mesh.traversing(b, a);
          if (n < 0 || (depth[n] != 0 && (depth[n] > 0) != (s == 0))) {
            separate = false; // a border, or the other side
            break;
          }
          if (depth[n] == 0) {
            depth[n] = s == 0 ? d + 1 : -(d + 1);
            reached[s].push_back(n);
          }
        }
      }
      ring_begin[s] = end;
    }
  for (const auto& r : reached)
    for (const int t : r)
      depth[t] = 0;
  if (!separate)
    return {};
  return count;
}

/** Turn the components that hold a vertex marked in \a cut outward where their
 * signed volume about their centroid is negative, as the repair orients each
 * component. The walk can orient two bodies it joined as a fold, one inside out
 * (the join's triangles run between facing sheets); apart, each faces out. */
void
turnOutward(const std::vector<Eigen::Vector3d>& points,
            std::vector<Triangle>& triangles,
            EdgeIncidences& incidences,
            const std::vector<std::uint8_t>& cut)
{
  std::size_t count = 0;
  const std::vector<int> component =
      triangleComponents(incidences, triangles.size(), &count);
  std::vector<std::uint8_t> held(count, 0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& v = triangles[t];
    held[component[t]] |= cut[v[0]] | cut[v[1]] | cut[v[2]];
  }
  const std::vector<double> volume = signedVolumes(points, triangles, component, count);
  std::vector<std::uint8_t> turned(triangles.size(), 0);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    if (held[component[t]] && volume[component[t]] < 0.0) {
      std::swap(triangles[t][1], triangles[t][2]);
      turned[t] = 1;
    }
  for (std::size_t i = 0; i < incidences.triangle.size(); ++i)
    incidences.forward[i] ^= turned[incidences.triangle[i]];
}

} // namespace

std::size_t
cutShortNecks(const std::vector<Eigen::Vector3d>& points,
              std::vector<Triangle>& triangles,
              EdgeIncidences& incidences,
              const std::vector<int>& seeds,
              std::size_t min_tunnel_samples)
{
  const std::size_t num_vertices = points.size();
  if (triangles.empty() || seeds.empty() || min_tunnel_samples < 4)
    return 0;
  const std::size_t max_edges = min_tunnel_samples - 1;
  const int depth_limit = static_cast<int>(max_edges / 2);
  const VertexEdges at(incidences, num_vertices);
  // Borders and what lies on them are no place for a neck's cycle.
  std::vector<std::uint8_t> touched = borderMask(incidences, num_vertices);
  // Every cycle of two breadth-first paths from a seed and an edge, of 3 to
  // max_edges edges.
  std::vector<Cycle> cycles;
  EdgeBall ball(num_vertices);
  const auto admit = [&](int w) { return touched[w] == 0; };
  for (const int s : seeds) {
    if (touched[s])
      continue;
    ball.grow(s, depth_limit, points, incidences, at, {}, admit);
    const auto& nodes = ball.nodes();
    // The ball's triangles (those of its vertices) make a disk round a vertex of a
    // surface, Euler characteristic 1, where every cycle in it bounds; round a neck
    // they make an annulus (0).
    long euler = static_cast<long>(nodes.size());
    ball.forEachEdge(incidences, at, [&](std::size_t, int b, std::uint32_t e) {
      --euler;
      for (std::size_t j = incidences.first[e]; j < incidences.first[e + 1]; ++j)
        for (const int c : triangles[incidences.triangle[j]])
          if (ball.slot(c) > b)
            ++euler; // counted at the edge of its two lower corners
    });
    if (euler >= 1)
      continue;
    ball.forEachEdge(incidences, at, [&](std::size_t a, int b, std::uint32_t) {
      // The root's edges close no cycle (a path and its first edge).
      if (a == 0 || nodes[a].branch == nodes[b].branch ||
          static_cast<std::size_t>(nodes[a].depth) +
                  static_cast<std::size_t>(nodes[b].depth) + 1 >
              max_edges)
        return;
      cycles.push_back(
          ball.cycle(static_cast<int>(a),
                     b,
                     nodes[a].length + nodes[b].length +
                         (points[nodes[b].vertex] - points[nodes[a].vertex]).norm()));
    });
  }
  sortOnce(cycles);
  if (cycles.empty())
    return 0;
  const std::vector<std::vector<int>> loops = boundaryLoops(incidences, num_vertices);
  // A cycle round a handle is no neck (its sides meet beyond the rings searched):
  // only cycles whose hash sum is zero separate the surface. Without a handle
  // (no hashes) every cycle does.
  std::vector<std::uint8_t> in_handled;
  const std::vector<std::uint64_t> hash =
      cohomologyHashes(incidences, at, triangles.size(), loops, in_handled);
  const auto separates = [&](const std::vector<int>& cycle) {
    if (hash.empty())
      return true;
    std::uint64_t sum = 0;
    for (std::size_t i = 0; i < cycle.size(); ++i) {
      const auto e = incidences.find(cycle[i], cycle[(i + 1) % cycle.size()]);
      sum ^= hash[static_cast<std::size_t>(e)];
    }
    return sum == 0;
  };
  std::vector<int> depth;
  const std::size_t cut = cutCycles(
      points,
      triangles,
      incidences,
      cycles,
      touched,
      [&](const auto& mesh, const Cycle& c) {
        if (!separates(c.vertices))
          return false;
        // The surface opens out on both sides and grows on as a surface, then goes
        // on as a body of its own on each.
        const auto rings = sideRings(mesh, c.vertices, 2 * NECK_RINGS, depth);
        return !rings[0].empty() &&
               std::none_of(rings.begin(),
                            rings.end(),
                            [](const auto& r) {
                              return r[NECK_RINGS - 1] < NECK_OPENING * r[0] ||
                                     r[2 * NECK_RINGS - 1] <
                                         NECK_GROWTH * r[NECK_RINGS - 1];
                            }) &&
               !sideRings(mesh, c.vertices, NECK_SIDE_RINGS, depth)[0].empty();
      });
  if (cut > 0)
    turnOutward(points, triangles, incidences, touched);
  return cut;
}

std::size_t
cutShortHandles(const std::vector<Eigen::Vector3d>& points,
                std::vector<Triangle>& triangles,
                EdgeIncidences& incidences,
                std::size_t min_tunnel_samples,
                int threads)
{
  if (triangles.empty() || min_tunnel_samples < 4)
    return 0;
  // Handles side by side (a patch of noise has several) are cut a round each: a
  // cut's vertices wait for the next round, with the hashes of the mesh it left.
  std::size_t cut = 0;
  for (int round = 0; round < MAX_ROUNDS; ++round) {
    const std::size_t more =
        cutRound(points, triangles, incidences, min_tunnel_samples, threads);
    if (more == 0)
      break;
    cut += more;
  }
  return cut;
}

} // namespace cocone
} // namespace pcl
