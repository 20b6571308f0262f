"""MJCF files: includes stay inside the model folder, bombs and deep trees hit budgets."""

from __future__ import annotations

import os
import re

import pytest

from serialkin import Robot
from serialkin.errors import BudgetError, InputTypeError, RobotDefinitionError

ARM = ("<mujoco><worldbody><body name='a'><joint name='j' axis='0 0 1'/>"
       "<geom type='sphere' size='0.1'/><body name='b' pos='1 0 0'/></body></worldbody>"
       "</mujoco>")


def test_an_include_that_leaves_the_folder_is_refused(tmp_path):
    """``..``, absolute paths and links pointing out of the model's folder are errors."""
    model = tmp_path / "model"
    model.mkdir()
    (tmp_path / "outside.xml").write_text("<mujoco/>")
    os.symlink(tmp_path / "outside.xml", model / "link.xml")
    for file in ("../outside.xml", str(tmp_path / "outside.xml"), "link.xml"):
        top = model / "top.xml"
        top.write_text(f"<mujoco><include file='{file}'/>{ARM[8:-9]}</mujoco>")
        with pytest.raises(RobotDefinitionError, match="leaves the model's folder"):
            Robot.from_mjcf(top)


def test_an_include_inside_the_folder_works(tmp_path):
    """A relative include below the model's folder is read as before."""
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "arm.xml").write_text(ARM)
    top = tmp_path / "top.xml"
    top.write_text("<mujoco><include file='parts/arm.xml'/></mujoco>")
    assert Robot.from_mjcf(top).n == 1


def test_an_include_bomb_hits_the_budget(tmp_path):
    """Files including the next one four times, twelve deep, stop at once with BudgetError."""
    for level in range(12):
        inner = "".join(f"<include file='f{level + 1}.xml'/>" for _ in range(4))
        (tmp_path / f"f{level}.xml").write_text(f"<mujoco>{inner}</mujoco>")
    (tmp_path / "f12.xml").write_text("<mujoco><worldbody/></mujoco>")
    with pytest.raises(BudgetError, match="include") as err:
        Robot.from_mjcf(tmp_path / "f0.xml")
    # bounded work: the expansion counter stopped it (not the 4¹² files the tree asks for)
    assert re.search(r"more than \d+ <include> expansions", str(err.value)), str(err.value)


@pytest.mark.parametrize("depth", [1500, 5000])
def test_deeply_nested_bodies_are_refused_clearly(depth):
    """Thousands of nested bodies raise BudgetError, not RecursionError."""
    text = ("<mujoco><worldbody>" + "<body><joint axis='0 0 1'/>" * depth
            + "</body>" * depth + "</worldbody></mujoco>")
    with pytest.raises(BudgetError, match="nest more than"):
        Robot.from_mjcf(text)


def test_a_file_name_too_long_is_named(tmp_path):
    """An include whose name the system refuses is a RobotDefinitionError naming it."""
    top = tmp_path / "top.xml"
    top.write_text(f"<mujoco><include file='{'a' * 5000}.xml'/></mujoco>")
    with pytest.raises(RobotDefinitionError, match="aaaa"):
        Robot.from_mjcf(top)


@pytest.mark.parametrize("arg", ["base_body", "end_body", "tool_site"])
def test_body_and_site_names_must_be_text(arg):
    """end_body=123 and the like raise InputTypeError naming the argument."""
    with pytest.raises(InputTypeError, match=arg):
        Robot.from_mjcf(ARM, **{arg: 123})
