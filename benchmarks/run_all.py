"""Run every benchmark script in this folder, one after the other (``make bench``).

Each script prints its own table; peers are measured in the same run when the ``bench``
extra is installed. Benchmarks are run by hand, never as timed assertions in tests.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> int:
    status = 0
    for script in sorted(HERE.glob("bench_*.py")):
        print(f"\n=== {script.name} ===", flush=True)
        rc = subprocess.call([sys.executable, str(script)], cwd=HERE.parent)
        status = status or rc
    return status


if __name__ == "__main__":
    sys.exit(main())
