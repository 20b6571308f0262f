"""A built Robot is immutable (issue 28): everything goes to the constructor or a copy."""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import InputError, InputTypeError
from serialkin.model.robot import Robot


def test_setting_an_attribute_warns_for_one_release():
    panda = models.get("panda")
    with pytest.warns(DeprecationWarning, match="immutable"):
        panda.name = "renamed"
    assert panda.name == "renamed"


def test_copies_carry_link_names_geometry_and_collision():
    panda = models.get("panda")
    assert panda.collision is not None
    moved = panda.with_tool(np.eye(4))
    assert moved.collision is panda.collision and moved.geometry == panda.geometry
    assert moved.link_names == panda.link_names
    bare = panda.with_collision(None)
    assert bare.collision is None and panda.collision is not None


def test_constructor_takes_every_part_and_checks_the_collision_model():
    panda = models.get("panda")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = Robot(list(panda.joints), link_names=[f"l{i}" for i in range(8)],
                  collision=panda.collision)
        copy = pickle.loads(pickle.dumps(r))  # unpickling sets state without a warning
    assert r.link_names == tuple(f"l{i}" for i in range(8)) and copy.collision is not None
    with pytest.raises(InputTypeError, match="CollisionModel"):
        Robot(list(panda.joints), collision="capsules")
    three = models.planar(3)
    with pytest.raises(InputError, match="frames 0..3"):
        Robot(list(three.joints), collision=panda.collision)


def test_no_library_path_assigns_to_a_robot():
    """Building every model and reading robot files warns about nothing."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        for name in models.names():
            models.get(name, **({"n": 3} if name == "planar" else {}))
