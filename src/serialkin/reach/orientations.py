"""Tool orientations sampled at every voxel of a reachability map.

Two documented sets, both deterministic (no random draw, so no seed):

* ``"uniform"`` — N rotations spread uniformly over SO(3) by a *super-Fibonacci spiral*
  (M. Alexa, "Super-Fibonacci Spirals: Fast, Low-Discrepancy Sampling of SO(3)", CVPR
  2022): for ``s = i + ½``, ``i = 0..N−1``,

  ``r = √(s/N)``, ``R = √(1 − s/N)``, ``α = 2π s / √2``, ``β = 2π s / ψ``,
  ``quaternion (x, y, z, w) = (r sin α, r cos α, R sin β, R cos β)``

  with ψ ≈ 1.533751 the real root of ψ⁴ = ψ + 4. The points have low discrepancy in
  the Haar measure of SO(3) for every N (no need for special counts).
* ``"approach"`` — D approach directions on the unit sphere (a Fibonacci lattice:
  ``z_i = 1 − (2i + 1)/D``, azimuth ``i·π(3 − √5)``), each with K rolls about it
  evenly spaced in [0, 2π): the tool z axis points along the direction, the tool x
  axis is the direction's reference perpendicular turned by the roll. N = D·K.

Planar arms use headings ``φ_k = −π + 2πk/N`` (tool x axis at angle φ in the plane).
"""

from __future__ import annotations

import math

import numpy as np

from serialkin._checks import check_choice, check_int
from serialkin.spatial import quaternion_to_matrix

#: Orientation sets of :func:`orientation_set`.
SAMPLINGS = ("uniform", "approach")

#: ψ, the real root of ψ⁴ = ψ + 4 (Alexa 2022).
_PSI = 1.533751168755204288118041


def super_fibonacci(count: int) -> np.ndarray:
    """``count`` rotations spread uniformly over SO(3) (super-Fibonacci spiral), (count, 3, 3).

    Raises:
        InputError: count not an integer >= 1.
    """
    count = check_int(count, "orientations", minimum=1)
    s = np.arange(count) + 0.5
    r = np.sqrt(s / count)
    R = np.sqrt(1.0 - s / count)
    alpha = 2.0 * math.pi * s / math.sqrt(2.0)
    beta = 2.0 * math.pi * s / _PSI
    quat_wxyz = np.stack([R * np.cos(beta), r * np.sin(alpha), r * np.cos(alpha),
                          R * np.sin(beta)], axis=-1)
    return np.ascontiguousarray(quaternion_to_matrix(quat_wxyz, normalize=True))


def fibonacci_sphere(count: int) -> np.ndarray:
    """``count`` unit vectors spread evenly on the sphere (Fibonacci lattice), (count, 3)."""
    count = check_int(count, "directions", minimum=1)
    i = np.arange(count)
    z = 1.0 - (2.0 * i + 1.0) / count
    rho = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    return np.stack([rho * np.cos(phi), rho * np.sin(phi), z], axis=-1)


def approach_orientations(directions: int, rolls: int) -> np.ndarray:
    """Rotations whose z axis is each of ``directions`` approach directions, ``rolls`` each.

    Returns:
        (directions·rolls, 3, 3); rotation ``d·rolls + k`` has z axis = direction d and
        its x axis turned by ``2πk/rolls`` about it from the reference perpendicular
        (the unit vector of ``e × z`` with e the world axis least aligned with z).
    """
    rolls = check_int(rolls, "rolls", minimum=1)
    z = fibonacci_sphere(directions)
    e = np.eye(3)[np.argmin(np.abs(z), axis=1)]
    x0 = np.cross(e, z)
    x0 /= np.linalg.norm(x0, axis=1, keepdims=True)
    y0 = np.cross(z, x0)
    ang = 2.0 * math.pi * np.arange(rolls) / rolls
    c, s = np.cos(ang)[None, :, None], np.sin(ang)[None, :, None]
    x = c * x0[:, None, :] + s * y0[:, None, :]
    y = -s * x0[:, None, :] + c * y0[:, None, :]
    zz = np.broadcast_to(z[:, None, :], x.shape)
    R = np.stack([x, y, zz], axis=-1)  # columns: tool x, y, z axes in the world
    return np.ascontiguousarray(R.reshape(-1, 3, 3))


def planar_headings(count: int) -> np.ndarray:
    """``count`` headings ``φ_k = −π + 2πk/count`` [rad], (count,)."""
    count = check_int(count, "orientations", minimum=1)
    return -math.pi + 2.0 * math.pi * np.arange(count) / count


def orientation_set(count: int, sampling: str = "uniform", *, rolls: int = 1) -> np.ndarray:
    """The rotations of a map: ``count`` uniform ones, or ``count`` directions × ``rolls``.

    Args:
        count: number of rotations ('uniform') or of approach directions ('approach').
        sampling: 'uniform' or 'approach' (see the module docstring).
        rolls: rolls per approach direction ('approach' only).

    Returns:
        (N, 3, 3) rotations, N = count ('uniform') or count·rolls ('approach').

    Raises:
        InputError: an unknown sampling (the valid names are listed), a count < 1.
    """
    sampling = check_choice(sampling, "sampling", SAMPLINGS)
    if sampling == "uniform":
        return super_fibonacci(count)
    return approach_orientations(count, rolls)
