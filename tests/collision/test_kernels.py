"""Distance kernels: agreement with coal, brute force, symmetry and rigid-motion invariance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin.collision import kernels as K

coal = pytest.importorskip("coal", reason="coal (hpp-fcl) is a test-only peer: pip install coal")

N = 1500  # random pairs per shape pair


def _rot(rng) -> np.ndarray:
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _tf(R=None, p=None):
    T = coal.Transform3s()
    if R is not None:
        T.setRotation(np.asarray(R, float))
    if p is not None:
        T.setTranslation(np.asarray(p, float))
    return T


def _coal_capsule(a, b, r):
    L = float(np.linalg.norm(b - a))
    if L < 1e-12:
        return coal.Sphere(r), _tf(p=a)
    z = (b - a) / L
    x = np.cross(z, [1.0, 0, 0] if abs(z[0]) < 0.9 else [0, 1.0, 0])
    x /= np.linalg.norm(x)
    return coal.Capsule(r, L), _tf(np.column_stack([x, np.cross(z, x), z]), (a + b) / 2)


def _coal_distance(g1, T1, g2, T2):
    req = coal.DistanceRequest()
    req.gjk_tolerance = 1e-13
    req.epa_tolerance = 1e-13
    req.gjk_max_iterations = 1000
    res = coal.DistanceResult()
    d = coal.distance(g1, T1, g2, T2, req, res)
    return d, np.array(res.getNearestPoint1()), np.array(res.getNearestPoint2())


def _capsule(rng, scale=0.3):
    a = rng.uniform(-scale, scale, 3)
    b = a + rng.uniform(-scale, scale, 3) * (rng.random() > 0.1)  # 10 %: zero length
    if rng.random() < 0.1:  # nearly parallel to the previous draw's direction
        b = a + np.array([0.2, 0.0, 1e-9 * rng.random()])
    return a, b, rng.uniform(0.01, 0.15)


def _cases(kind: str, seed: int):
    """Random pairs; a third moved so that the shapes touch."""
    rng = np.random.default_rng(seed)
    for k in range(N):
        a0, a1, ra = _capsule(rng)
        if kind.startswith("sphere"):
            a1 = a0
        if kind.endswith("capsule"):
            b0, b1, rb = _capsule(rng)
            if kind == "capsule_capsule" and k % 7 == 0:  # exactly parallel, overlapping span
                b0, b1 = a0 + [0.0, 0.05, 0.0], a1 + [0.1, 0.05, 0.0]
            yield a0, a1, ra, ("capsule", b0, b1, rb), k % 3 == 0
        elif kind.endswith("sphere"):
            yield a0, a1, ra, ("sphere", rng.uniform(-0.3, 0.3, 3), rng.uniform(0.01, 0.15)), \
                k % 3 == 0
        elif kind.endswith("box"):
            yield a0, a1, ra, ("box", rng.uniform(-0.3, 0.3, 3), _rot(rng),
                               rng.uniform(0.01, 0.2, 3)), k % 3 == 0
        else:
            n = rng.normal(size=3)
            yield a0, a1, ra, ("halfspace", n / np.linalg.norm(n), rng.uniform(-0.3, 0.3)), \
                k % 3 == 0


def _ours(a0, a1, ra, other):
    if other[0] in ("capsule", "sphere"):
        b0 = other[1]
        b1 = other[2] if other[0] == "capsule" else other[1]
        return K.capsule_capsule(a0, a1, ra, b0, b1, other[-1])
    if other[0] == "box":
        return K.capsule_box(a0, a1, ra, other[1], other[2], other[3])
    return K.capsule_halfspace(a0, a1, ra, other[1], other[2])


def _coal_other(other):
    if other[0] == "capsule":
        return _coal_capsule(other[1], other[2], other[3])
    if other[0] == "sphere":
        return coal.Sphere(other[2]), _tf(p=other[1])
    if other[0] == "box":
        return coal.Box(*(2 * other[3])), _tf(other[2], other[1])
    return coal.Halfspace(other[1], float(other[2])), _tf()


def _touching(a0, a1, ra, other):
    """Move the second shape along the witness direction so that the shapes touch."""
    d, w1, w2 = _ours(a0, a1, ra, other)
    if other[0] == "halfspace":
        return other[:2] + (other[2] + d,)
    u = (w1 - w2) / max(np.linalg.norm(w1 - w2), 1e-300) if d > 0 else None
    if u is None:
        return other
    shift = d * u
    return (other[0],) + tuple(x + shift if isinstance(x, np.ndarray) and x.shape == (3,)
                               and i < (3 if other[0] == "capsule" else 2) else x
                               for i, x in enumerate(other[1:], start=1))


PAIRS = ["capsule_capsule", "capsule_sphere", "sphere_sphere", "capsule_box", "sphere_box",
         "capsule_halfspace", "sphere_halfspace"]


@pytest.mark.parametrize("kind", PAIRS)
def test_agrees_with_coal(kind):
    """Signed distance and witness points agree with coal to 1e-9 (separated and touching)."""
    seen = {"sep": 0, "touch": 0, "overlap": 0}
    for i, (a0, a1, ra, other, touch) in enumerate(_cases(kind, PAIRS.index(kind))):
        if touch:
            other = _touching(a0, a1, ra, other)
        d, w1, w2 = _ours(a0, a1, ra, other)
        g1, T1 = _coal_capsule(a0, a1, ra)
        g2, T2 = _coal_other(other)
        dc, c1, c2 = _coal_distance(g1, T1, g2, T2)
        assert abs(np.linalg.norm(w1 - w2) - abs(d)) < 1e-9 or d < 0, (kind, i)
        if d > 1e-9:
            seen["sep"] += 1
            assert abs(d - dc) < 1e-9, (kind, i, d, dc)
            if d > 1e-4:  # witnesses are unique when the distance is not degenerate
                assert abs(np.linalg.norm(w1 - c2) - ra) < 1e-6 or np.allclose(w2, c2, atol=1e-6)
        elif d > -1e-9:
            seen["touch"] += 1
            assert abs(dc) < 1e-9, (kind, i, d, dc)
        else:
            seen["overlap"] += 1
            assert dc < 1e-9, (kind, i, d, dc)
            if kind != "capsule_box":  # exact penetration depth: coal's EPA, to its tolerance
                crossing = kind == "capsule_capsule" and d == -(ra + other[-1])
                if not crossing:
                    assert abs(d - dc) < 1e-6, (kind, i, d, dc)
            else:  # the deepest-point depth is a lower bound on the penetration depth
                assert d >= dc - 1e-6, (kind, i, d, dc)
    assert min(seen.values()) > 20, seen


def test_separated_witnesses_realise_the_distance():
    """Separated pairs: ‖w1 − w2‖ = d and each witness lies on its shape's surface."""
    for kind in PAIRS:
        for a0, a1, ra, other, _ in _cases(kind, 100 + PAIRS.index(kind)):
            d, w1, w2 = _ours(a0, a1, ra, other)
            if d <= 1e-9:
                continue
            assert abs(np.linalg.norm(w1 - w2) - d) < 1e-12
            # points as tuples, as the library's batch kernels pass them
            assert abs(K.segment_distance(tuple(a0), tuple(a1), tuple(w1), tuple(w1)) - ra) \
                < 1e-9


