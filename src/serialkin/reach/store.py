"""A map's output folder: a manifest, one NPZ file per finished chunk, the assembled map.

Layout of ``folder``::

    manifest.json        format, the job's settings (robot hash, grid, orientations, ...)
                         and their hash
    chunks/c0000012.npz  chunk 12's per-voxel arrays and its wall time, written atomically
    map.npz              the assembled map (ReachMap.save), once every chunk is there
    metadata.json        summary and per-chunk timings

Every file is written through :mod:`serialkin._io` (temporary file + rename): a run
killed at any moment leaves only whole chunk files, and ``resume=True`` recomputes
exactly the chunks that have none. A folder whose manifest records other settings is
refused, naming each difference.
"""

from __future__ import annotations

import hashlib
import io
import json
import warnings
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from serialkin._io import write_bytes_atomic, write_text_atomic
from serialkin.errors import InputError, OutputError
from serialkin.reach.chunk import FIELDS

FORMAT = "serialkin-reach/1"
MANIFEST = "manifest.json"
CHUNKS = "chunks"


def chunk_path(folder: Path, c: int) -> Path:
    """Path of chunk c's file."""
    return folder / CHUNKS / f"c{c:07d}.npz"


def settings_hash(settings: dict[str, Any]) -> str:
    """SHA-256 (16 hex digits) of the settings' canonical JSON: equal settings, equal hash."""
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def differences(old: dict[str, Any], new: dict[str, Any], where: str = "in the folder"
                ) -> list[str]:
    """``'key: <old> <where>, <new> now'`` for every key whose values differ (JSON text)."""
    out = []
    for key in sorted(set(old) | set(new)):
        a, b = old.get(key), new.get(key)
        if a != b:
            out.append(f"{key}: {json.dumps(a)} {where}, {json.dumps(b)} now")
    return out


def open_folder(folder: str | Path, settings: dict[str, Any], resume: bool) -> Path:
    """Prepare ``folder`` for a run with ``settings``; check a resumed folder's manifest.

    Raises:
        InputError: the folder holds a map and ``resume`` is False; or ``resume`` is True
            and the manifest differs (each differing setting named) or is unreadable.
        OutputError: the folder cannot be written.
    """
    path = Path(folder)
    man = path / MANIFEST
    record = {"format": FORMAT, "settings_hash": settings_hash(settings), "settings": settings}
    if man.exists():
        if not resume:
            raise InputError(f"{str(path)!r} already holds a reachability map; pass "
                             "resume=True (--resume) to continue it, or choose another folder")
        try:
            if not man.is_file():
                raise ValueError("not a regular file")
            old = json.loads(man.read_text(encoding="utf-8"))
            if not isinstance(old, dict):
                raise ValueError(f"a JSON {type(old).__name__}, expected an object")
            if old.get("format") != FORMAT:
                raise ValueError(f"format {str(old.get('format'))[:60]!r}, expected {FORMAT!r}")
            old_settings = old.get("settings")
            if not isinstance(old_settings, dict):
                raise ValueError(f"'settings' is {type(old_settings).__name__}, expected an "
                                 "object")
        except (OSError, ValueError, UnicodeDecodeError, RecursionError) as exc:
            raise InputError(f"cannot resume {str(path)!r}: {MANIFEST} is not a map manifest "
                             f"({str(exc)[:160]}); remove the folder or choose another") \
                from None
        diff = differences(old_settings, json.loads(json.dumps(settings)))
        if diff:
            raise InputError(f"cannot resume {str(path)!r}: it was written with other "
                             "settings (" + "; ".join(diff) + ")")
        return path
    if path.exists() and not path.is_dir():
        raise OutputError(f"{str(path)!r} exists and is not a folder")
    write_text_atomic(man, json.dumps(record, indent=1))
    return path


def write_chunk(folder: Path, result: dict[str, Any]) -> Path:
    """Write one chunk's result (from ``compute_chunk``) atomically."""
    buf = io.BytesIO()
    np.savez(buf, start=result["start"], stop=result["stop"], seconds=result["seconds"],
             **{k: result[k] for k in FIELDS})
    return write_bytes_atomic(chunk_path(folder, int(result["chunk"])), buf.getvalue())


