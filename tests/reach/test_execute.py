"""Map execution: chunk-independent seeds, Dask equality, streaming, resume, bad input."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from serialkin import models
from serialkin._budget import set_memory_budget
from serialkin.errors import BudgetError, InputError
from serialkin.models.planar import planar
from serialkin.reach import connect, load_map, reachability_map
from serialkin.reach.store import CHUNKS
from tests.reach._guard import outcome

SRC = str(Path(__file__).resolve().parents[2] / "src")
ARM = (3, [1.0, 0.8, 0.3])


def _same(a, b) -> None:
    for k, v in a.arrays().items():
        w = b.arrays()[k]
        assert v.dtype == w.dtype and v.shape == w.shape
        assert v.tobytes() == w.tobytes(), k


def _numerical(**kw):
    kw.setdefault("progress", False)
    return reachability_map(planar(*ARM), 0.25, 8, solver="numerical", **kw)


def test_map_is_bit_identical_whatever_the_chunking():
    """The numerical map does not depend on the chunk size (seeds are keyed by voxel)."""
    a = _numerical(chunk_voxels=512)
    b = _numerical(chunk_voxels=7)
    assert b.chunk_seconds.size > a.chunk_seconds.size
    _same(a, b)


def test_another_seed_changes_only_the_starts():
    """Another seed gives other starts but (with restarts) the same reached sets here."""
    a = _numerical(seed=1, restarts=8)
    b = _numerical(seed=2, restarts=8)
    assert np.array_equal(a.reached, b.reached)


@pytest.mark.slow
def test_dask_local_cluster_matches_embedded_bit_for_bit(tmp_path):
    """A LocalCluster with 2 worker processes gives the embedded map, bit for bit."""
    from serialkin.reach import local_cluster

    pytest.importorskip("dask.distributed")
    embedded = _numerical(chunk_voxels=16)
    client = local_cluster(2)
    try:
        assert len(client.scheduler_info()["workers"]) == 2
        distributed = _numerical(chunk_voxels=16, client=client, out=tmp_path / "m")
    finally:
        client.close()
        client.cluster.close()
    _same(embedded, distributed)
    meta = json.loads((tmp_path / "m" / "metadata.json").read_text())
    assert meta["executor"] == "dask"
    assert len(meta["chunk_seconds"]) == distributed.chunk_seconds.size > 1
    assert all(s is not None and s > 0 for s in meta["chunk_seconds"])
    _same(embedded, load_map(tmp_path / "m" / "map.npz"))


_KILLED_RUN = """
import sys
from serialkin.models.planar import planar
from serialkin.reach import reachability_map
reachability_map(planar(3, [1.0, 0.8, 0.3]), 0.2, 12, solver="numerical", chunk_voxels=10,
                 out=sys.argv[1], progress=False)
