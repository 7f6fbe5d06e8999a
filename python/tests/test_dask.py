"""python3 -m pcl_cocone.tiled on real Dask clusters (run from ctest as python_dask):
a scheduler and two worker processes on localhost, and a LocalCluster. Each run's
mesh must be the file the in-process tiled run (reconstruct(points, tile_points=N))
writes, also when a worker is killed while it holds a tile."""

import contextlib
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import distributed  # noqa: F401 - the test needs it (Debian: python3-distributed)
import pcl_cocone
from samples import torus
from pcl_cocone import tiled

TILE_POINTS = 5000


@pytest.fixture(scope="module")
def cloud(tmp_path_factory):
    """A torus of 30,000 points in a .npy file and the mesh file the in-process tiled
    run writes for it."""
    directory = tmp_path_factory.mktemp("cloud")
    points = torus(30000, 7)
    path = str(directory / "torus.npy")
    np.save(path, points)
    expected = str(directory / "expected.ply")
    result = pcl_cocone.reconstruct(points, tile_points=TILE_POINTS, threads=1)
    assert result.report["tiling"]["tiles"] == 8
    tiled.write_mesh(expected, points, result)
    with open(expected, "rb") as f:
        return path, f.read()


def run_tool(*arguments, **popen):
    command = [sys.executable, "-m", "pcl_cocone.tiled", *map(str, arguments)]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, **popen)


@contextlib.contextmanager
def cluster(directory, workers=2):
    """A dask-scheduler and worker processes (one thread, no nanny: killing one kills
    the worker) on localhost; yields the scheduler's address and the workers."""
    scheduler_file = str(directory / "scheduler.json")
    processes = []
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    try:
        processes.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host",
             "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file",
             scheduler_file], **quiet))
        for w in range(workers):
            processes.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker",
                 "--scheduler-file", scheduler_file, "--host", "127.0.0.1",
                 "--nthreads", "1", "--no-nanny", "--no-dashboard", "--name",
                 f"worker-{w}"], **quiet))
        deadline = time.monotonic() + 60.0
        while not os.path.exists(scheduler_file) and time.monotonic() < deadline:
            time.sleep(0.05)
        with distributed.Client(scheduler_file=scheduler_file, timeout=60) as client:
            client.wait_for_workers(workers, timeout=60)
            yield client.scheduler.address, processes[1:]
    finally:
        for p in reversed(processes):
            if p.poll() is None:
                p.terminate()
        for p in processes:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def read(path):
    with open(path, "rb") as f:
        return f.read()


def write_ply(path, points):
    """A binary PLY file of the points, with a colour to skip."""
    with open(path, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\ncomment made by the test\n"
                b"element vertex %d\nproperty double x\nproperty double y\n"
                b"property double z\nproperty uchar red\nend_header\n" % len(points))
        record = np.zeros(len(points), dtype=[("p", "<f8", 3), ("red", "u1")])
        record["p"] = points
        record.tofile(f)


def test_scheduler_and_two_workers_give_the_in_process_mesh(cloud, tmp_path):
    path, expected = cloud
    with cluster(tmp_path) as (address, _):
        out = tmp_path / "out.ply"
        report = tmp_path / "report.json"
        tool = run_tool(path, out, "--scheduler", address, "--tile_points",
                        TILE_POINTS, "--report", report)
        _, err = tool.communicate(timeout=300)
        assert tool.returncode == 0, err
        assert read(out) == expected
        figures = json.loads(read(report))["figures"]
        assert figures["tiles"] == 8 and figures["workers"] == 2
        # The same points as a PLY file in, an OBJ file out: the same mesh.
        points = np.load(path)
        ply = tmp_path / "torus.ply"
        write_ply(ply, points)
        assert np.array_equal(tiled.read_points(str(ply)), points)
        obj = tmp_path / "out.obj"
        tool = run_tool(ply, obj, "--scheduler", address, "--tile_points", TILE_POINTS)
        _, err = tool.communicate(timeout=300)
        assert tool.returncode == 0, err
    faces = [line.split()[1:] for line in read(obj).decode().splitlines()
             if line.startswith("f ")]
    triangles = pcl_cocone.reconstruct(points, tile_points=TILE_POINTS).triangles
    used = np.unique(triangles)  # the file's vertices, in input order
    assert np.array_equal(used[np.array(faces, dtype=np.int64) - 1], triangles)


