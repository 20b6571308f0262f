"""The allowed-collision matrix: body pairs whose contact is allowed (never checked).

Three sources, combined with :meth:`AllowedCollisionMatrix.allow`:

* :func:`default_acm` — every body with itself, bodies on the same link frame (one rigid
  part) and bodies on adjacent frames (joined by a joint, usually touching): frames that
  follow each other among the frames carrying bodies, so that a frame without a body (a
  massless link between coincident joint axes, as in a spherical wrist) does not separate
  its neighbours;
* :func:`acm_from_srdf` — an SRDF's ``<disable_collisions>`` pairs, added to the default;
* :func:`~serialkin.collision.queries.sampled_acm` — pairs in contact in *every* sampled
  configuration (as MoveIt's setup assistant finds "always in collision" pairs): ``q``
  drawn uniformly within the joint limits (seeded), contact meaning a signed distance
  ≤ ``margin``. It measures distances, so it lives with the distance queries
  (:mod:`serialkin.collision.queries`, which import this module, not the reverse).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from serialkin._checks import short_repr
from serialkin.collision.srdf import Srdf, read_srdf
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError
from serialkin.model.collision_model import CollisionModel

__all__ = ["AllowedCollisionMatrix", "acm_from_srdf", "check_acm", "default_acm"]


@dataclass(frozen=True)
class AllowedCollisionMatrix:
    """A symmetric boolean (B, B) matrix over a model's bodies: True = never checked.

    Attributes:
        body_names: (B,) the bodies, in the model's order.
        allowed: (B, B) bool, symmetric, True on the diagonal.
    """

    body_names: tuple[str, ...]
    allowed: np.ndarray

    def __post_init__(self) -> None:
        m = np.array(self.allowed, dtype=bool)
        B = len(self.body_names)
        if m.shape != (B, B):
            raise InputError(f"allowed must have shape ({B}, {B}), got {m.shape}")
        m = m | m.T
        np.fill_diagonal(m, True)
        m.setflags(write=False)
        object.__setattr__(self, "body_names", tuple(self.body_names))
        object.__setattr__(self, "allowed", m)

    def allow(self, pairs: Iterable[tuple[str, str]]) -> AllowedCollisionMatrix:
        """A copy that also allows the named body pairs (InputError for unknown names)."""
        m = self.allowed.copy()
        index = {n: i for i, n in enumerate(self.body_names)}
        for a, b in pairs:
            for x in (a, b):
                if x not in index:
                    raise InputError(f"unknown body {short_repr(x, 80)}; bodies: "
                                     f"{', '.join(self.body_names)}")
            m[index[a], index[b]] = m[index[b], index[a]] = True
        return AllowedCollisionMatrix(self.body_names, m)

    def is_allowed(self, a: str, b: str) -> bool:
        """True when the contact of bodies ``a`` and ``b`` is allowed."""
        return bool(self.allowed[self.body_names.index(a), self.body_names.index(b)])

    def checked_pairs(self) -> list[tuple[str, str]]:
        """The body pairs (i < j) that are checked."""
        B = len(self.body_names)
        return [(self.body_names[i], self.body_names[j]) for i in range(B)
                for j in range(i + 1, B) if not self.allowed[i, j]]


def default_acm(model: CollisionModel) -> AllowedCollisionMatrix:
    """Allow bodies on the same frame and on adjacent frames, and the model's ``allowed`` pairs.

    Frames ``i < j`` are adjacent when no body is fixed to a frame strictly between them
    (for a model with bodies on every frame: ``|frame_i − frame_j| ≤ 1``).
    """
    f = model.body_frames
    rank = np.searchsorted(np.unique(f), f)  # index of each body's frame among used frames
    acm = AllowedCollisionMatrix(model.body_names, np.abs(rank[:, None] - rank[None, :]) <= 1)
    return acm.allow(model.allowed) if model.allowed else acm


def acm_from_srdf(model: CollisionModel, srdf: Srdf | str | os.PathLike[str],
                  acm: AllowedCollisionMatrix | None = None, *,
                  skip_links: Iterable[str] = ()) -> AllowedCollisionMatrix:
    """Add an SRDF's ``<disable_collisions>`` pairs to ``acm`` (default: :func:`default_acm`).

    Args:
        model: the collision model whose bodies the SRDF's links name.
        srdf: an :class:`Srdf`, a file or an XML string.
        acm: the matrix to extend (default: :func:`default_acm` of ``model``).
        skip_links: links that exist in the robot but carry no body in ``model`` (e.g.
            gripper fingers on joints off the chain): pairs naming them are skipped.

    Raises:
        RobotDefinitionError: the SRDF names a link that is neither a body of ``model``
            nor in ``skip_links`` (the message names the SRDF, the link and lists the
            bodies).
    """
    s = srdf if isinstance(srdf, Srdf) else read_srdf(srdf)
    known = set(model.body_names)
    skip = {str(x) for x in skip_links} - known
    pairs = []
    for a, b, _ in s.disabled:
        for x in (a, b):
            if x not in known and x not in skip:
                raise RobotDefinitionError(
                    f"{s.source}: disable_collisions names link {short_repr(x, 80)}, which "
                    "is not a body of "
                    f"the collision model; bodies: {', '.join(model.body_names)} (a link "
                    "without capsules, such as a finger off the chain, can be given in "
                    "skip_links)")
        if a not in skip and b not in skip:
            pairs.append((a, b))
    base = default_acm(model) if acm is None else acm
    return base.allow(pairs)


def check_acm(acm: object) -> AllowedCollisionMatrix | None:
    """``acm`` itself when it is an :class:`AllowedCollisionMatrix` or None.

    The argument check of every function that takes an ``acm``.

    Raises:
        InputTypeError: anything else (the message names its type and value).
    """
    if acm is not None and not isinstance(acm, AllowedCollisionMatrix):
        raise InputTypeError(f"acm must be an AllowedCollisionMatrix or None, got "
                             f"{type(acm).__name__} {short_repr(acm)}")
    return acm
