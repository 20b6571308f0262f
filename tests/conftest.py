"""Suite-wide test settings.

Hypothesis explores new random examples on every developer run; under CI (``CI`` set in
the environment) it is derandomised so that a landing is judged on a reproducible suite.
Set ``HYPOTHESIS_PROFILE=explore`` to search harder locally.
"""

from __future__ import annotations

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", max_examples=500, deadline=None)
settings.register_profile("dev", deadline=None)

_default = "ci" if os.environ.get("CI") else "dev"
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", _default))
