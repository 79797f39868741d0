"""vitri: variational implicit surfaces (RBF interpolants of constraint points) meshed by a dynamic
Delaunay tetrahedralization, from numpy (docs/python.md).

    import vitri
    mesh = vitri.reconstruct(points)            # (n, 3) array -> Mesh
    V, F, N = mesh                              # (#V, 3) float64, (#F, 3) uint32, (#V, 3) float64

Functions:
    reconstruct(points, normals=None, **options) -> Mesh (or a list of Mesh for levels)
        A scan (points, with or without normals) meshed as ``vitri mesh`` meshes a point file: noise
        measured and absorbed, outliers set aside, normals estimated and oriented when not given, a
        closed or open surface (docs/scans.md). The options are the CLI's, by name:
          precision       relative precision (x the diagonal of the data's bounding box); a decreasing
                          sequence gives levels of detail (a list of meshes). Default: the data's
                          resolution (2.5 x spacing and noise), within a budget of Delaunay vertices
                          (a coarser mesh with a RuntimeWarning beyond it).
          function        'global', 'local' or 'auto' (default)
          smoothing       local function: regularization (default 0: the points are interpolated)
          threads         0 (default): every available CPU
          min_angle, max_distance, max_size   the quality mode (docs/quality.md); max_distance may be a
                          sequence (levels)
          offset, sides, off_surface_spacing, neighbours      the normal constraints (docs/guide.md)
          surface         'closed', 'open' or 'auto' (default);   viewpoint   the sensor's (x, y, z)
          max_vertices    a limit on the Delaunay vertices (LimitError beyond it)
          memory          bytes or '16G': the run's memory limit, checked before the large allocations
                          (default: the machine's available memory less a reserve; docs/memory.md)
          certify, certify_floor   certified levels (docs/certificate.md), as --certify
          progress        progress(phase: str, vertices: int, queued: int) -> bool | None; False cancels
                          (vitri.Cancelled); an exception raised there reaches the caller.
    mesh_constraints(points, values, **options) -> Mesh
        The surface f = 0 of the function through f(points[i]) = values[i] (f < 0 inside), as
        ``vitri mesh`` meshes an .xyzv file; default precision: 2.5 x the median spacing.
    read(path) -> Mesh | types.SimpleNamespace
        .off/.obj/.ply with faces and .stl (corners welded): a Mesh; .xyzv: kind='constraints', points,
        values; .xyz/.pwn/.pcd and face-less .ply/.off/.obj: kind='points', points, normals (or None),
        viewpoint, sensors.
    write(path, data, *, ascii=False)
        A Mesh or (V, F[, N]) to .obj/.off/.ply (PLY binary unless ascii) or .stl (binary, float32, no
        normals); an object with points and values to .xyzv; with points (and normals) to .xyz/.pwn.

Classes: Mesher (refinement, levels, edits by stable constraint ids, deltas), Rbf and LocalRbf (fit,
evaluate, edit by ids), Delaunay
(the exact dynamic tetrahedralization), Mesh.

Errors: Error > InvalidArgument (also ValueError) > InvalidPoint (.index) > DegenerateNeighbourhood,
OrientationError, UnknownConstraint (.id); Error > ParseError (.file, .line), NumericalError, LimitError, Cancelled. A wrong
dtype is a TypeError. Long calls release the GIL and stop on Ctrl-C (KeyboardInterrupt).
"""

from . import _vitri
from ._vitri import (
    Cancelled,
    DegenerateNeighbourhood,
    Delaunay,
    Error,
    InvalidArgument,
    InvalidPoint,
    LimitError,
    LocalRbf,
    Mesh,
    Mesher,
    NumericalError,
    OrientationError,
    ParseError,
    Rbf,
    UnknownConstraint,
    mesh_constraints,
    read,
    reconstruct,
    write,
)

__version__ = _vitri.__version__

__all__ = [
    "Cancelled", "DegenerateNeighbourhood", "Delaunay", "Error", "InvalidArgument", "InvalidPoint",
    "LimitError", "LocalRbf", "Mesh", "Mesher", "NumericalError", "OrientationError", "ParseError", "Rbf",
    "UnknownConstraint",
    "mesh_constraints", "read", "reconstruct", "write", "__version__",
]
