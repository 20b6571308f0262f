"""Print the allowed body pairs of the zoo robots (src/serialkin/collision/allowed_pairs.py).

A maintenance script, run by hand when a zoo robot's collision model changes: for each
robot, the pairs beyond ``default_acm`` by the method that module's ``METHOD`` states
(the vendor SRDF for the Panda and the UR5, never/always sampling for the others).
Its output is pasted into ``ALLOWED``.

Usage: ``python benchmarks/generate_allowed_pairs.py`` (needs example-robot-data for the
vendor SRDFs).
"""

from __future__ import annotations

import dataclasses

from serialkin import models
from serialkin.collision import acm_from_srdf, default_acm, sampled_acm
from serialkin.collision.allowed_pairs import METHOD
from serialkin.collision.reference import vendor_files


def main() -> None:
    """Print the pairs of every robot of ``METHOD``."""
    for name in METHOD:
        r = models.get(name)
        bare = dataclasses.replace(r.collision, allowed=())
        files = vendor_files(name)
        if name in ("panda", "ur5") and not isinstance(files, str):
            acm = acm_from_srdf(bare, files[1])
        else:
            acm = sampled_acm(r, bare, samples=20000, seed=0, never=True)
        base = default_acm(bare)
        names = bare.body_names
        print(name, [(a, b) for i, a in enumerate(names) for b in names[i + 1:]
                     if acm.is_allowed(a, b) and not base.is_allowed(a, b)])


if __name__ == "__main__":
    main()
