"""#60 item 5: `kinelab singular ur5 --sweep 2000` listed every 2π copy of a family as its own (wrist_2 = 0, π, −π,
2π, −2π), the chance relations of unexplained samples as more families, and q with 17 digits ("-0.0000" too)."""

import re

from kinelab import cli


def test_a_ur5_sweep_lists_each_family_once_in_words_and_rounded(capsys):
    assert cli.main(["singular", "ur5", "--sweep", "2000"]) == 0
    out = capsys.readouterr().out
    families = re.findall(r"found: (.*)", out)
    assert "wrist_2_joint = 0 or π" in families and "elbow_joint = 0 or π" in families
    assert not any(re.search(r"[−-]π|2π", f) for f in families)  # no copy a turn (or a sign) away
    assert sum(f.startswith("(no simple relation") for f in families) <= 1
    assert len(families) == len(set(families)) <= 3
    for line in re.findall(r"e\.g\. q = (.*)", out):
        values = line.split()
        assert all(re.fullmatch(r"-?\d+\.\d{8}", v) for v in values) and "-0.00000000" not in values
