"""Trial 49, side A (CLI): compete refused an empty --store file that reproduce takes as a new store (T49-A02);
sensor and drift settings separated by a space or ';' were said to need a number (T49-A03); a config (T49-A04) or a
JSON file (T49-A05) holding a curly quote or a no-break space pasted from a slide was refused by a bare position; and a
missing required package (numba, NumPy) was a traceback from every command (T49, extra)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config
from neurohover.experiments.store_checks import new_store
from neurohover.jsontext import JSONError, strict_json
from neurohover.tasks import Drift, Sensor

ROOT = Path(__file__).resolve().parents[1]
COMPETE = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20"]


@pytest.mark.slow
def test_compete_takes_an_empty_store_file_as_a_new_store(cli, tmp_path: Path, monkeypatch) -> None:
    """T49-A02: an empty --store file (and an empty results.sqlite in --out, the default store) becomes the store, as
    reproduce takes it: Store and compete share one decision (new_store)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "e.sqlite").touch()
    assert new_store(tmp_path / "e.sqlite") and new_store(tmp_path / "none.sqlite")
    rc, out, err = cli(*COMPETE, "--out", "c", "--store", "e.sqlite")
    assert rc == 0, err
    assert not new_store(tmp_path / "e.sqlite") and "store: " in out
    (tmp_path / "z4").mkdir()
    (tmp_path / "z4" / "results.sqlite").touch()
    rc, out, err = cli(*COMPETE, "--out", "z4")
    assert rc == 0, err
    assert (tmp_path / "z4" / "summary.json").is_file() and not new_store(tmp_path / "z4" / "results.sqlite")


def test_sensor_settings_separated_by_spaces_or_semicolons_say_so() -> None:
    """T49-A03: the value is named, and the settings are shown separated by commas; no separator to suggest: the form."""
    keys = "with keys level, velocity, position, rates, attitude, correlation, delay, dropout"
    said = r"^sensor setting velocity: its value '0.05 position=0.05' is not a number: separate settings with commas \(velocity=0.05,position=0.05\), "
    with pytest.raises(NeurohoverError, match=said + keys + "$"):
        Sensor.parse("velocity=0.05 position=0.05")
    said = r"^sensor setting level: its value '0.5;delay=1' is not a number: separate settings with commas \(level=0.5,delay=1\)"
    with pytest.raises(NeurohoverError, match=said):
        Sensor.parse("level=0.5;delay=1")
    said = r"^sensor setting 'velocity=abc' needs a number after '=': its value 'abc' is not one; give KEY=NUMBER pairs separated by commas, "
    with pytest.raises(NeurohoverError, match=said + keys + "$"):
        Sensor.parse("velocity=abc")
    with pytest.raises(NeurohoverError, match=r"^sensor setting 'velocity=' needs a number after '='$"):
        Sensor.parse("velocity=")


def test_drift_settings_separated_by_a_space_say_so(cli, tmp_path: Path, monkeypatch) -> None:
    """T49-A03: drift names the commas too, before its form."""
    said = r"^drift 'walk=0.01 D_w=0.8@200-800' is not understood: separate settings with commas \(walk=0.01,D_w=0.8@200-800\); give walk=STD"
    with pytest.raises(NeurohoverError, match=said):
        Drift.parse("walk=0.01 D_w=0.8@200-800")
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli(*COMPETE, "--out", "c", "--obs-noise", "level=0.5;delay=1")
    assert rc == 2 and "its value '0.5;delay=1' is not a number: separate settings with commas (level=0.5,delay=1)" in err, err
    assert not (tmp_path / "c").exists()


