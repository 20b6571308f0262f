"""Deprecated location of :class:`~serialkin.model.collision_model.CollisionModel`.

The collision model is part of a robot's description, so it lives in the model layer
(:mod:`serialkin.model.collision_model`); ``serialkin.collision.CollisionModel`` is
the public name. This module stays for one release and warns.
"""

import warnings

from serialkin.model.collision_model import CollisionModel

warnings.warn("serialkin.collision.model is deprecated: import CollisionModel from "
              "serialkin.collision (or serialkin.model.collision_model)",
              DeprecationWarning, stacklevel=2)

__all__ = ["CollisionModel"]
