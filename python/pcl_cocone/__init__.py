"""Boundary-aware Co-cone surface reconstruction (pcl_cocone_boundary) for NumPy.

    import numpy as np, pcl_cocone
    result = pcl_cocone.reconstruct(points)       # points: (N, 3) float64 or float32
    result.triangles         # (M, 3) int32, indices of the input points
    result.boundary_indices  # the undersampled points
    result.border_loops      # the mesh's borders, closed loops of point indices
    result.normals           # (N, 3), NaN where a point is not in the mesh
    result.report            # counts, the ratio used, timings per stage (ms)

Parameters (keyword arguments, as cocone::Parameters / pcl::CoConeBoundary):
ratio (0: automatic), spacing_factor, gap_angle, normal_angle, cocone_angle (angles in
radians), boundary_detection, threads (0: all processors). An unknown name raises
TypeError, a value out of range ValueError; a cloud with no result (fewer than 4
distinct finite points, collinear points) RuntimeError. The computation releases the
GIL.
"""

from ._pcl_cocone import Result, default_parameters, detect_boundary, reconstruct

__all__ = ["Result", "default_parameters", "detect_boundary", "reconstruct"]
