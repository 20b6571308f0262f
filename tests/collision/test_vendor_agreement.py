"""The zoo robots' self-collision check against Pinocchio + coal on the vendor meshes."""

import pytest

from serialkin import models
from serialkin.collision.allowed_pairs import ALLOWED, METHOD
from serialkin.collision.reference import NO_VENDOR_MESHES, VENDOR, vendor_files

#: Margin [m] beyond which a false positive counts, and the largest rate allowed there.
MARGIN, MAX_FP = 0.03, 0.015


@pytest.mark.peer
@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(VENDOR))
def test_agrees_with_coal(name):
    """2,000 configurations: no false negative, few false positives beyond 30 mm, same frames."""
    files = vendor_files(name)
    if isinstance(files, str):
        pytest.skip(files)
    from serialkin.collision.reference import compare_with_coal

    a = compare_with_coal(models.get(name), name, 2000, seed=1, margin=MARGIN)
    assert a.frame_error < 1e-9
    assert a.false_negative == 0.0, a.fn_pairs
    assert a.false_positive <= MAX_FP, a.fp_pairs


@pytest.mark.parametrize("name", sorted(VENDOR))
def test_shipped_pairs_are_the_vendor_srdf(name):
    """The allowed pairs shipped with Panda and UR5 are exactly the vendor SRDF's."""
    files = vendor_files(name)
    if isinstance(files, str):
        pytest.skip(files)
    from serialkin.collision.srdf import read_srdf

    srdf = {tuple(sorted(p[:2])) for p in read_srdf(files[1]).disabled}
    assert {tuple(sorted(p)) for p in ALLOWED[name]} == srdf
    assert set(models.get(name).collision.allowed) == srdf


@pytest.mark.parametrize("name", NO_VENDOR_MESHES)
def test_sampled_pairs_never_or_always_touch(name):
    """Each sampled allowed pair is in contact in none or all of 2,000 fresh configurations."""
    import numpy as np

    from serialkin.collision.acm import AllowedCollisionMatrix
    from serialkin.collision.queries import body_pair_distances

    r = models.get(name)
    m = r.collision
    assert "sampled" in METHOD[name]
    rng = np.random.default_rng(7)
    lo, hi = np.clip(r.qlim[:, 0], -np.pi, None), np.clip(r.qlim[:, 1], None, np.pi)
    q = lo + (hi - lo) * rng.random((2000, r.n))
    acm = AllowedCollisionMatrix(m.body_names, np.eye(len(m.body_names), dtype=bool))
    pairs, d = body_pair_distances(r, m, q, acm)
    contact = {(m.body_names[i], m.body_names[j]): d[:, k] <= 0 for k, (i, j) in enumerate(pairs)}
    for a, b in ALLOWED[name]:
        c = contact.get((a, b), contact.get((b, a)))
        assert c.all() or not c.any(), (a, b)