#: Most solutions of one orientation (closed-form IK of a 6R arm).
MAX_SOLUTIONS = 16


def _chunk_problem(z: Any, start: int, stop: int, orientations: int) -> str | None:
    """What is wrong with a chunk file's arrays (None: nothing), checked value by value."""
    if set(z.files) != {"start", "stop", "seconds", *FIELDS}:
        return f"arrays {sorted(z.files)}, expected {sorted({'start', 'stop', 'seconds', *FIELDS})}"
    for key in ("start", "stop", "seconds"):
        if z[key].shape != () or z[key].dtype.kind not in "iuf":
            return f"{key!r} is not a number"
    if int(z["start"]) != start or int(z["stop"]) != stop:
        return (f"it covers voxels {int(z['start'])}..{int(z['stop'])}, not this chunk's "
                f"{start}..{stop}")
    seconds = float(z["seconds"])
    if not (np.isfinite(seconds) and seconds >= 0):
        return f"its time {seconds!r} s is not a finite duration"
    a = {}
    for key, dtype in FIELDS.items():
        v = z[key]
        if v.dtype != np.dtype(dtype) or v.shape != (stop - start,):
            return f"{key!r} is {v.dtype} {v.shape}, expected {np.dtype(dtype)} ({stop - start},)"
        a[key] = v
    reached, sols = a["reached"], a["solutions"]
    if reached.min(initial=0) < 0 or reached.max(initial=0) > orientations:
        return f"'reached' outside 0..{orientations} (the orientations sampled)"
    if (sols < reached).any() or (sols > MAX_SOLUTIONS * reached).any():
        return "'solutions' below 'reached' or above 16 per reached orientation"
    lo, mean, hi = (a[f"manipulability_{k}"] for k in ("min", "mean", "max"))
    if not all(np.isfinite(m).all() and (m >= 0).all() for m in (lo, mean, hi)):
        return "a manipulability that is negative or not finite"
    tol = 1e-9 * np.maximum(1.0, hi)
    some = reached > 0
    if ((lo > mean + tol) | (mean > hi + tol))[some].any():
        return "manipulability statistics out of order (min <= mean <= max)"
    if ((lo != 0) | (mean != 0) | (hi != 0))[~some].any():
        return "a manipulability where nothing is reached"
    return None


def read_chunk(folder: Path, c: int, start: int, stop: int,
               orientations: int) -> dict[str, Any] | None:
    """Chunk c's result if its file is there, whole and valid, else None.

    A chunk file is data from disk, never trusted: every array is checked (its dtype and
    shape, ``start..stop`` equal to the chunk's, 0 <= reached <= ``orientations``,
    reached <= solutions <= 16·reached, manipulabilities finite, non-negative, ordered,
    and 0 where nothing is reached). A file that fails is reported by a
    :class:`RuntimeWarning` naming it and the reason, and None is returned: the chunk is
    computed again. Never unpickled (``allow_pickle=False``).
    """
    p = chunk_path(folder, c)
    if not p.exists():
        return None
    try:
        with np.load(p, allow_pickle=False) as z:
            problem = _chunk_problem(z, start, stop, orientations)
            out: dict[str, Any] = {} if problem else {k: np.asarray(z[k]) for k in FIELDS}
            if not problem:
                out["seconds"] = float(z["seconds"])
    except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        problem = f"unreadable ({type(exc).__name__}: {str(exc)[:80]})"
    if problem:
        warnings.warn(f"{p}: {problem}; the chunk is computed again", RuntimeWarning,
                      stacklevel=2)
        return None
    out.update(chunk=c, start=start, stop=stop)
    return out


def done_chunks(folder: Path, count: int) -> set[int]:
    """Indices of the chunks whose file exists (checked for wholeness when read)."""
    d = folder / CHUNKS
    if not d.is_dir():
        return set()
    done = set()
    for p in d.glob("c*.npz"):
        try:
            c = int(p.stem[1:])
        except ValueError:
            continue
        if 0 <= c < count:
            done.add(c)
    return done
