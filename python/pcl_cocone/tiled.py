"""Tiled reconstruction on a Dask cluster: one task per tile, stitched here.

    python3 -m pcl_cocone.tiled INPUT OUTPUT [--scheduler ADDRESS] [--tile_points N]
                                [--threads N] [--workers N] [--halo_spacings S]
                                [-v] [--report FILE]

INPUT is .ply (ASCII or binary), .xyz/.txt/.pts (x y z per line, further columns
ignored) or .npy (an (N, 3) array); OUTPUT is .ply (binary) or .obj: the points in the
mesh, in input order, and the triangles.

The points are cut into tiles here (plan_tiles), each tile's points go to the cluster
as one task (reconstruct_tile) and the results come back in the order of the tiles to
be stitched (stitch_tiles). The mesh is the one reconstruct(points, tile_points=N)
gives in one process, whichever worker ran a tile and however often: a task lost with
its worker is run again by Dask, and a tile's result depends only on its points. A
cloud that fits one tile is reconstructed here, in one piece, as reconstruct() does.

Without --scheduler, a distributed.LocalCluster of --workers processes with one thread
each runs the tasks. The workers of a cluster must be able to import pcl_cocone (it is
installed there, or on their PYTHONPATH).
"""

import argparse
import json
import os
import sys
import time
import uuid
import warnings

import numpy as np

from ._pcl_cocone import plan_tiles, reconstruct, reconstruct_tile, stitch_tiles

INPUT_FORMATS = (".ply", ".xyz", ".txt", ".pts", ".npy")
OUTPUT_FORMATS = (".ply", ".obj")

_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
              "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
              "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4",
              "double": "f8", "float64": "f8"}


class FormatError(ValueError):
    """A file this module cannot read or write."""


def _extension(path):
    return os.path.splitext(path)[1].lower()


