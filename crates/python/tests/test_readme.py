"""The READMEs' Python examples run as written (on the real recording and a seeded bundle)."""

import re
from pathlib import Path

import pytest

import evtac

ROOT = Path(__file__).resolve().parents[3]


@pytest.mark.parametrize("readme", ["README.md", "crates/python/README.md"])
def test_the_example_runs(readme, aedat, tmp_path, capsys):
    text = (ROOT / readme).read_text()
    code = "".join(re.findall(r"```python\n(.*?)```", text, re.S))
    model = re.search(r'evtac\.Model\.load\("([^"]+)"\)', code).group(1)
    evtac.Model.untrained(5, evtac.Representation("static")).save(tmp_path / "bundle")
    code = code.replace('"trial.aedat4"', repr(str(aedat))).replace(
        f'"{model}"', repr(str(tmp_path / "bundle"))
    )
    exec(compile(code, readme, "exec"), {})
    out = capsys.readouterr().out
    assert re.match(r"590 samples, last pitch -?\d+\.\d\d roll -?\d+\.\d\d\n", out)
    if "evtac.Estimator" in code:
        assert re.search(r"^\d+ estimates left at the end$", out, re.M)
