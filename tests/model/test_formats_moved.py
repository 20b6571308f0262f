"""The file formats live in serialkin.formats (issue 28); the old model paths warn for a release."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys

import pytest

import serialkin.formats as formats
from serialkin import models
from serialkin.formats import mesh, mjcf, robotfile, urdf, xacro, xacro_expr
from serialkin.formats.xmlfile import parse_floats, read_robot_xml
from serialkin.model import robot as robot_module
from serialkin.model.robot import Robot

MOVED = {"urdf": urdf, "mjcf": mjcf, "xacro": xacro, "xacro_expr": xacro_expr,
         "robotfile": robotfile, "mesh": mesh}


@pytest.mark.parametrize("name", sorted(MOVED))
def test_old_module_paths_warn_and_re_export(name, monkeypatch):
    old = f"serialkin.model.{name}"
    monkeypatch.delitem(sys.modules, old, raising=False)
    with pytest.warns(DeprecationWarning, match=rf"import from serialkin\.formats\.{name}"):
        alias = importlib.import_module(old)
    new = MOVED[name]
    assert alias.__all__ == new.__all__
    for public in new.__all__:
        assert getattr(alias, public) is getattr(new, public)


def test_old_private_xml_helpers_still_resolve(monkeypatch):
    monkeypatch.delitem(sys.modules, "serialkin.model.urdf", raising=False)
    with pytest.warns(DeprecationWarning):
        from serialkin.model.urdf import _floats, _read_xml
    assert _read_xml is read_robot_xml and _floats is parse_floats


def test_old_model_package_names_warn():
    import serialkin.model as model

    with pytest.warns(DeprecationWarning, match=r"import load_robot_file from serialkin\.formats"):
        assert model.load_robot_file is formats.load_robot_file
    with pytest.warns(DeprecationWarning, match="serialkin.model.load_mesh"):
        from serialkin.model import load_mesh
    assert load_mesh is mesh.load_mesh
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        model.nothing  # noqa: B018


def test_robot_constructors_call_the_registered_readers():
    for name, function in [("from_urdf", urdf.robot_from_urdf), ("to_urdf", urdf.robot_to_urdf),
                           ("from_mjcf", mjcf.robot_from_mjcf),
                           ("from_xacro", xacro.robot_from_xacro)]:
        assert robot_module._PROVIDED[name] is function
    panda = models.get("panda")
    again = Robot.from_urdf(panda.to_urdf())
    assert again.n == panda.n and again.joint_names == panda.joint_names


def test_library_paths_warn_about_nothing():
    """Importing serialkin and reading and writing files uses no deprecated path."""
    code = ("import serialkin as sk, serialkin.formats, serialkin.collision, serialkin.viz, "
            "serialkin.cli; r = sk.models.get('panda'); sk.Robot.from_urdf(r.to_urdf()); "
            "import sys; print(sorted(m for m in sys.modules if m.startswith('serialkin.model.')"
            " and m.rsplit('.', 1)[1] in {'urdf', 'mjcf', 'xacro', 'xacro_expr', 'robotfile', "
            "'mesh'}))")
    out = subprocess.run([sys.executable, "-W", "error::DeprecationWarning", "-c", code],
                         capture_output=True, text=True, check=True,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert out.stdout.strip() == "[]"
