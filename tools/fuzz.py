"""The long fuzz run: ``python tools/fuzz.py [CASES]`` (default 5000 cases per test; the CI runs 120).

It runs tests/test_fuzz.py with KINELAB_FUZZ_CASES set, so the long run and the CI subset are the same code.
"""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    cases = sys.argv[1] if len(sys.argv) > 1 else "5000"
    env = {**os.environ, "KINELAB_FUZZ_CASES": cases}
    return subprocess.call([sys.executable, "-m", "pytest", "-q", str(ROOT / "tests" / "test_fuzz.py")], env=env)


if __name__ == "__main__":
    sys.exit(main())
