"""Every command's every option fed the classes of bad values (issue 37): no traceback, ever, and every
number option refuses what no run can mean (negative, not a number, infinite, too large) with exit 2.

Each command gets a small valid base (one episode, a few steps) so that a value it accepts runs in a
moment; the option under test comes last, so it is the one the command reads.
"""

from __future__ import annotations

import argparse
import subprocess
import sys

import pytest

from neurohover.cli import build_parser, main
from neurohover.cli.options import real

#: Values every option is fed; for an int or float option the first four must be refused.
BAD = ("-1", "abc", "nan", "1e15", "inf", "", "0", "1" + "0" * 400)
#: Options for which an infinite or huge value has a meaning (seconds between checkpoints: never).
UNBOUNDED = {("evolve", "--checkpoint-every")}


def _base(tmp) -> dict[str, list[str]]:
    o = str(tmp)
    return {
        "fly": ["--task", "ghh08", "--episodes", "1"],
        "demo": ["--mdps", "1", "--episodes", "1"],
        "evolve": ["--task", "ghh08", "--out", f"{o}/ev.json", "--budget", "2", "--episode-steps", "20", "--validation-episodes", "1"],
        "learn-model": ["--flight-data", f"{o}/flight.npz", "--method", "lr", "--out", f"{o}/m.json"],
        "build-policies": ["--task", "ghh08", "--out", f"{o}/bp", "--budget", "2", "--episode-steps", "20"],
        "compete": ["--task", "ghh08", "--agent", "model-free", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", f"{o}/c"],
        "evaluate-agent": ["--task", "ghh08", "--n-mdps", "1", "--episodes", "1", "--episode-steps", "20"],
        "reproduce": ["fig2", "--store", f"{o}/r.sqlite", "--only", "nomatch*"],
        "results": ["fig2", "--store", f"{o}/r.sqlite"],
        "wins": ["fig2", "--store", f"{o}/r.sqlite"],
        "report": ["fig2", "--store", f"{o}/r.sqlite", "--out", f"{o}/rep"],
        "plot": [f"{o}/flight.npz"],
    }


def _options():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, p in sub.choices.items():
        for act in p._actions:
            if act.option_strings and act.nargs != 0 and not act.choices and not isinstance(act, argparse._HelpAction):
                yield name, act.option_strings[-1], act.type


@pytest.mark.slow
def test_no_option_of_any_command_ends_in_a_traceback(tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)  # options that name files write them here
    assert main(["fly", "--task", "ghh08", "--episodes", "1", "--record", str(tmp_path / "flight.npz")]) == 0
    base = _base(tmp_path)
    options = list(_options())
    assert {name for name, _, _ in options} >= set(base) - {"bench"}  # every command with options is fed
    silent = []
    for name, opt, kind in options:
        for value in BAD:
            try:
                rc = main([name, *base.get(name, []), opt, value])
            except SystemExit as stop:  # argparse's own refusal
                rc = stop.code
            err = capsys.readouterr().err
            assert "Traceback" not in err, f"{name} {opt} {value!r}: {err[-400:]}"
            assert rc in (0, 2), f"{name} {opt} {value!r}: exit {rc}"
            if rc == 2:
                assert err.strip().splitlines()[-1].startswith(("neurohover", "usage")), f"{name} {opt} {value!r}: {err[-300:]}"
            assert "0" * 100 not in err, f"{name} {opt}: a 400-digit value echoed whole: {err[-300:]}"
            numeric = kind in (int, float, real)
            must_refuse = value in ("-1", "abc", "nan") or (value in ("inf", "1e15", BAD[-1]) and (name, opt) not in UNBOUNDED)
            if numeric and must_refuse and rc != 2:
                silent.append(f"{name} {opt} {value}")
    assert not silent, f"accepted without a word: {silent}"


@pytest.mark.slow
def test_a_reader_that_goes_away_ends_the_command_quietly() -> None:
    """`neurohover demo | head -1`: the pipe closes under the table, and no traceback follows."""
    demo = subprocess.Popen([sys.executable, "-m", "neurohover", "demo", "--mdps", "2", "--episodes", "1"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert demo.stdout is not None and demo.stderr is not None
    demo.stdout.readline()
    demo.stdout.close()  # the reader goes away before the rest of the table
    err = demo.stderr.read().decode()
    assert demo.wait(timeout=120) in (0, 1)
    assert "Traceback" not in err and "BrokenPipe" not in err
