"""Boundary-aware Co-cone surface reconstruction (pcl_cocone_boundary) for NumPy.

    import numpy as np, pcl_cocone
    result = pcl_cocone.reconstruct(points)       # points: (N, 3) float64 or float32
    result.triangles         # (M, 3) int32, indices of the input points
    result.boundary_indices  # the undersampled points
    result.border_loops      # the mesh's borders, closed loops of point indices
    result.normals           # (N, 3), NaN where a point is not in the mesh
    result.outlier_indices   # the points set aside as outliers (in no triangle)
    result.point_noise       # (N,) float32 noise level per point (sigma in spacings)
    result.noise_level       # the cloud's; result.smoothed: decided on smoothed points
    result.report            # counts, the ratio used, timings per stage (ms)

Parameters (keyword arguments, as cocone::Parameters / pcl::CoConeBoundary):
ratio (0: automatic), spacing_factor, gap_angle, normal_angle, cocone_angle (angles in
radians), boundary_detection, noise_handling (default True: outliers set aside, a noisy
cloud smoothed before the decisions), noise_threshold (the cloud noise level above
which it is smoothed, >= 0), smoothing_iterations (>= 1), threads (0: all
processors). An unknown name raises TypeError, a value out of range ValueError; a
cloud with no result (fewer than 4 distinct finite points, collinear points)
RuntimeError. The computation releases the GIL.

Tiles (reconstruct(points, tile_points=N) in three phases, for other processes):
    plan = pcl_cocone.plan_tiles(points, tile_points=N)
    results = [pcl_cocone.reconstruct_tile(points[plan.tile_points(t)],
                                           plan.tile_points(t), plan.core_size(t))
               for t in range(plan.tiles)]          # anywhere: picklable, any order
    result = pcl_cocone.stitch_tiles(plan, results)  # as reconstruct() with tile_points
The same keyword parameters go to all three. python3 -m pcl_cocone.tiled runs the tiles
on a Dask cluster (pcl_cocone/tiled.py).
"""

from ._pcl_cocone import (Result, TilePlan, TileResult, default_parameters,
                          detect_boundary, plan_tiles, reconstruct, reconstruct_tile,
                          stitch_tiles)

__all__ = ["Result", "TilePlan", "TileResult", "default_parameters", "detect_boundary",
           "plan_tiles", "reconstruct", "reconstruct_tile", "stitch_tiles"]
