"""Zoo frames against the vendor descriptions: documented, tested, offered by name."""

from __future__ import annotations

import math

import numpy as np
import pytest

import serialkin as sk
from serialkin import models
from serialkin.errors import InputError
from serialkin.models.frames import FRAMES, VENDOR_SUFFIX
from tests.erd import urdf

VENDORED = [name for name, f in FRAMES.items() if f.vendor is not None]
#: The UR URDF writes π/2 as 1.57079632679 (11 digits): its rotations are off by 1e-11.
ATOL = 1e-10


def _vendor_robot(name: str) -> sk.Robot:
    v = FRAMES[name].vendor
    path = urdf(v.file) if v.file else None
    if path is None:
        pytest.skip(f"{v.file} is not shipped by the installed example-robot-data")
    return sk.Robot.from_urdf(str(path), base_link=v.base_link, tip_link=v.tip_link)


@pytest.mark.parametrize("info", models.catalog(), ids=lambda i: i.name)
def test_every_model_documents_its_frames(info):
    """Every catalog entry states its base and flange frames and its vendor relation."""
    f = info.frames
    assert f.base and f.flange
    assert (f.vendor is not None) != bool(f.no_vendor), "a vendor relation or a reason"


@pytest.mark.parametrize("name", VENDORED)
def test_zoo_and_vendor_urdf_differ_by_the_documented_transforms(name):
    """T_vbase_vtip(q) of the vendor URDF = T_vbase_base · fk(q) · T_flange_vtip to 1e-10."""
    vend = _vendor_robot(name)
    zoo = models.get(name)
    v = FRAMES[name].vendor
    assert vend.n == zoo.n
    Q = np.vstack([np.zeros(zoo.n), zoo.random_q(50, seed=3)])
    want = vend.fk(Q)
    got = v.T_vbase_base @ zoo.fk(Q) @ v.T_flange_vtip
    np.testing.assert_allclose(got, want, atol=ATOL)


@pytest.mark.parametrize("name", VENDORED)
def test_vendor_variant_is_the_vendor_urdf(name):
    """models.get('<name>-vendor') has the vendor URDF's FK and the zoo's joint limits."""
    vend = _vendor_robot(name)
    variant = models.get(name.replace("_", "-") + "-vendor")
    assert variant.name == name + VENDOR_SUFFIX
    np.testing.assert_array_equal(variant.qlim, models.get(name).qlim)
    Q = variant.random_q(30, seed=4)
    np.testing.assert_allclose(variant.fk(Q), vend.fk(Q), atol=ATOL)


@pytest.mark.parametrize("name", VENDORED)
def test_documented_transforms_agree_with_pinocchio(name):
    """Pinocchio's placement of the vendor tip equals the zoo FK moved by the documented frames."""
    pin = pytest.importorskip("pinocchio", reason="pinocchio (pip 'pin') is in the bench extra")
    v = FRAMES[name].vendor
    path = urdf(v.file)
    if path is None:
        pytest.skip(f"{v.file} is not shipped by the installed example-robot-data")
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    zoo = models.get(name)
    idx = [model.getJointId(j) for j in _vendor_robot(name).joint_names]
    assert all(0 < i < model.njoints for i in idx)
    fid_tip = model.getFrameId(v.tip_link)
    fid_base = model.getFrameId(v.base_link)
    for q in zoo.random_q(20, seed=5):
        qp = pin.neutral(model)
        for i, qi in zip(idx, q):
            jm = model.joints[i]
            if jm.nq == 2:
                qp[jm.idx_q:jm.idx_q + 2] = math.cos(qi), math.sin(qi)
            else:
                qp[jm.idx_q] = qi
        pin.framesForwardKinematics(model, data, qp)
        T = np.linalg.inv(data.oMf[fid_base].homogeneous) @ data.oMf[fid_tip].homogeneous
        np.testing.assert_allclose(v.T_vbase_base @ zoo.fk(q) @ v.T_flange_vtip, T, atol=ATOL)


def test_ur5_and_panda_transforms_are_the_known_ones():
    """The UR5 base differs by Rz(π) and the Panda hand TCP by Rz(-45°)·Tz(0.1034 m)."""
    ur = FRAMES["ur5"].vendor
    np.testing.assert_allclose(ur.T_vbase_base[:3, :3], np.diag([-1.0, -1.0, 1.0]), atol=1e-15)
    np.testing.assert_array_equal(ur.T_flange_vtip, np.eye(4))
    pa = FRAMES["panda"].vendor
    np.testing.assert_array_equal(pa.T_vbase_base, np.eye(4))
    c = math.cos(math.pi / 4)
    np.testing.assert_allclose(pa.T_flange_vtip[:3, :3], [[c, c, 0], [-c, c, 0], [0, 0, 1]],
                               atol=1e-15)
    np.testing.assert_allclose(pa.T_flange_vtip[:3, 3], [0, 0, 0.1034])


def test_vendor_variant_names_and_refusal():
    """Variants exist only where frames differ; other names are refused listing the variants."""
    assert set(models.vendor_variants()) == {"ur5_vendor", "panda_vendor"}
    assert models.get("Franka-Vendor").name == "panda_vendor"
    assert models.canonical_name("UR5-vendor") == "ur5_vendor"
    assert models.canonical_name("planar7") == "planar"
    assert models.canonical_name("nope") is None
    with pytest.raises(InputError, match="variants: ur5_vendor, panda_vendor"):
        models.get("puma560_vendor")


def test_vendor_variant_keeps_ik_and_collision():
    """The UR5 in vendor frames solves IK (round trip) and keeps its collision capsules."""
    r = models.get("ur5_vendor")
    assert r.collision is not None
    q = np.array([0.3, -1.1, 1.2, -0.4, 0.9, 0.2])
    T = r.fk(q)
    res = r.ik(T, q0=q + 0.05)
    assert res.success
    np.testing.assert_allclose(r.fk(res.q), T, atol=1e-8)
    sols = np.asarray(r.ik_all(T)).reshape(-1, 6)
    assert len(sols) >= 1
    np.testing.assert_allclose(r.fk(sols), np.broadcast_to(T, (len(sols), 4, 4)), atol=1e-8)
