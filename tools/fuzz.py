"""The long fuzz run: ``python tools/fuzz.py [CASES] [PYTEST ARGS]`` (default 1000 cases per test; the CI runs 120).

It runs tests/test_fuzz.py with KINELAB_FUZZ_CASES set, so the long run and the CI subset are the same code,
and prints the outcome counts per class (cases, clean errors, accepted, raw exceptions, hangs, nonsense
accepted; the last three must be 0).
"""

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COLUMNS = ("cases", "clean", "accepted", "raw", "hangs", "nonsense_accepted")


def main() -> int:
    cases = sys.argv[1] if len(sys.argv) > 1 else "1000"
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(tmp) / "fuzz.jsonl"
        env = {**os.environ, "KINELAB_FUZZ_CASES": cases, "KINELAB_FUZZ_REPORT": str(report)}
        code = subprocess.call([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                                str(ROOT / "tests" / "test_fuzz.py"), *sys.argv[2:]], env=env)
        rows = [json.loads(line) for line in report.read_text().splitlines()] if report.exists() else []
    print("| class | " + " | ".join(COLUMNS) + " |")
    print("|---" * (len(COLUMNS) + 1) + "|")
    for row in rows:
        print(f"| {row['class']} | " + " | ".join(str(row[c]) for c in COLUMNS) + " |")
    return code


if __name__ == "__main__":
    sys.exit(main())
