"""Self-collision in QP tracking: the robot's collision model and the allowed pairs of the rest.

A ``QPResolver(self_collision=True)`` on a robot with a collision model keeps apart the body
pairs that ``robot.clearance`` checks, with the same allowed pairs: the model's default
matrix, a matrix given as ``acm``, or the default with an SRDF's ``<disable_collisions>``
(``srdf``, ``skip_links``). The arm: a 6-link planar arm (links 0.1 m, capsules of radius
5 mm) folded towards its base, where link 1 and link 6 cross unless kept apart.
"""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.collision import acm_from_srdf
from serialkin.diffik.resolver import QPResolver
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError
from serialkin.spatial.segments import closest_segment_segment
from serialkin.tracking import Path, planar_arm, track

Q0 = np.full(6, 0.1)
FOLD = Path.polyline([[0.5, 0.1], [0.05, 0.0], [0.0, 0.0]], 0.02)


def _srdf(tmp_path, a: str, b: str):
    path = tmp_path / f"{a}_{b}.srdf"
    path.write_text(f'<robot name="planar6"><disable_collisions link1="{a}" link2="{b}" '
                    'reason="test"/></robot>', encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def arm():
    return sk.models.planar(6, 0.1)


def _qp(**kw):
    return QPResolver(task="planar", safety=0.005, **kw)


def _pair_distance(arm, Q, i: int, j: int) -> float:
    """Smallest signed distance of link capsules i and j (1-based) over Q [m], by hand.

    Link i runs from the origin of frame i − 1 to that of frame i, radius 5 % of its length.
    """
    radius = 0.05 * 0.1
    worst = np.inf
    for q in Q:
        P = arm.fk_all(q)[:, :3, 3]
        s, t = closest_segment_segment(tuple(P[i - 1]), tuple(P[i]), tuple(P[j - 1]),
                                       tuple(P[j]))
        gap = P[i - 1] + s * (P[i] - P[i - 1]) - P[j - 1] - t * (P[j] - P[j - 1])
        worst = min(worst, float(np.linalg.norm(gap)) - 2 * radius)
    return worst


@pytest.fixture(scope="module")
def free_run(arm):
    return track(arm, FOLD, _qp(), q0=Q0)


@pytest.fixture(scope="module")
def kept_run(arm):
    return track(arm, FOLD, _qp(self_collision=True), q0=Q0)


def test_without_self_collision_the_folding_links_cross(arm, free_run):
    """The fold makes link 1 and link 6 overlap when nothing keeps them apart."""
    assert _pair_distance(arm, free_run.q, 1, 6) < -0.005
    assert arm.in_collision(free_run.q).any()


def test_self_collision_keeps_the_collision_models_pairs_apart(arm, kept_run):
    """Every configuration is free by ``robot.clearance`` with the model's default pairs."""
    assert _pair_distance(arm, kept_run.q, 1, 6) > 0.0
    assert arm.clearance(kept_run.q).distance.min() > 0.0


def test_a_pair_disabled_by_the_srdf_is_no_longer_pushed_apart(arm, free_run, tmp_path):
    """With link1–link6 disabled by an SRDF the QP lets them cross, as without the check."""
    tr = track(arm, FOLD, _qp(self_collision=True), q0=Q0,
               srdf=_srdf(tmp_path, "link1", "link6"))
    assert _pair_distance(arm, tr.q, 1, 6) < -0.005
    np.testing.assert_allclose(tr.q, free_run.q, atol=1e-9)  # no other pair came near


def test_a_pair_not_disabled_is_still_pushed_apart(arm, tmp_path):
    """An SRDF disabling another pair (link2–link5) still keeps link1–link6 apart."""
    srdf = _srdf(tmp_path, "link2", "link5")
    tr = track(arm, FOLD, _qp(self_collision=True), q0=Q0, srdf=srdf)
    assert _pair_distance(arm, tr.q, 1, 6) > 0.0
    assert arm.clearance(tr.q, srdf=str(srdf)).distance.min() > 0.0


def test_srdf_text_a_file_and_the_acm_it_gives_track_alike(arm, tmp_path):
    """``srdf=`` (file or XML text) and ``acm=acm_from_srdf(...)`` give the same trajectory."""
    srdf = _srdf(tmp_path, "link1", "link6")
    runs = [track(arm, FOLD, _qp(self_collision=True), q0=Q0, **kw) for kw in (
        {"srdf": srdf}, {"srdf": srdf.read_text(encoding="utf-8")},
        {"acm": acm_from_srdf(arm.collision, srdf)})]
    runs.append(track(arm, FOLD, _qp(self_collision=True,
                                     acm=acm_from_srdf(arm.collision, srdf)), q0=Q0))
    for tr in runs[1:]:
        np.testing.assert_array_equal(tr.q, runs[0].q)


def test_skip_links_drop_the_pairs_naming_links_without_a_body(arm, tmp_path, kept_run):
    """An SRDF pair naming a link off the model is skipped with ``skip_links``, else refused."""
    path = tmp_path / "tcp.srdf"
    path.write_text('<robot name="p"><disable_collisions link1="tcp" link2="link1"/></robot>',
                    encoding="utf-8")
    with pytest.raises(RobotDefinitionError, match=r"^srdf: .*'tcp'.*skip_links"):
        track(arm, FOLD, _qp(self_collision=True), q0=Q0, srdf=path)
    tr = track(arm, FOLD, _qp(self_collision=True), q0=Q0, srdf=path, skip_links=["tcp"])
    np.testing.assert_array_equal(tr.q, kept_run.q)  # nothing else is allowed


def test_segment_self_collision_stays_for_a_robot_without_a_model():
    """The scenarios' planar arms carry no collision model: their segments are kept apart."""
    arm = planar_arm(6, 0.1)
    tr = track(arm, FOLD, QPResolver(task="planar", self_collision=True, link_radius=0.01,
                                     safety=0.005), q0=Q0)
    assert _pair_distance(arm, tr.q, 1, 6) + 2 * 0.005 > 2 * 0.01  # link_radius, not 5 mm


@pytest.mark.parametrize(("kwargs", "error", "match"), [
    ({"srdf": "/nonexistent/arm.srdf"}, InputError, r"srdf .*'/nonexistent/arm.srdf'.*no such"),
    ({"srdf": "<robot><disable_collisions link1='link1'/>"}, RobotDefinitionError,
     r"^srdf: .*malformed XML"),
    ({"srdf": "<robot><disable_collisions link1='link1'/></robot>"}, RobotDefinitionError,
     r"^srdf: .*link1 and link2"),
    ({"srdf": "<robot><disable_collisions link1='link1' link2='nope'/></robot>"},
     RobotDefinitionError, r"^srdf: .*'nope'.*bodies: link1, link2"),
    ({"srdf": 3}, InputTypeError, r"srdf must be an SRDF file path.*got int"),
    ({"skip_links": ["tcp"]}, InputError, r"skip_links .*give srdf too"),
    ({"skip_links": "tcp"}, InputTypeError, r"skip_links must be a list of link names"),
    ({"acm": "link1,link6"}, InputTypeError, r"acm must be an AllowedCollisionMatrix"),
])
def test_bad_allowed_pairs_are_refused_naming_the_argument(arm, kwargs, error, match):
    """A missing, malformed or mismatched SRDF (or acm) is an error that names it."""
    with pytest.raises(error, match=match):
        track(arm, FOLD, _qp(self_collision=True), q0=Q0, **kwargs)


def test_allowed_pairs_need_a_solver_that_checks_self_collision(arm, tmp_path):
    """srdf/acm with DLS, an IK method or a QP without self_collision is refused, named."""
    srdf = _srdf(tmp_path, "link1", "link6")
    for solver in ("dls", "qp", "lm", _qp()):
        with pytest.raises(InputError, match=r"^srdf lists the body pairs .* self_collision"):
            track(arm, FOLD, solver, q0=Q0, srdf=srdf)
    with pytest.raises(InputError, match=r"acm or srdf, not both"):
        track(arm, FOLD, _qp(self_collision=True), q0=Q0, srdf=srdf,
              acm=acm_from_srdf(arm.collision, srdf))
    with pytest.raises(InputError, match=r"given to track and the QPResolver"):
        track(arm, FOLD, _qp(self_collision=True, acm=acm_from_srdf(arm.collision, srdf)),
              q0=Q0, srdf=srdf)


def test_allowed_pairs_need_a_collision_model(tmp_path):
    """A robot without a collision model (segments only) refuses srdf and acm, saying why."""
    arm = planar_arm(6, 0.1)
    with pytest.raises(InputError, match=r"srdf names bodies of a collision model.*none"):
        track(arm, FOLD, _qp(self_collision=True), q0=Q0, srdf=_srdf(tmp_path, "a", "b"))
    acm = acm_from_srdf(sk.models.planar(6, 0.1).collision, _srdf(tmp_path, "link1", "link6"))
    with pytest.raises(InputError, match=r"acm names bodies of a collision model"):
        track(arm, FOLD, _qp(self_collision=True, acm=acm), q0=Q0)


def test_an_acm_of_other_bodies_is_refused(arm):
    """An allowed-collision matrix over another model's bodies names both sets."""
    other = sk.models.get("ur5").collision
    with pytest.raises(InputError, match=r"acm must be over the bodies .*'link1'.*base_link"):
        track(arm, FOLD, _qp(self_collision=True), q0=Q0, acm=acm_from_srdf(other, "<robot/>"))


def test_qp_resolver_acm_is_checked_at_construction(arm):
    """QPResolver(acm=...) needs an AllowedCollisionMatrix and self_collision=True."""
    acm = acm_from_srdf(arm.collision, "<robot/>")
    with pytest.raises(InputError, match=r"acm .* needs self_collision=True"):
        _qp(acm=acm)
    with pytest.raises(InputTypeError, match=r"acm must be an AllowedCollisionMatrix"):
        _qp(self_collision=True, acm=[("link1", "link6")])