def test_a_worker_killed_during_the_run_gives_the_same_mesh(cloud, tmp_path):
    path, expected = cloud
    with cluster(tmp_path) as (address, workers):
        out = tmp_path / "out.ply"
        tool = run_tool(path, out, "--scheduler", address, "--tile_points",
                        TILE_POINTS, "-v")
        # As soon as a worker holds a tile (running or queued there), kill it: the
        # scheduler must run its tiles again on the other one.
        killed = None
        with distributed.Client(address, timeout=60) as client:
            pids = {a: workers[int(str(w["name"]).split("-")[1])].pid
                    for a, w in client.scheduler_info()["workers"].items()}
            deadline = time.monotonic() + 120.0
            while killed is None and tool.poll() is None and \
                    time.monotonic() < deadline:
                for worker, keys in client.processing().items():
                    if any("pcl_cocone-tile" in str(k) for k in keys):
                        killed = pids[worker]
                        os.kill(killed, signal.SIGKILL)
                        break
                else:
                    time.sleep(0.005)
        _, err = tool.communicate(timeout=300)
        assert killed is not None, "no tile was seen on a worker before the run ended"
        assert killed in [w.pid for w in workers]
        assert sum(w.poll() is not None for w in workers) == 1  # one worker gone
        assert tool.returncode == 0, err
        assert "8 tasks on 2 workers" in err
        assert read(out) == expected


def test_local_cluster_gives_the_in_process_mesh(cloud, tmp_path):
    path, expected = cloud
    out = tmp_path / "out.ply"
    tool = run_tool(path, out, "--tile_points", TILE_POINTS, "--workers", 2, "-v")
    _, err = tool.communicate(timeout=300)
    assert tool.returncode == 0, err
    assert read(out) == expected
    assert "8 tasks on 2 workers" in err


def test_a_cloud_of_one_tile_needs_no_cluster(tmp_path):
    points = torus(3000, 7)
    path = tmp_path / "small.xyz"
    np.savetxt(path, points, fmt="%.17g")
    out = tmp_path / "small.ply"
    tool = run_tool(path, out, "--tile_points", TILE_POINTS, "--scheduler",
                    "tcp://127.0.0.1:1")  # nothing there: not contacted
    _, err = tool.communicate(timeout=120)
    assert tool.returncode == 0, err
    expected = tmp_path / "expected.ply"
    tiled.write_mesh(str(expected), points,
                     pcl_cocone.reconstruct(points, tile_points=TILE_POINTS))
    assert read(out) == read(expected)


@pytest.mark.parametrize("arguments, message", [
    (["missing.npy", "out.ply"], "No such file"),
    (["{cloud}", "out.stl"], "unknown mesh format"),
    (["in.pcd", "out.ply"], "unknown point format"),
    (["{cloud}", "out.ply", "--tile_points", "5"], "tile_points"),
    (["{cloud}", "out.ply", "--workers", "0"], "--workers"),
    (["{cloud}", "out.ply", "--tile_points", "many"], "invalid int value"),
    (["{cloud}"], "required"),
])
def test_errors_are_one_line_and_status_1(cloud, tmp_path, arguments, message):
    arguments = [a.format(cloud=cloud[0]) for a in arguments]
    tool = run_tool(*arguments, cwd=tmp_path)
    _, err = tool.communicate(timeout=120)
    assert tool.returncode == 1
    assert len(err.strip().splitlines()) == 1, err
    assert message in err
    assert not (tmp_path / "out.ply").exists()
