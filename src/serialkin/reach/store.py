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


def _differences(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    out = []
    for key in sorted(set(old) | set(new)):
        a, b = old.get(key), new.get(key)
        if a != b:
            out.append(f"{key}: {json.dumps(a)} in the folder, {json.dumps(b)} now")
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
            old = json.loads(man.read_text(encoding="utf-8"))
            old_settings = old["settings"]
            if old.get("format") != FORMAT:
                raise ValueError(f"format {old.get('format')!r}, expected {FORMAT!r}")
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise InputError(f"cannot resume {str(path)!r}: unreadable {MANIFEST}: "
                             f"{exc}") from exc
        diff = _differences(old_settings, json.loads(json.dumps(settings)))
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


def read_chunk(folder: Path, c: int, start: int, stop: int) -> dict[str, Any] | None:
    """Chunk c's result if its file is there and whole (covering start..stop), else None."""
    p = chunk_path(folder, c)
    if not p.exists():
        return None
    try:
        with np.load(p, allow_pickle=False) as z:
            if int(z["start"]) != start or int(z["stop"]) != stop:
                return None
            out: dict[str, Any] = {k: np.asarray(z[k]) for k in FIELDS}
            out["seconds"] = float(z["seconds"])
    except (OSError, KeyError, ValueError, EOFError):
        return None
    if any(out[k].shape != (stop - start,) for k in FIELDS):
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
