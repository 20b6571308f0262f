"""serialkin: kinematics of serial robot manipulators.

Quick start::

    import numpy as np
    import serialkin as sk

    robot = sk.models.get("puma560")
    T = robot.fk(np.zeros(robot.n))        # (4, 4) tool pose
    J = robot.jacobian(np.zeros(robot.n))  # (6, n), rows [v; ω]
"""

from serialkin import errors, ik, models, spatial
from serialkin import formats as formats  # registers the readers behind Robot.from_urdf, ...
from serialkin._version import __version__ as __version__
from serialkin.errors import SerialkinError
from serialkin.ik import IKResult
from serialkin.model import DHLink, Joint, Robot

__all__ = [
    "DHLink",
    "IKResult",
    "Joint",
    "Robot",
    "SerialkinError",
    "errors",
    "ik",
    "models",
    "spatial",
]
