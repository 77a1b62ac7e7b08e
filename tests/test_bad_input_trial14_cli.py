"""The fourteenth bad-input trial's command-line findings (and the items earlier trials left): each gives one clear
message (exit 2) naming the value and what is allowed, before any work is done."""

from __future__ import annotations

from pathlib import Path


def test_evolve_refuses_a_net_out_before_evolving(tmp_path: Path, cli) -> None:
    """evolve --out p.net was refused only when the evolved policy was saved (JSON under .net, which load_policy reads
    as the authors' format), so the whole run was lost; it is refused up front, leaving no history or checkpoint."""
    out = tmp_path / "p.net"
    rc, _, err = cli("evolve", "--task", "ghh08", "--out", str(out), "--budget", "10")
    assert rc == 2
    assert f"--out {str(out)!r}: a policy is written as JSON" in err and "give a .json name" in err
    assert list(tmp_path.iterdir()) == []


def test_written_names_are_printed_escaped(tmp_path: Path, cli) -> None:
    """T14-24 (the lines outside the plots and fly): evaluate-agent's 'wrote', report's 'report written to' printed a
    newline or a RIGHT-TO-LEFT OVERRIDE in the name raw, splitting the line or showing it reversed."""
    out = tmp_path / "a\nb\u202ec.json"
    rc, _, err = cli(
        "evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--n-mdps", "1", "--episodes", "1", "--episode-steps", "20", "--json", str(out)
    )
    assert rc == 0 and out.is_file()
    assert f"wrote {tmp_path}/a\\nb\\u202ec.json" in err and "\u202e" not in err


def test_an_array_in_a_message_is_shown_on_one_line() -> None:
    """The evolution fixer's note on T14-6: brief() of a NumPy array kept its repr's line breaks, splitting a message."""
    import numpy as np

    from neurohover.errors import brief

    assert brief(np.zeros((2, 2))) == "array([[0., 0.], [0., 0.]])"


def test_a_long_bad_experiment_name_is_shown_briefly() -> None:
    """The store fixer's note: check_name echoed a bad name whole ({name!r}), so a 100,000-character name made a line as long."""
    import pytest

    from neurohover.errors import NeurohoverError
    from neurohover.experiments.config import check_name

    with pytest.raises(NeurohoverError, match=r"name = '//////////.*\(100,000 characters\) is not allowed") as err:
        check_name("/" * 100_000, "here")
    assert len(str(err.value)) < 250
