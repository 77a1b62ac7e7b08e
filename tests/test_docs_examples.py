"""The documentation's examples run as written, and the package metadata says what it should."""

from __future__ import annotations

import importlib.metadata
import os
import re
import shutil
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest
from conftest import ROOT

import neurohover
import neurohover.experiments

README = ROOT / "README.md"


def _readme_python_blocks() -> list[tuple[str, str]]:
    """(section heading, code) of every ```python block of the README, in order."""
    blocks, heading = [], ""
    for section in re.split(r"^(## .*)$", README.read_text(), flags=re.M):
        if section.startswith("## "):
            heading = section[3:].strip()
            continue
        blocks += [(heading, code) for code in re.findall(r"^```python\n(.*?)^```", section, flags=re.S | re.M)]
    return blocks


def _run_script(code: str, cwd: Path, name: str = "example.py") -> subprocess.CompletedProcess:
    script = cwd / name
    script.write_text(code)
    return subprocess.run([sys.executable, str(script)], cwd=cwd, capture_output=True, text=True, timeout=600)


def test_readme_has_python_examples() -> None:
    assert len(_readme_python_blocks()) >= 3


def test_the_readmes_new_agent_is_found_and_flies_as_it_says(tmp_path: Path, monkeypatch) -> None:
    """The contributor section's agent module, dropped into a package, is discovered and keeps the better candidate."""
    from neurohover.agents.protocol import run_test
    from neurohover.agents.registry import discover, policies_from_set
    from neurohover.agents.spec import AgentOptions
    from neurohover.policysets import load_policy_set

    (code,) = [c for _, c in _readme_python_blocks() if c.startswith("# neurohover/agents/best_of_two.py")]
    (tmp_path / "myagents").mkdir()
    (tmp_path / "myagents" / "__init__.py").write_text("")
    (tmp_path / "myagents" / "best_of_two.py").write_text(code)
    monkeypatch.syspath_prepend(str(tmp_path))
    spec = discover("myagents")["best-of-two"]
    ghh08 = neurohover.get_task_family("ghh08")
    agent = spec.build(policies_from_set(spec, load_policy_set("ghh08")), AgentOptions())
    run = run_test(agent, ghh08, ghh08.mdp("train:0"), episodes=4, seed=1, n_steps=300)
    better = int(run.returns[1] > run.returns[0])
    assert run.policy[:2] == ["candidate:0", "candidate:1"] and run.policy[2:] == [f"candidate:{better}"] * 2
    sys.modules.pop("myagents", None)
    sys.modules.pop("myagents.best_of_two", None)


@pytest.mark.slow
@pytest.mark.parametrize("index", range(len(_readme_python_blocks())), ids=[f"{i}-{h}" for i, (h, _) in enumerate(_readme_python_blocks())])
def test_readme_python_block_runs_as_written(index: int, tmp_path: Path) -> None:
    heading, code = _readme_python_blocks()[index]
    proc = _run_script(code, tmp_path)
    assert proc.returncode == 0, f"README block {index} (## {heading}) failed:\n{code}\n{proc.stderr}"


@pytest.mark.slow
def test_experiments_docstring_example_runs_as_a_script(tmp_path: Path) -> None:
    doc = neurohover.experiments.__doc__
    example = doc[doc.index("Example\n-------") :]
    if ">>> " in example:  # doctest form: the prompted lines, prompts removed
        code = "\n".join(line[4:] for line in example.splitlines() if line.startswith((">>> ", "... ")))
    else:  # the literal block after "::"
        lines = []
        for line in example[example.index("::\n\n") + 4 :].splitlines():
            if line and not line.startswith("    "):
                break
            lines.append(line)
        code = textwrap.dedent("\n".join(lines))
    assert "reproduce(" in code and "write_report(" in code
    proc = _run_script(code, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert " failed:" not in proc.stderr, proc.stderr  # units are reported, not raised, when workers die
    assert "status='finished'" in proc.stdout
    assert (tmp_path / "results.sqlite").is_file()
    assert (tmp_path / "report" / "report.md").read_text().strip()


@pytest.mark.slow
def test_version_is_the_installed_distributions(tmp_path: Path) -> None:
    assert neurohover.__version__ == importlib.metadata.version("neurohover")
    # A distribution found first on sys.path supplies the version: nothing is hard-coded.
    dist = tmp_path / "neurohover-9.8.7.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: neurohover\nVersion: 9.8.7\n")
    proc = subprocess.run(
        [sys.executable, "-c", "import neurohover; print(neurohover.__version__)"],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(tmp_path)},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "9.8.7"


def test_pyproject_names_authors_and_urls() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["authors"] and all(a.get("name") for a in project["authors"])
    assert project["urls"] and all(u.startswith("https://") for u in project["urls"].values())


@pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(), reason="needs a git checkout")
def test_quickstart_output_is_ignored_by_git() -> None:
    # The README's first command writes quickstart/ in the checkout.
    proc = subprocess.run(["git", "check-ignore", "-q", "quickstart/summary.csv"], cwd=ROOT)
    assert proc.returncode == 0
