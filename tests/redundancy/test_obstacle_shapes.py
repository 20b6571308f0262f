"""Obstacles are the shared shape classes: file form, unsupported cylinders, the old names."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import serialkin.redundancy
from serialkin.errors import InputError, InputTypeError, NotSupportedError
from serialkin.model.geometry import Capsule, Cylinder, Sphere
from serialkin.redundancy import MultiTaskResolver, clearances
from serialkin.redundancy import obstacles as obstacle_module
from serialkin.redundancy.obstacles import obstacle_from_dict, obstacle_to_dict

from ._robots import six_link

SHAPES = [Cylinder(0.03, math.inf, center=[0.075, -0.065, 0.0], influence=0.02, name="A"),
          Sphere(0.04, center=[0.1, 0.2, 0.3], name="ball"),
          Capsule(0.02, a=[0.0, 0.1, 0.0], b=[0.3, 0.1, 0.2], influence=0.05)]


def test_file_form_reads_back_equal_and_circle_is_the_vertical_cylinder():
    """obstacle_to_dict/obstacle_from_dict round-trip; a file 'circle' is Cylinder(r, inf)."""
    for o in SHAPES:
        assert obstacle_from_dict(obstacle_to_dict(o)) == o
    for kind in ("circle", "cylinder"):
        read = obstacle_from_dict({"type": kind, "name": "A", "center": [0.075, -0.065],
                                   "radius": 0.03, "influence": 0.02})
        assert read == SHAPES[0] and read.infinite_along_z
    assert obstacle_to_dict(SHAPES[0]) == {"type": "circle", "center": [0.075, -0.065],
                                           "radius": 0.03, "influence": 0.02, "name": "A"}


def test_only_infinite_z_cylinders_are_obstacles():
    """A finite or tilted cylinder is refused where obstacles are given, naming the item."""
    robot = six_link()
    tilted = Rotation.from_euler("y", 0.5).as_matrix()
    for bad in (Cylinder(0.05, 1.0, center=[0.3, 0.0, 0.0]),
                Cylinder(0.05, math.inf, center=[0.3, 0.0, 0.0], rotation=tilted)):
        with pytest.raises(NotSupportedError, match=r"obstacles\[1\].*infinite along z"):
            clearances(robot, np.zeros(6), [SHAPES[1], bad])
        with pytest.raises(NotSupportedError, match="infinite along z"):
            MultiTaskResolver(obstacles=[bad])
    with pytest.raises(InputTypeError, match=r"obstacles\[0\] must be a Cylinder"):
        clearances(robot, np.zeros(6), ["post"])


OLD = {  # old name -> (old call, the same obstacle in the shared vocabulary)
    "Circle": (lambda c: c([0.1, 0.2], 0.05, 0.03, "post"),
               Cylinder(0.05, math.inf, center=[0.1, 0.2, 0.0], influence=0.03, name="post")),
    "Cylinder": (lambda c: c(center=[0.1, 0.2], radius=0.05),
                 Cylinder(0.05, math.inf, center=[0.1, 0.2, 0.0])),
    "Sphere": (lambda c: c(np.array([0.1, 0.2, 0.3]), 0.05, name="ball"),
               Sphere(0.05, center=[0.1, 0.2, 0.3], name="ball")),
    "Capsule": (lambda c: c([0, 0, 0], [0.2, 0, 0.1], 0.02, influence=0.1),
                Capsule(0.02, a=[0, 0, 0], b=[0.2, 0, 0.1], influence=0.1)),
}


@pytest.mark.parametrize("name", sorted(OLD))
def test_old_obstacle_names_warn_and_build_the_shared_classes(name):
    """redundancy(.obstacles).Circle/Cylinder/Sphere/Capsule warn and build equal objects."""
    call, new = OLD[name]
    for module in (obstacle_module, serialkin.redundancy):
        with pytest.warns(DeprecationWarning,
                          match=rf"{module.__name__}\.{name} is deprecated: import "
                                rf"{type(new).__name__} from serialkin\.model\.geometry"):
            old = getattr(module, name)
        built = call(old)
        assert type(built) is type(new) and built == new


def test_old_names_keep_their_checks():
    """The old constructors still refuse a radius of 0 and a centre of the wrong size."""
    with pytest.warns(DeprecationWarning):
        circle, sphere = obstacle_module.Circle, obstacle_module.Sphere
    with pytest.raises(InputError, match="radius must be a finite number > 0"):
        circle([0.0, 0.0], 0.0)
    with pytest.raises(InputError, match="center must be a vector of 2"):
        circle([0.0, 0.0, 0.0], 0.1)
    with pytest.raises(InputError, match="center must be a vector of 3"):
        sphere([0.0, 0.0], 0.1)


def test_old_names_in_import_statements_warn():
    """`from serialkin.redundancy import Circle` warns at the import line."""
    with pytest.warns(DeprecationWarning, match=r"serialkin\.redundancy\.Circle"):
        from serialkin.redundancy import Circle  # noqa: F401
    with pytest.warns(DeprecationWarning, match=r"serialkin\.redundancy\.obstacles\.Sphere"):
        from serialkin.redundancy.obstacles import Sphere as OldSphere  # noqa: F401
    with pytest.raises(AttributeError, match="no attribute 'Box'"):
        serialkin.redundancy.Box  # noqa: B018
