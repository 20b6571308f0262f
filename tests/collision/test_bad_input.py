"""Bad input to the collision package: clear errors of the library's own types."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.collision import (
    AllowedCollisionMatrix,
    CollisionModel,
    acm_from_srdf,
    panda_collision_model,
    read_srdf,
    sampled_acm,
    scene_clearance,
    self_clearance,
)
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError
from serialkin.model.geometry import Box, HalfSpace


@pytest.fixture(scope="module")
def panda():
    return models.panda(), panda_collision_model()


def test_wrong_q_size(panda):
    """A q with the wrong number of joints names q and the robot."""
    robot, model = panda
    with pytest.raises(InputError, match="q has 6 values"):
        self_clearance(robot, model, np.zeros(6))


def test_model_frame_beyond_robot(panda):
    """A body on a frame the robot does not have is refused, naming the body."""
    model = CollisionModel.from_dicts([{"name": "x", "frame": 9, "spheres": [
        {"center": [0, 0, 0], "radius": 0.1}]}])
    with pytest.raises(InputError, match="'x' is fixed to frame 9"):
        self_clearance(panda[0], model, np.zeros(7))


def test_acm_of_other_bodies(panda):
    """A matrix over other bodies is refused."""
    robot, model = panda
    acm = AllowedCollisionMatrix(("a", "b"), np.eye(2, dtype=bool))
    with pytest.raises(InputError, match="acm must be an AllowedCollisionMatrix"):
        self_clearance(robot, model, np.zeros(7), acm)


def test_scene_item_type(panda):
    """A scene item that is not a shape names its index and type."""
    robot, model = panda
    with pytest.raises(InputTypeError, match=r"scene\[1\] must be .* got str"):
        scene_clearance(robot, model, np.zeros(7), [HalfSpace([0, 0, 1]), "table"])


@pytest.mark.parametrize(("build", "match"), [
    (lambda: Box((0.2, -0.2, 0.2)), r"box size: expected finite numbers >= 0"),
    (lambda: Box((0.2, 0.2)), "box size: expected 3 numbers"),
    (lambda: Box((0.2, 0.2, 0.2), center=[0, 0]), "center must be a vector of 3"),
    (lambda: Box((0.2, 0.2, 0.2), rotation=np.ones((3, 3))), "rotation"),
    (lambda: HalfSpace([0, 0, 0]), "normal must be a non-zero vector"),
    (lambda: HalfSpace([0, 0, 1], float("nan")), "offset"),
])
def test_bad_scene_shapes(build, match):
    """Malformed boxes and half-spaces raise InputError naming the field."""
    with pytest.raises(InputError, match=match):
        build()


@pytest.mark.parametrize(("bodies", "match"), [
    ([{"name": "a"}], r"bodies\[0\]\.frame is missing"),
    ([{"name": "a", "frame": 0, "color": 1}], "unknown keys"),
    ([{"name": "a", "frame": 1.5}], r"bodies\[0\]\.frame must be an integer"),
    ([{"name": "a", "frame": 0, "spheres": [{"center": [0, 0], "radius": 1}]}],
     r"spheres\[0\]\.center must be 3 numbers"),
    ([{"name": "a", "frame": 0}, {"name": "a", "frame": 1}], "unique"),
    ([{"name": "a", "frame": -1}], r"body_frames\[0\] must be >= 0"),
])
def test_bad_model_dicts(bodies, match):
    """Malformed dictionary forms raise errors naming the entry."""
    with pytest.raises((InputError, InputTypeError), match=match):
        CollisionModel.from_dicts(bodies)


def test_bad_srdf(panda):
    """Malformed XML, a missing link attribute and an unknown group state are named."""
    with pytest.raises(RobotDefinitionError, match="malformed XML"):
        read_srdf("<robot><disable_collisions")
    with pytest.raises(RobotDefinitionError, match="must name link1 and link2"):
        acm_from_srdf(panda[1], '<robot><disable_collisions link1="panda_link1"/></robot>')
    with pytest.raises(RobotDefinitionError, match="no group_state named 'home'"):
        read_srdf("<robot/>").group_state("home")
    with pytest.raises(RobotDefinitionError, match="finite number"):
        read_srdf('<robot><group_state name="s"><joint name="j" value="x"/></group_state>'
                  '</robot>')


def test_missing_srdf_file_is_named_as_an_srdf(panda, tmp_path):
    """A missing SRDF file is reported as an SRDF file (not a URDF), by read_srdf and clearance."""
    missing = str(tmp_path / "nope.srdf")
    with pytest.raises(RobotDefinitionError, match=r"^SRDF file '.*nope\.srdf' does not exist"):
        read_srdf(missing)
    with pytest.raises(RobotDefinitionError, match="SRDF file"):
        panda[0].clearance(np.zeros(7), srdf=missing)


def test_bad_sampling_options(panda):
    """Sampling needs at least one sample and a finite margin."""
    robot, model = panda
    with pytest.raises(InputError, match="samples"):
        sampled_acm(robot, model, samples=0)
    with pytest.raises(InputError, match="margin"):
        sampled_acm(robot, model, samples=5, margin=float("inf"))