"""


@pytest.mark.slow
def test_killed_run_resumes_to_the_same_map(tmp_path):
    """A run killed (SIGKILL) mid-way, resumed, recomputes only missing chunks: same map."""
    out = tmp_path / "m"
    env = dict(os.environ, PYTHONPATH=SRC)
    proc = subprocess.Popen([sys.executable, "-c", _KILLED_RUN, str(out)], env=env)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            if (out / CHUNKS).is_dir() and len(list((out / CHUNKS).glob("c*.npz"))) >= 3:
                break
            time.sleep(0.02)
    finally:
        proc.kill()
        proc.wait()
    before = {p.name: p.read_bytes() for p in (out / CHUNKS).glob("c*.npz")}
    assert len(before) >= 3
    resumed = reachability_map(planar(*ARM), 0.2, 12, solver="numerical", chunk_voxels=10,
                               out=out, resume=True, progress=False)
    meta = json.loads((out / "metadata.json").read_text())
    assert meta["resumed_chunks"] >= len(before)  # nothing finished is recomputed
    assert meta["recomputed_chunks"] > 0  # the run was killed before its end
    assert meta["recomputed_chunks"] == len(resumed.chunk_seconds) - meta["resumed_chunks"]
    for name, data in before.items():  # finished chunk files are left as they were
        assert (out / CHUNKS / name).read_bytes() == data
    fresh = reachability_map(planar(*ARM), 0.2, 12, solver="numerical", chunk_voxels=1000,
                             progress=False)
    _same(fresh, resumed)


def test_resume_refuses_other_settings_naming_them(tmp_path):
    """Resuming a folder of another robot or resolution is refused with the differences."""
    out = tmp_path / "m"
    reachability_map(planar(2, [1.0, 0.6]), 0.2, out=out, progress=False)
    with pytest.raises(InputError, match=r"resolution: 0\.2 in the folder, 0\.25 now"):
        reachability_map(planar(2, [1.0, 0.6]), 0.25, out=out, resume=True, progress=False)
    with pytest.raises(InputError, match="robot_hash"):
        reachability_map(planar(2, [1.0, 0.7]), 0.2, out=out, resume=True, progress=False)
    with pytest.raises(InputError, match="already holds a reachability map"):
        reachability_map(planar(2, [1.0, 0.6]), 0.2, out=out, progress=False)
    again = reachability_map(planar(2, [1.0, 0.6]), 0.2, out=out, resume=True, progress=False)
    meta = json.loads((out / "metadata.json").read_text())
    assert meta["recomputed_chunks"] == 0 and again.reachable.any()


@pytest.mark.parametrize("resolution", [0.0, -0.1, float("nan")])
def test_bad_resolution(resolution):
    """A zero, negative or NaN resolution is an InputError naming the resolution."""
    with pytest.raises(InputError, match="resolution"):
        reachability_map(planar(2, [1.0, 0.6]), resolution, progress=False)


def test_grid_too_large_says_how_large_and_what_to_change():
    """A grid beyond the memory budget is refused before allocating, with size and advice."""
    set_memory_budget("100M")
    try:
        with pytest.raises(BudgetError) as err:
            reachability_map(models.get("ur5"), 0.002, progress=False)
    finally:
        set_memory_budget(None)
    text = str(err.value)
    assert "voxels" in text and "GiB" in text and "coarser resolution" in text


def test_unreachable_scheduler_fails_fast():
    """A scheduler address that does not answer gives an InputError within seconds."""
    pytest.importorskip("dask.distributed")
    import socket

    with socket.socket() as s:  # a free port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    # a guard against hangs, not a timing claim: the call returns, with the error
    err = outcome(lambda: connect(f"tcp://127.0.0.1:{port}", timeout=2.0))
    assert isinstance(err, InputError), repr(err)
    assert "did not answer within 2 s" in str(err)


def test_planar_task_on_spatial_robot_and_unknown_names():
    """A planar task on a spatial robot, unknown sampling/solver names are refused."""
    with pytest.raises(InputError, match="planar"):
        reachability_map(models.get("ur5"), 0.3, task="planar_pose", progress=False)
    with pytest.raises(InputError, match="sampling"):
        reachability_map(models.get("ur5"), 0.3, sampling="random", progress=False)
    with pytest.raises(InputError, match="solver"):
        reachability_map(models.get("ur5"), 0.3, solver="fast", progress=False)
    with pytest.raises(InputError, match="closed_form"):
        reachability_map(models.get("panda"), 0.3, solver="closed_form", progress=False)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"orientations": 0}, "orientations"), ({"seed": -1}, "seed"),
    ({"chunk_voxels": 0}, "chunk_voxels"), ({"bounds": [[0, 1], [0, 1]]}, "bounds"),
    ({"bounds": [[1, 0], [0, 1], [0, 1]]}, "bounds"), ({"restarts": -1}, "restarts"),
    ({"client": "tcp://x:1"}, "client"), ({"task": "orbit"}, "task"),
])
def test_bad_settings_name_the_argument(kwargs, match, tmp_path):
    """Each malformed setting raises the library's error naming it, before writing."""
    with pytest.raises((InputError, TypeError), match=match):
        reachability_map(planar(2, [1.0, 0.6]), 0.2, out=tmp_path / "m", progress=False,
                         **kwargs)
    assert not (tmp_path / "m").exists()


def test_scene_only_removes_reached_targets():
    """With obstacles (collision-aware numerical IK) no voxel reaches more orientations."""
    from serialkin.model.geometry import Sphere

    r = models.get("ur5")
    opts = {"bounds": [[0.3, 0.5], [-0.1, 0.1], [0.2, 0.4]], "solver": "numerical",
            "restarts": 8, "progress": False}
    try:
        blocked = reachability_map(r, 0.1, 4, scene=[Sphere(0.08, center=[0.4, 0.0, 0.3])], **opts)
    except InputError as exc:
        if "unknown option" in str(exc) and "scene" in str(exc):
            pytest.skip("this version's IK takes no collision scene yet")
        raise
    free = reachability_map(r, 0.1, 4, **opts)
    assert blocked.settings["scene_hash"] is not None
    assert np.all(blocked.reached <= free.reached)


def test_huge_orientation_count_is_refused_before_allocating():
    """10¹² orientations are refused by the memory budget, naming the setting."""
    with pytest.raises(BudgetError, match="orientations"):
        reachability_map(models.get("ur5"), 0.3, 10**12, progress=False)