def _config(tmp_path: Path, old: str, new: str) -> Path:
    text = (ROOT / "neurohover" / "experiments" / "configs" / "fig2.toml").read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("aliases = ")]
    text = "\n".join(lines).replace('name = "fig2"', 'name = "mine"')
    assert old in text
    path = tmp_path / "q.toml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def test_config_with_a_curly_quote_or_no_break_space_names_it(tmp_path: Path) -> None:
    """T49-A04: tomllib's position, then the character there by its Unicode name and what TOML takes."""
    path = _config(tmp_path, 'task = "ghh08"', "task = \u201cghh08\u201d")
    said = r"is not valid TOML: Invalid value \(at line \d+, column 8\): '\u201c' \(U\+201C LEFT DOUBLE QUOTATION MARK\) is not allowed there: "
    with pytest.raises(NeurohoverError, match=said + r"TOML strings take ASCII quotes \(\"\)$"):
        load_config(str(path), "quick")
    path = _config(tmp_path, "seed = ", "seed =\u00a0")
    with pytest.raises(NeurohoverError, match=r"\): '\\xa0' \(U\+00A0 NO-BREAK SPACE\) is not allowed there: outside strings TOML takes ASCII spaces \(' '\)$"):
        load_config(str(path), "quick")


def test_json_with_a_curly_quote_names_it(cli, tmp_path: Path, monkeypatch) -> None:
    """T49-A05: every JSON reader (strict_json) names the character at the decoder's position, or a look-alike before it
    on its line; a policy file through fly."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "q.json").write_text('{\n "topology": \u201cslp\u201d\n}\n', encoding="utf-8")
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--policy", "q.json")
    assert rc == 2, err
    said = "policy file 'q.json' is not valid JSON: Expecting value: line 2 column 14 (char 15): '\u201c' (U+201C LEFT DOUBLE QUOTATION MARK)"
    assert said + ' is not allowed there: JSON strings take ASCII double quotes (")' in err, err
    with pytest.raises(JSONError, match=r"near it, at column 7, '\u201d' \(U\+201D RIGHT DOUBLE QUOTATION MARK\) is not an ASCII quote"):
        strict_json('{"kind\u201d: "mlp"}')
    said = r"^Expecting value: line 1 column 6 \(char 5\): '\uff15' \(U\+FF15 FULLWIDTH DIGIT FIVE\) is not allowed there: "
    with pytest.raises(JSONError, match=said + "outside strings JSON takes ASCII characters only: write '5'$"):
        strict_json('{"a":\uff15}')
    with pytest.raises(JSONError, match=r"^Extra data: line 1 column 15 \(char 14\)$"):  # an accent inside a string is no look-alike
        strict_json('{"a": "Caf\u00e9"} x')


def _without_site(tmp_path: Path, extra: str | None = None, *args: str) -> subprocess.CompletedProcess:
    """``python -S ARGS`` (no site-packages) with only this checkout (and ``extra``) on its path."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "NUMBA_"))}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *([extra] if extra else [])])
    return subprocess.run([sys.executable, "-S", *args], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)


def test_a_missing_required_package_is_named_on_one_line(tmp_path: Path) -> None:
    """T49 extra: `python -S -m neurohover --version` was numba's ModuleNotFoundError traceback; the first missing
    package is named with how to install it (exit 2; an ImportError saying so on import)."""
    if _without_site(tmp_path, None, "-c", "import numpy").returncode == 0:
        pytest.skip("this Python finds NumPy without site-packages")
    proc = _without_site(tmp_path, None, "-m", "neurohover", "--version")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.startswith("neurohover: error: neurohover needs the package numba, which this Python (") and proc.stderr.count("\n") == 1
    assert "(No module named 'numba'): install it (pip install numba, or pip install neurohover with its dependencies)" in proc.stderr
    fake = tmp_path / "fake"
    (fake / "numba").mkdir(parents=True)
    (fake / "numba" / "__init__.py").write_text("import numpy\n", encoding="utf-8")  # numba there, NumPy missing
    proc = _without_site(tmp_path, str(fake), "-m", "neurohover", "--version")
    assert proc.returncode == 2 and proc.stderr.startswith("neurohover: error: neurohover needs the package numpy,"), proc.stderr
    proc = _without_site(tmp_path, None, "-c", "import neurohover")
    assert proc.stderr.strip().splitlines()[-1].startswith("ModuleNotFoundError: neurohover needs the package numba,"), proc.stderr