def test_segment_distance_brute_force():
    """Segment–segment distance equals the minimum over a dense grid of (s, t) to its spacing."""
    rng = np.random.default_rng(7)
    s = np.linspace(0, 1, 401)
    for _ in range(100):
        a0, a1, b0, b1 = rng.uniform(-1, 1, (4, 3))
        if rng.random() < 0.3:
            b1 = b0 + (a1 - a0) * rng.uniform(-2, 2)  # parallel
        P = a0 + s[:, None] * (a1 - a0)
        Q = b0 + s[:, None] * (b1 - b0)
        brute = np.linalg.norm(P[:, None] - Q[None], axis=2).min()
        d = K.segment_distance(tuple(a0), tuple(a1), tuple(b0), tuple(b1))  # as the library
        step = (np.linalg.norm(a1 - a0) + np.linalg.norm(b1 - b0)) / 400
        assert d <= brute + 1e-12
        assert brute - d <= step


def test_capsule_box_brute_force():
    """Capsule–box distance equals the minimum of sphere–box over dense samples of the axis."""
    rng = np.random.default_rng(8)
    t = np.linspace(0, 1, 2001)
    for _ in range(60):
        a0, a1 = rng.uniform(-0.5, 0.5, (2, 3))
        c, R, h = rng.uniform(-0.2, 0.2, 3), _rot(rng), rng.uniform(0.02, 0.2, 3)
        d = K.capsule_box(a0, a1, 0.05, c, R, h)[0]
        brute = min(K.sphere_box(a0 + x * (a1 - a0), 0.05, c, R, h)[0] for x in t)
        assert d <= brute + 1e-12
        assert brute - d <= np.linalg.norm(a1 - a0) / 2000


def test_box_point_inside_and_outside():
    """Point–box signed distance: minus the nearest-face distance inside, Euclidean outside."""
    c, R, h = np.zeros(3), np.eye(3), np.array([0.1, 0.2, 0.3])
    assert K.box_point(c, R, h, np.array([0.05, 0.0, 0.0]))[0] == pytest.approx(-0.05)
    sd, q = K.box_point(c, R, h, np.array([0.4, 0.6, 0.0]))
    assert sd == pytest.approx(math.hypot(0.3, 0.4))
    assert np.allclose(q, [0.1, 0.2, 0.0])


_vec = st.lists(st.floats(-1, 1, allow_nan=False), min_size=3, max_size=3).map(np.array)
_rad = st.floats(0.0, 0.3)


@settings(max_examples=80, deadline=None)
@given(_vec, _vec, _rad, _vec, _vec, _rad)
def test_capsule_capsule_symmetric(a0, a1, ra, b0, b1, rb):
    """d(A, B) = d(B, A) and the witnesses swap."""
    d1, w1, w2 = K.capsule_capsule(a0, a1, ra, b0, b1, rb)
    d2, v1, v2 = K.capsule_capsule(b0, b1, rb, a0, a1, ra)
    assert d1 == pytest.approx(d2, abs=1e-12)
    if d1 > 1e-6:
        assert np.linalg.norm(v1 - v2) == pytest.approx(np.linalg.norm(w1 - w2), abs=1e-12)


@settings(max_examples=80, deadline=None)
@given(_vec, _vec, _rad, _vec, _vec, st.integers(0, 2**32 - 1))
def test_rigid_motion_invariance(a0, a1, ra, c, h, seed):
    """A rigid motion of both shapes changes neither capsule–capsule nor capsule–box distance."""
    rng = np.random.default_rng(seed)
    R, p = _rot(rng), rng.uniform(-1, 1, 3)
    h = np.abs(h) * 0.3
    Rb = _rot(rng)
    b0, b1 = c, c + h

    def move(x):
        return R @ x + p

    d = K.capsule_capsule(a0, a1, ra, b0, b1, 0.1)[0]
    assert K.capsule_capsule(move(a0), move(a1), ra, move(b0), move(b1), 0.1)[0] == \
        pytest.approx(d, abs=1e-12)
    e = K.capsule_box(a0, a1, ra, c, Rb, h)[0]
    assert K.capsule_box(move(a0), move(a1), ra, move(c), R @ Rb, h)[0] == \
        pytest.approx(e, abs=1e-10)
