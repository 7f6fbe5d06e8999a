#!/usr/bin/env python3
# Open3D's ball pivoting for scripts/benchmark.sh, printing the same key=value line
# as cocone_benchmark:
#   python3 scripts/benchmark_ball_pivoting.py CLOUD.ply
# Normals from the 20 nearest points; balls of 1, 2 and 4 mean nearest-neighbour
# distances (one radius leaves holes in random samples, larger ones cost time).
# peak_mb includes the interpreter and Open3D's libraries: base_mb is that share.
import resource
import sys
import time

import numpy as np
import open3d as o3d


def megabytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: benchmark_ball_pivoting.py CLOUD.ply")
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    cloud = o3d.io.read_point_cloud(sys.argv[1])
    cloud.normals = o3d.utility.Vector3dVector()  # estimated like the others'
    n = len(cloud.points)
    base_mb = megabytes()

    start = time.perf_counter()
    cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(knn=20))
    normals = time.perf_counter()
    spacing = float(np.mean(cloud.compute_nearest_neighbor_distance()))
    radii = o3d.utility.DoubleVector([spacing, 2.0 * spacing, 4.0 * spacing])
    measured = time.perf_counter()
    mesh = o3d.geometry.TriangleMesh.create_from_point_cloud_ball_pivoting(cloud, radii)
    end = time.perf_counter()
    peak_mb = megabytes()

    # Edges as sorted vertex pairs: boundary edges are in one triangle; the Euler
    # characteristic counts the vertices used.
    triangles = np.asarray(mesh.triangles, dtype=np.int64)
    edges = np.sort(triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    keys, counts = np.unique(edges[:, 0] * (n + 1) + edges[:, 1], return_counts=True)
    border = np.unique(np.concatenate([keys[counts == 1] // (n + 1),
                                       keys[counts == 1] % (n + 1)]))
    vertices = len(np.unique(triangles))
    print(
        f"method=ball_pivoting points={n} seconds={end - start:.3f} "
        f"base_mb={base_mb:.0f} peak_mb={peak_mb:.0f} "
        f"stages=normals:{normals - start:.3f},spacing:{measured - normals:.3f},"
        f"pivoting:{end - measured:.3f} triangles={len(triangles)} "
        f"boundary_edges={int(np.sum(counts == 1))} "
        f"euler={vertices - len(counts) + len(triangles)} border_points={len(border)} "
        f"manifold={int(mesh.is_edge_manifold() and mesh.is_vertex_manifold())}"
    )


if __name__ == "__main__":
    main()
