"""The built-in model zoo: catalog, lookup, sources and limits."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin import models
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError


@pytest.mark.parametrize("info", models.catalog(), ids=lambda i: i.name)
def test_catalog_entries_build(info):
    """Every catalog entry builds a robot with its DOF, convention, source and sane limits."""
    robot = info.build(4) if info.name == "planar" else info.build()
    assert isinstance(robot, sk.Robot)
    if info.dof is not None:
        assert robot.n == info.dof
    assert robot.convention == info.convention
    assert robot.source, "every model names its source"
    assert np.all(robot.qlim[:, 0] <= robot.qlim[:, 1])
    q = robot.random_q(20, seed=0)
    assert np.all(robot.within_limits(q))


def test_names_and_get():
    """names() lists the catalog; get() is case-insensitive and accepts aliases and planar<N>."""
    assert models.names() == tuple(i.name for i in models.catalog())
    assert models.get("UR5").name == "UR5"
    assert models.get("puma").name == "puma560"
    assert models.get("Three-Link").name == "three_link"
    assert models.get("franka").name == "panda"
    r = models.get("planar20", lengths=0.01675)
    assert r.n == 20
    np.testing.assert_allclose(r.fk(np.zeros(20))[:3, 3], [20 * 0.01675, 0, 0], atol=1e-12)
    assert models.get("scara", l1=0.5).dh[0].a == 0.5


def test_unknown_name_suggests_close_matches():
    """An unknown name raises InputError suggesting close names and listing all."""
    with pytest.raises(InputError, match=r"unknown robot model 'pumma'; did you mean 'puma560'"):
        models.get("pumma")
    with pytest.raises(InputError, match="Available: planar, two_link"):
        models.get("zzz")
    with pytest.raises(InputTypeError, match="model name must be a string"):
        models.get(5)


def test_planar_arguments():
    """planar() takes one or n lengths and one or n limit pairs, and rejects the rest."""
    r = models.planar(3, [1.0, 0.5, 0.25], qlim=(-1.0, 1.0))
    assert [row.a for row in r.dh] == [1.0, 0.5, 0.25]
    np.testing.assert_array_equal(r.qlim, [[-1.0, 1.0]] * 3)
    assert np.all(np.isinf(models.planar(2).qlim))
    with pytest.raises(InputError, match="lengths must be one number or 3 numbers"):
        models.planar(3, [1.0, 2.0])
    with pytest.raises(InputError, match="lengths must be non-negative"):
        models.planar(2, [1.0, -1.0])
    with pytest.raises(InputError, match=r"qlim must be a pair .* shape \(2, 2\)"):
        models.planar(2, qlim=[[0, 1, 2]])
    with pytest.raises(InputError, match="n must be >= 1"):
        models.planar(0)
    with pytest.raises(RobotDefinitionError, match="lower 1 is greater than upper -1"):
        models.planar(2, qlim=(1.0, -1.0))


def test_scara_is_table_1():
    """The SCARA rows are Table 1: (L1,0,d1,q1), (L2,0,0,q2), (0,π,d2+q3,0), (0,0,0,q4)."""
    r = models.scara(d1=0.5, d2=0.2, l1=0.4, l2=0.3)
    got = [(row.a, row.alpha, row.d, row.theta, row.type) for row in r.dh]
    assert got == [(0.4, 0, 0.5, 0, "R"), (0.3, 0, 0, 0, "R"), (0, np.pi, 0.2, 0, "P"),
                   (0, 0, 0, 0, "R")]
    with pytest.raises(InputError, match="l1"):
        models.scara(l1=-1.0)


def test_panda_is_modified_dh_with_flange():
    """The Panda uses modified DH with the 0.107 m flange as tool and Franka's joint limits."""
    r = models.panda()
    assert r.convention == "modified"
    np.testing.assert_allclose(r.tool[:3, 3], [0, 0, 0.107])
    np.testing.assert_allclose(r.qlim[3], [-3.0718, -0.0698])


def test_stanford_has_prismatic_third_joint():
    """The Stanford arm's third joint is prismatic with a 12-50 inch stroke."""
    r = models.stanford()
    assert r.joint_types == ("R", "R", "P", "R", "R", "R")
    np.testing.assert_allclose(r.qlim[2], [12 * 0.0254, 50 * 0.0254])


def test_each_call_builds_a_fresh_robot():
    """Model functions return independent robots (changing one copy does not touch others)."""
    a, b = models.ur5(), models.ur5()
    assert a is not b
    c = a.with_tool(sk.spatial.transl(0, 0, 0.1))
    np.testing.assert_array_equal(b.tool, np.eye(4))
    assert not np.allclose(c.fk(np.zeros(6)), b.fk(np.zeros(6)))
