"""Section 1 (workspace): the seed and sample count shared by its parts."""

from __future__ import annotations

#: Seed of every sampling of section 1.
SEED = 2024
#: Samples of each 2-link area in the table of section 1.
AREA_SAMPLES = 100_000
