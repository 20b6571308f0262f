"""A resumed map trusts nothing on disk: tampered chunks are recomputed, bad manifests refused."""

from __future__ import annotations

import io
import json
import warnings

import numpy as np
import pytest

from serialkin.errors import InputError
from serialkin.models.planar import planar
from serialkin.reach import reachability_map
from serialkin.reach.store import CHUNKS, MANIFEST


def _map(out=None, resume=False):
    return reachability_map(planar(2, [1.0, 0.6]), 0.2, 8, chunk_voxels=20, out=out,
                            resume=resume, progress=False)


def _rewrite(path, **changes):
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: np.array(z[k]) for k in z.files}
    for key, change in changes.items():
        arrays[key] = change(arrays[key])
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    path.write_bytes(buf.getvalue())


TAMPERING = {
    "reached above the orientations": dict(reached=lambda a: np.full_like(a, 999)),
    "negative reached": dict(reached=lambda a: np.full_like(a, -5)),
    "NaN manipulability": dict(manipulability_mean=lambda a: np.full_like(a, np.nan)),
    "solutions below reached": dict(solutions=lambda a: np.zeros_like(a),
                                    reached=lambda a: np.ones_like(a)),
    "another chunk's range": dict(start=lambda a: a + 1, stop=lambda a: a + 1),
    "wrong dtype": dict(reached=lambda a: a.astype(np.float64)),
    "wrong length": dict(solutions=lambda a: a[:-1]),
}


@pytest.mark.parametrize("case", [*TAMPERING, "truncated", "not a zip"])
def test_a_tampered_chunk_is_recomputed_with_a_warning(tmp_path, case):
    """Each kind of bad chunk file warns naming the file and is computed again: same map."""
    out = tmp_path / "m"
    fresh = _map(out)
    chunk = sorted((out / CHUNKS).glob("c*.npz"))[1]
    if case == "truncated":
        chunk.write_bytes(chunk.read_bytes()[:100])
    elif case == "not a zip":
        chunk.write_bytes(b"\x00" * 64)
    else:
        _rewrite(chunk, **TAMPERING[case])
    (out / "map.npz").unlink()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        again = _map(out, resume=True)
    assert any(chunk.name in str(w.message) for w in caught), [str(w.message) for w in caught]
    for key in ("reached", "solutions", "manipulability_mean"):
        np.testing.assert_array_equal(getattr(fresh, key), getattr(again, key))


@pytest.mark.parametrize("manifest", ["[]", "{}", '{"format": "serialkin-reach/1", '
                                      '"settings": null}', '"text"', "", "{", "folder"])
def test_a_broken_manifest_is_a_clear_error(tmp_path, manifest):
    """A manifest that is a list, null settings, a string, empty, broken or a folder: InputError."""
    out = tmp_path / "m"
    _map(out)
    man = out / MANIFEST
    man.unlink()
    if manifest == "folder":
        man.mkdir()
    else:
        man.write_text(manifest)
    with pytest.raises(InputError, match="not a map manifest"):
        _map(out, resume=True)


def test_an_untouched_folder_resumes_silently(tmp_path):
    """Valid chunk files are read without warnings."""
    out = tmp_path / "m"
    _map(out)
    (out / "map.npz").unlink()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        _map(out, resume=True)
    assert json.loads((out / "metadata.json").read_text())["recomputed_chunks"] == 0
