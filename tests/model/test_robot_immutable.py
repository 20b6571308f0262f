"""A built Robot is immutable (issue 28): everything goes to the constructor or a copy."""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import InputError, InputTypeError
from serialkin.model.robot import Robot


def test_setting_an_attribute_raises_and_says_how_to_copy():
    """Announced with a DeprecationWarning one release ago; now an error."""
    panda = models.get("panda")
    with pytest.raises(AttributeError, match=r"Robot is immutable: cannot set 'name'.*with_tool"):
        panda.name = "renamed"
    with pytest.raises(AttributeError, match="immutable"):
        panda.tool = np.eye(4)
    with pytest.raises(AttributeError, match=r"cannot delete 'geometry'"):
        del panda.geometry
    assert panda.name == "panda" and panda.geometry == ()  # unchanged


def test_is_planar_is_not_written_onto_the_robot():
    three, panda = models.planar(3), models.get("panda")
    before = dict(vars(three))
    assert three.is_planar and not panda.is_planar
    assert three.is_planar  # the second read is the kept value
    assert vars(three).keys() == before.keys()
    copy = pickle.loads(pickle.dumps(three))  # read-only again: one kernel specialization
    assert not any(a.flags.writeable for a in (copy.chain.F, copy.chain.packed, copy.qlim))
    assert copy.is_planar


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
