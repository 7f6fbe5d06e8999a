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
"""

from ._pcl_cocone import Result, default_parameters, detect_boundary, reconstruct

__all__ = ["Result", "default_parameters", "detect_boundary", "reconstruct"]
