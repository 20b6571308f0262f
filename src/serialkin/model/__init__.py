"""Robot models: joints, DH tables, the compiled chain, URDF and the built-in zoo."""

from serialkin.model.dh import DHLink
from serialkin.model.joint import Joint
from serialkin.model.robot import Robot

__all__ = ["DHLink", "Joint", "Robot"]
