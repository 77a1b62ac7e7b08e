"""Bad-input trial 22, the command line (T22-18): argparse's own refusals (a type, a choice, a required option) printed
its usage block beside the error, 3-7 lines, where every other refusal is one line."""

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
