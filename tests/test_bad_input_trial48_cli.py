"""Bad-input trial 48, side A (CLI): T48-A03 (evaluate-agent's --json, and its lock, resolved before a --callable that
changes the working directory runs)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest


@pytest.mark.parametrize("given", ["eaj2.json", "sub/x.json"])
def test_evaluate_agent_json_lands_where_given_when_the_callable_changes_directory(cli, tmp_path: Path, monkeypatch, given: str) -> None:
    """T48-A03: a --callable that calls os.chdir on its first call sent a relative --json into its new working
    directory (still printing "wrote eaj2.json") and left .eaj2.json.lock in the original folder; --json sub/x.json was
    refused only after the whole evaluation was flown."""
    home, away = tmp_path / "home", tmp_path / "away"
    home.mkdir()
    away.mkdir()
    module = f"chdir_agent_t48_{given[:3]}"
    (home / f"{module}.py").write_text(
        f"import os\nimport numpy as np\n\n\ndef act(obs):\n    os.chdir({str(away)!r})\n    return np.zeros((len(obs), 4))\n", encoding="utf-8"
    )
    monkeypatch.chdir(home)  # restored after the test, wherever the callable went
    monkeypatch.delitem(sys.modules, module, raising=False)
    try:
        rc, _, err = cli("evaluate-agent", "--task", "ghh08", "--n-mdps", "1", "--episode-steps", "5", "--callable", f"{module}:act", "--json", given)
    finally:
        sys.modules.pop(module, None)
    assert rc == 0, err
    assert Path.cwd() == away  # the callable did move
    assert f"wrote {given}" in err
    assert json.loads((home / given).read_text(encoding="utf-8"))["task"] == "ghh08"
    assert not list(away.rglob("*.json")), list(away.rglob("*"))
    assert not [p for p in tmp_path.rglob("*") if p.name.endswith(".lock")], list(tmp_path.rglob("*"))
