"""Bad-input trials 22 and 23, the command line: argparse's own refusals (a type, a choice, a required option) printed
its usage block beside the error, 3-7 lines, where every other refusal is one line (T22-18); report made its --out folder
before refusing an experiment named twice (T23-18)."""

from __future__ import annotations

import pytest


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["fly", "--task", "ghh08", "--episodes", "abc"], "neurohover fly: error: argument --episodes: invalid integer value: 'abc' (usage: neurohover fly"),
        (["fly"], "neurohover fly: error: the following arguments are required: --task (usage: neurohover fly --help)"),
        (["wins", "x", "--store", "s.sqlite", "--scale", ""], "neurohover wins: error: argument --scale: '' is not allowed"),
        (["flyy"], "neurohover: error: argument COMMAND: invalid choice: 'flyy'"),
    ],
)
def test_an_argparse_refusal_is_one_line_pointing_to_help(argv: list[str], message: str, capsys) -> None:
    from neurohover.cli import main

    with pytest.raises(SystemExit) as done:
        main(argv)
    out, err = capsys.readouterr()
    assert done.value.code == 2 and out == "", err
    assert len(err.splitlines()) == 1 and err.startswith(message), err


def test_report_refuses_an_experiment_named_twice_before_making_its_folder(tmp_path, capsys) -> None:
    """T23-18: `report --out R2 fig2 fig2` made R2, refused, and removed it: three lines where one refusal is one."""
    from neurohover.cli import main
    from neurohover.experiments import Store

    Store(tmp_path / "s.sqlite").close()
    assert main(["report", "--store", str(tmp_path / "s.sqlite"), "--out", str(tmp_path / "R2"), "fig2", "fig2"]) == 2
    err = capsys.readouterr().err
    assert err == "neurohover report: error: experiment 'fig2' is named more than once: give each once\n", err
    assert not (tmp_path / "R2").exists()
