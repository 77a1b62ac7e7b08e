"""Helpers of the tests that hand-edit a policy file's record and read what load_policy said of it (trials 25, 26)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError


def evolved_policy_file(where: Path) -> Path:
    """A policy file as evolve writes it under ``where``: a 10-episode run of 20-step episodes on ghh08/train:0."""
    from neurohover.cli import main

    out = where / "p.json"
    argv = ["evolve", "--task", "ghh08", "--mdp", "train:0", "--topology", "slp", "--seed-policy", "baseline", "--budget", "10"]
    assert main([*argv, "--episode-steps", "20", "--seed", "1", "--out", str(out)]) == 0
    return out


def edited(src: Path, dst: Path, **changes: Any) -> Path:
    """``src``'s JSON file with ``changes`` (a value None: the key removed) written to ``dst``."""
    data = json.loads(src.read_text())
    data.update(changes)
    dst.write_text(json.dumps({k: v for k, v in data.items() if v is not None}))
    return dst


def refused(path: Path, *words: str) -> str:
    """load_policy's one-line refusal of ``path``, naming the file and holding each of ``words``."""
    with pytest.raises(NeurohoverError) as err:
        nh.load_policy(path)
    message = str(err.value)
    assert message.startswith(f"policy file {str(path)!r}: its "), message
    for word in words:
        assert word in message, message
    return message