def _read_ply(path):
    """The x, y, z of the vertex element of a PLY file, (N, 3) float64."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            raise FormatError(f"{path}: not a PLY file")
        form, elements = None, []  # (name, count, [(property, type or None: list)])
        while True:
            line = f.readline()
            if not line:
                raise FormatError(f"{path}: PLY header without end_header")
            words = line.decode("ascii", "replace").split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "end_header":
                break
            try:
                if words[0] == "format":
                    form = words[1]
                elif words[0] == "element":
                    elements.append((words[1], int(words[2]), []))
                elif words[0] == "property" and words[1] == "list":
                    elements[-1][2].append((words[4], None))
                elif words[0] == "property":
                    elements[-1][2].append((words[2], _PLY_TYPES[words[1]]))
            except (IndexError, KeyError, ValueError):
                raise FormatError(f"{path}: bad PLY header line: {line.strip()!r}") \
                    from None
        if form not in ("ascii", "binary_little_endian", "binary_big_endian"):
            raise FormatError(f"{path}: unknown PLY format {form!r}")
        names = [e[0] for e in elements]
        if "vertex" not in names:
            raise FormatError(f"{path}: no vertex element")
        before = elements[:names.index("vertex")]
        _, count, properties = elements[names.index("vertex")]
        columns = [p[0] for p in properties]
        if not {"x", "y", "z"} <= set(columns):
            raise FormatError(f"{path}: the vertices have no x, y and z")
        if form == "ascii":
            for _, n, _ in before:
                for _ in range(n):
                    f.readline()
            rows = [f.readline() for _ in range(count)]
            try:
                data = np.loadtxt(rows, usecols=[columns.index(c) for c in "xyz"],
                                  ndmin=2, dtype=np.float64)
            except ValueError as e:
                raise FormatError(f"{path}: bad vertex line ({e})") from None
            if len(data) != count:
                raise FormatError(f"{path}: {len(data)} of {count} vertices")
            return data
        endian = "<" if form == "binary_little_endian" else ">"
        for name, n, props in before + [elements[names.index("vertex")]]:
            if any(t is None for _, t in props):
                raise FormatError(f"{path}: a list property in element {name!r} "
                                  "before the vertices' end")
        for _, n, props in before:
            f.seek(n * np.dtype([(p, endian + t) for p, t in props]).itemsize, 1)
        dtype = np.dtype([(p, endian + t) for p, t in properties])
        data = np.fromfile(f, dtype=dtype, count=count)
        if len(data) != count:
            raise FormatError(f"{path}: {len(data)} of {count} vertices (cut short?)")
        return np.column_stack([data[c].astype(np.float64) for c in "xyz"])


def read_points(path):
    """The points of a .ply, .xyz/.txt/.pts or .npy file as an (N, 3) float64 array."""
    ext = _extension(path)
    if ext not in INPUT_FORMATS:
        raise FormatError(f"{path}: unknown point format {ext!r} "
                          f"(one of {', '.join(INPUT_FORMATS)})")
    if ext == ".ply":
        points = _read_ply(path)
    elif ext == ".npy":
        points = np.load(path, allow_pickle=False)
        if points.ndim != 2 or points.shape[1] != 3:
            raise FormatError(f"{path}: an array of shape {points.shape}, not (N, 3)")
    else:
        try:
            points = np.loadtxt(path, usecols=(0, 1, 2), ndmin=2, comments="#",
                                dtype=np.float64)
        except ValueError as e:
            raise FormatError(f"{path}: not x y z per line ({e})") from None
    return np.ascontiguousarray(points, dtype=np.float64)


def write_mesh(path, points, result):
    """Write the points in the mesh (in input order) and its triangles to .ply (binary,
    with the normals) or .obj, through a temporary file: a failure leaves no file."""
    ext = _extension(path)
    if ext not in OUTPUT_FORMATS:
        raise FormatError(f"{path}: unknown mesh format {ext!r} "
                          f"(one of {', '.join(OUTPUT_FORMATS)})")
    triangles = result.triangles
    used = np.unique(triangles)
    number = np.full(len(points), -1, dtype=np.int32)
    number[used] = np.arange(len(used), dtype=np.int32)
    faces = number[triangles]
    temporary = path + ".part"
    try:
        with open(temporary, "wb") as f:
            if ext == ".ply":
                header = ("ply\nformat binary_little_endian 1.0\n"
                          f"element vertex {len(used)}\n"
                          "property double x\nproperty double y\nproperty double z\n"
                          "property float nx\nproperty float ny\nproperty float nz\n"
                          f"element face {len(faces)}\n"
                          "property list uchar int vertex_indices\nend_header\n")
                f.write(header.encode("ascii"))
                vertices = np.empty(len(used), dtype=[("p", "<f8", 3), ("n", "<f4", 3)])
                vertices["p"] = points[used]
                vertices["n"] = result.normals[used]
                vertices.tofile(f)
                records = np.empty(len(faces), dtype=[("k", "u1"), ("v", "<i4", 3)])
                records["k"] = 3
                records["v"] = faces
                records.tofile(f)
            else:
                np.savetxt(f, points[used], fmt="v %.17g %.17g %.17g")
                np.savetxt(f, faces + 1, fmt="f %d %d %d")
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise


def tile_task(points, ids, core_points, parameters):
    """One tile, on a worker (module level, so that it is sent by name)."""
    return reconstruct_tile(points, ids, core_points, **parameters)


def reconstruct_on_cluster(points, client_factory, parameters):
    """Reconstruct (N, 3) points tile by tile, one task per tile on the cluster that
    client_factory() connects to (called only when there is more than one tile; it
    returns a context manager giving a distributed.Client).

    Returns the Result (as reconstruct(points, **parameters) gives) and a dict of
    figures: tiles, points per tile, seconds per phase."""
    figures = {"points": len(points)}
    start = time.perf_counter()
    plan = plan_tiles(points, **parameters)
    figures["tiles"] = plan.tiles
    figures["plan_seconds"] = time.perf_counter() - start
    if plan.one_piece:
        start = time.perf_counter()
        result = reconstruct(points, **parameters)
        figures.update(largest_tile=len(points), halo_points=0, workers=0,
                       connect_seconds=0.0, tiles_seconds=time.perf_counter() - start,
                       stitch_seconds=0.0)
        return result, figures
    start = time.perf_counter()
    with client_factory() as client:
        figures["workers"] = len(client.scheduler_info()["workers"])
        figures["connect_seconds"] = time.perf_counter() - start
        start = time.perf_counter()
        token = uuid.uuid4().hex
        futures = []
        # Each tile's points go inside its task, not scattered to a worker first: the
        # scheduler keeps them, so that it can run the tile again elsewhere when its
        # worker dies (scattered data would die with it). Dask warns about such tasks.
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", "Large object", UserWarning)
            for t in range(plan.tiles):
                ids = plan.tile_points(t)
                futures.append(client.submit(tile_task, points[ids], ids,
                                             plan.core_size(t), parameters,
                                             key=f"pcl_cocone-tile-{token}-{t}"))
        results = client.gather(futures)  # in the order of the tiles
        del futures
        figures["tiles_seconds"] = time.perf_counter() - start
    figures["tile_run_seconds"] = sum(sum(r.timings_ms.values()) for r in results) / 1e3
    start = time.perf_counter()
    result = stitch_tiles(plan, results, **parameters)
    figures["stitch_seconds"] = time.perf_counter() - start
    tiling = result.report["tiling"]
    figures.update(largest_tile=tiling["largest_tile"],
                   halo_points=tiling["halo_points"])
    return result, figures


class _Connect:
    """A client of the scheduler at an address, or of a new LocalCluster."""

    def __init__(self, address, workers):
        self.address, self.workers = address, workers
        self.cluster = self.client = None

    def __enter__(self):
        from distributed import Client, LocalCluster

        if self.address:
            self.client = Client(self.address)
        else:
            self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                        processes=True, dashboard_address=None)
            self.client = Client(self.cluster)
        return self.client

    def __exit__(self, *exc):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()
        return False


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line and exit status 1, as for any other error
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        sys.exit(1)


def main(argv=None):
    parser = _Parser(prog="python3 -m pcl_cocone.tiled",
                     description="Reconstruct a point cloud tile by tile on a Dask "
                                 "cluster and stitch the tiles into one mesh.")
    parser.add_argument("input", help="points: " + ", ".join(INPUT_FORMATS))
    parser.add_argument("output", help="mesh: " + ", ".join(OUTPUT_FORMATS))
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="the Dask scheduler (e.g. tcp://host:8786); default: a "
                             "local cluster of --workers processes")
    parser.add_argument("--tile_points", type=int, default=1000000, metavar="N",
                        help="at most N points in a tile's core (default 1000000)")
    parser.add_argument("--halo_spacings", type=float, default=8.0, metavar="S",
                        help="width of a tile's halo in local spacings (default 8)")
    parser.add_argument("--threads", type=int, default=1, metavar="N",
                        help="threads per tile task (default 1; 0: all processors)")
    parser.add_argument("--workers", type=int, default=None, metavar="N",
                        help="worker processes of the local cluster (default: one "
                             "per processor)")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="print the tiles and the time of each phase")
    parser.add_argument("--report", metavar="FILE",
                        help="write the figures and the reconstruction report as JSON")
    args = parser.parse_args(argv)
    prog = parser.prog

    def say(text):
        if args.verbose:
            print(text, file=sys.stderr, flush=True)

    try:
        if _extension(args.output) not in OUTPUT_FORMATS:
            raise FormatError(f"{args.output}: unknown mesh format "
                              f"{_extension(args.output)!r} "
                              f"(one of {', '.join(OUTPUT_FORMATS)})")
        if args.workers is not None and args.workers < 1:
            raise ValueError(f"--workers must be at least 1, got {args.workers}")
        started = time.perf_counter()
        points = read_points(args.input)
        read_seconds = time.perf_counter() - started
        say(f"read {len(points)} points from {args.input} ({read_seconds:.2f} s)")
        parameters = {"tile_points": args.tile_points, "threads": args.threads,
                      "halo_spacings": args.halo_spacings}
        result, figures = reconstruct_on_cluster(
            points, lambda: _Connect(args.scheduler, args.workers), parameters)
        say(f"plan: {figures['tiles']} tiles, largest {figures['largest_tile']} "
            f"points, {figures['halo_points']} halo points "
            f"({figures['plan_seconds']:.2f} s)")
        workers = figures["workers"]
        say(f"tiles: {figures['tiles']} tasks on {workers} worker"
            f"{'' if workers == 1 else 's'} "
            f"({figures['tiles_seconds']:.2f} s"
            + (f"; {figures['tile_run_seconds']:.2f} s in the tiles' runs; "
               f"connecting {figures['connect_seconds']:.2f} s)"
               if "tile_run_seconds" in figures else ")"))
        say(f"stitch: {result.report['triangles']} triangles, "
            f"{result.report['border_loops']} border loops "
            f"({figures['stitch_seconds']:.2f} s)")
        start = time.perf_counter()
        write_mesh(args.output, points, result)
        figures["write_seconds"] = time.perf_counter() - start
        figures["read_seconds"] = read_seconds
        figures["total_seconds"] = time.perf_counter() - started
        say(f"wrote {args.output} ({figures['write_seconds']:.2f} s); "
            f"total {figures['total_seconds']:.2f} s")
        if args.report:
            with open(args.report, "w") as f:
                json.dump({"input": args.input, "output": args.output,
                           "scheduler": args.scheduler or "local", "figures": figures,
                           "report": result.report}, f, indent=1, default=float)
    except KeyboardInterrupt:
        raise
    except Exception as e:  # noqa: BLE001 - any failure is one line and status 1
        text = str(e).splitlines()[0] if str(e) else type(e).__name__
        if not isinstance(e, (OSError, ValueError, TypeError, RuntimeError)):
            text = f"{type(e).__name__}: {text}"
        print(f"{prog}: error: {text}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    # Run as the module pcl_cocone.tiled, not as __main__: the workers then import
    # tile_task by name (a function of __main__ would be pickled with its globals).
    from pcl_cocone.tiled import main as _main

    sys.exit(_main())
