"""The robot collision model: capsules and spheres on the link frames, as flat arrays.

A *body* is a named rigid part (a URDF/SRDF link, e.g. ``panda_link3`` or ``panda_hand``)
fixed to one link frame of the robot: frame index ``0..n`` of :meth:`Robot.fk_all`
(0 = base, i = after joint i). Several bodies may share a frame (a hand on the last link).
Each body carries capsules (segment ``a b`` and radius, in its frame's coordinates,
metres); a sphere is the capsule with ``a = b``. The shapes are held as flat arrays so
that the compiled kernels read them directly.

Dictionary form (robot files, :meth:`CollisionModel.from_dicts`)::

    [{"name": "panda_link1", "frame": 1,
      "capsules": [{"a": [0, 0, -0.19], "b": [0, 0, 0], "radius": 0.08}],
      "spheres": [{"center": [0, 0, 0.05], "radius": 0.06}]},
     ...]

``capsules`` and ``spheres`` are optional (a body without shapes may still be named by an
SRDF).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from serialkin._checks import as_float_array, short_repr
from serialkin.errors import InputError, InputTypeError

__all__ = ["CollisionModel"]


@dataclass(frozen=True)
class CollisionModel:
    """Capsules and spheres per body, bodies per link frame (flat arrays, metres).

    Attributes:
        body_names: (B,) unique body names.
        body_frames: (B,) int, the link frame (0..n) each body is fixed to.
        shape_body: (m,) int, the body of each shape.
        a: (m, 3) first end of each capsule axis in its frame [m].
        b: (m, 3) second end [m] (``a = b`` for a sphere).
        radius: (m,) radius [m], ≥ 0.
        source: where the numbers come from.
        allowed: body-name pairs whose contact is always allowed (never checked) beyond the
            adjacent ones of :func:`~serialkin.collision.acm.default_acm`, e.g. pairs whose
            capsules overlap in every configuration; stored sorted, each pair sorted.

    Raises:
        InputError: inconsistent lengths, a negative or non-finite radius or point, an
            unknown body index, a negative frame, duplicate body names (the message names
            the field and the index).
    """

    body_names: tuple[str, ...]
    body_frames: np.ndarray
    shape_body: np.ndarray
    a: np.ndarray
    b: np.ndarray
    radius: np.ndarray
    source: str = ""
    allowed: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        names = tuple(self.body_names)
        for i, nm in enumerate(names):
            if not isinstance(nm, str) or not nm:
                raise InputTypeError(f"body_names[{i}] must be a non-empty string, "
                                     f"got {short_repr(nm)}")
        if len(set(names)) != len(names):
            dup = sorted({x for x in names if names.count(x) > 1})
            raise InputError(f"body_names must be unique, got duplicates {dup}")
        frames = _ints(self.body_frames, "body_frames", len(names))
        if (frames < 0).any():
            i = int(np.argmax(frames < 0))
            raise InputError(f"body_frames[{i}] must be >= 0, got {frames[i]}")
        sb = _ints(self.shape_body, "shape_body", None)
        m = sb.shape[0]
        if m and (sb.min() < 0 or sb.max() >= len(names)):
            i = int(np.argmax((sb < 0) | (sb >= len(names))))
            raise InputError(f"shape_body[{i}] must be a body index in 0..{len(names) - 1}, "
                             f"got {sb[i]}")
        pts = {}
        for field in ("a", "b"):
            p = as_float_array(getattr(self, field), field)
            if p.shape != (m, 3):
                raise InputError(f"{field} must have shape ({m}, 3), got {p.shape}")
            pts[field] = np.ascontiguousarray(p)
        r = as_float_array(self.radius, "radius")
        if r.shape != (m,):
            raise InputError(f"radius must have shape ({m},), got {r.shape}")
        if (r < 0).any():
            i = int(np.argmax(r < 0))
            raise InputError(f"radius[{i}] (a shape of body {names[sb[i]]!r}) must be >= 0, "
                             f"got {r[i]}")
        pairs = set()
        for i, pair in enumerate(self.allowed):
            if isinstance(pair, (str, bytes)) or len(pair) != 2:
                raise InputError(f"allowed[{i}] must be a pair of body names, got "
                                 f"{short_repr(pair)}")
            for x in pair:
                if x not in names:
                    raise InputError(f"allowed[{i}] names an unknown body {short_repr(x)}; "
                                     f"bodies: {', '.join(names)}")
            if pair[0] != pair[1]:
                pairs.add(tuple(sorted(pair)))
        object.__setattr__(self, "allowed", tuple(sorted(pairs)))
        for k, v in (("body_names", names), ("body_frames", frames), ("shape_body", sb),
                     ("a", pts["a"]), ("b", pts["b"]), ("radius", np.ascontiguousarray(r))):
            if isinstance(v, np.ndarray):
                v.setflags(write=False)
            object.__setattr__(self, k, v)

    @property
    def shape_frame(self) -> np.ndarray:
        """(m,) int: the link frame of each shape."""
        return self.body_frames[self.shape_body]

    def body_index(self, name: str) -> int:
        """Index of the body called ``name``; InputError listing the names if unknown."""
        try:
            return self.body_names.index(name)
        except ValueError:
            raise InputError(f"unknown body {short_repr(name)}; bodies: "
                             f"{', '.join(self.body_names)}") from None

    @classmethod
    def from_dicts(cls, bodies: Sequence[Mapping], source: str = "") -> CollisionModel:
        """Build from the dictionary form of the module docstring.

        A body may list ``allowed``: names of other bodies it may always touch (see
        :attr:`allowed`).

        Raises:
            InputError / InputTypeError: a missing or malformed entry; the message names
                it, e.g. ``bodies[2].capsules[0].radius``.
        """
        if isinstance(bodies, (str, bytes, Mapping)) or not isinstance(bodies, Sequence):
            raise InputTypeError(f"bodies must be a list of mappings, got {short_repr(bodies)}")
        names, frames, sb, A, B, R = [], [], [], [], [], []
        allowed: list[tuple[str, str]] = []
        for i, body in enumerate(bodies):
            where = f"bodies[{i}]"
            if not isinstance(body, Mapping):
                raise InputTypeError(f"{where} must be a mapping, got {short_repr(body)}")
            unknown = set(body) - {"name", "frame", "capsules", "spheres", "allowed"}
            if unknown:
                raise InputError(f"{where} has unknown keys {sorted(map(str, unknown))}; "
                                 "expected name, frame, capsules, spheres, allowed")
            others = body.get("allowed", [])
            if isinstance(others, (str, bytes)) or not isinstance(others, Sequence):
                raise InputTypeError(f"{where}.allowed must be a list of body names, got "
                                     f"{short_repr(others)}")
            allowed += [(body.get("name"), other) for other in others]
            for key in ("name", "frame"):
                if key not in body:
                    raise InputError(f"{where}.{key} is missing")
            names.append(body["name"])
            f = body["frame"]
            if isinstance(f, bool) or not isinstance(f, (int, np.integer)):
                raise InputTypeError(f"{where}.frame must be an integer, got {short_repr(f)}")
            frames.append(int(f))
            for kind, keys in (("capsules", ("a", "b")), ("spheres", ("center",))):
                items = body.get(kind, [])
                if not isinstance(items, Sequence) or isinstance(items, (str, bytes)):
                    raise InputTypeError(f"{where}.{kind} must be a list, got {short_repr(items)}")
                for j, s in enumerate(items):
                    w = f"{where}.{kind}[{j}]"
                    if not isinstance(s, Mapping) or set(s) != {*keys, "radius"}:
                        raise InputError(f"{w} must be a mapping with keys "
                                         f"{', '.join((*keys, 'radius'))}, got {short_repr(s)}")
                    pts = [as_float_array(s[k], f"{w}.{k}") for k in keys]
                    for k, p in zip(keys, pts, strict=True):
                        if p.shape != (3,):
                            raise InputError(f"{w}.{k} must be 3 numbers, got shape {p.shape}")
                    r = as_float_array(s["radius"], f"{w}.radius")
                    if r.shape != () or r < 0:
                        raise InputError(f"{w}.radius must be a number >= 0, "
                                         f"got {short_repr(s['radius'])}")
                    sb.append(i)
                    A.append(pts[0])
                    B.append(pts[-1])
                    R.append(float(r))
        return cls(tuple(names), np.array(frames, dtype=np.int64), np.array(sb, dtype=np.int64),
                   np.reshape(np.array(A, dtype=float), (-1, 3)),
                   np.reshape(np.array(B, dtype=float), (-1, 3)), np.array(R, dtype=float),
                   source, tuple(allowed))

    def to_dicts(self) -> list[dict]:
        """The dictionary form (inverse of :meth:`from_dicts`)."""
        out = [{"name": nm, "frame": int(f), "capsules": [], "spheres": []}
               for nm, f in zip(self.body_names, self.body_frames, strict=True)]
        for s, bi in enumerate(self.shape_body):
            a, b, r = self.a[s].tolist(), self.b[s].tolist(), float(self.radius[s])
            if a == b:
                out[bi]["spheres"].append({"center": a, "radius": r})
            else:
                out[bi]["capsules"].append({"a": a, "b": b, "radius": r})
        index = {nm: i for i, nm in enumerate(self.body_names)}
        for a, b in self.allowed:
            out[index[a]].setdefault("allowed", []).append(b)
        return out


def _ints(x: object, name: str, size: int | None) -> np.ndarray:
    a = np.asarray(x)
    if a.size == 0:
        a = a.astype(np.int64)
    if a.dtype.kind not in "iu" or a.ndim != 1 or (size is not None and a.shape[0] != size):
        want = f"({size},)" if size is not None else "(m,)"
        raise InputError(f"{name} must be an integer array of shape {want}, "
                         f"got {short_repr(x)}")
    return np.ascontiguousarray(a.astype(np.int64))
