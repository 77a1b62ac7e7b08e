"""Bad-input trial 53, side A (the command line): fly --record (and FlightData.save) replaced a .npz that neurohover did
not write, a user's own NumPy archive or a text file, without a word (T53-A04): refused now, naming it, as the other
writers refuse files they did not write; flight data neurohover wrote is still replaced. A sensor delay's text of a
value no whole number, 9.0000000000000001 (9.0 as a float), flew as delay 9 (T53-A05), and 99999999999999999999 was
named as 1e20 in its refusal (T53-A06): the delay is read from its text's own decimal value. An integer of more digits
than Python reads (4,300) in ``plot --episodes``, ``wins --runs`` or a drift's ``@LO-HI`` was "not allowed: give ..."
as if it were no number (T53-A01..A03): out of range now, named by its first digits and length."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover import NeurohoverError
from neurohover.experiments import Store


@pytest.mark.parametrize("made", ["archive", "text"])
def test_a04_a_npz_neurohover_did_not_write_is_not_replaced(tmp_path: Path, cli, made: str) -> None:
    path = tmp_path / "u3.npz"
    if made == "archive":
        np.savez(path, weights=np.ones(5))
    else:
        path.write_text("my notes\n")
    before = path.read_bytes()
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(path))
    assert rc == 2 and "is a file neurohover did not write: give another path (writing flight data (a NumPy archive) would destroy it)" in err, err
    fd = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), n_steps=10, record=True).flight_data
    with pytest.raises(NeurohoverError, match="is a file neurohover did not write"):
        fd.save(path)
    assert path.read_bytes() == before


def test_a04_flight_data_neurohover_wrote_is_replaced(tmp_path: Path, cli) -> None:
    path = tmp_path / "own.npz"
    for episodes in ("1", "2"):
        rc, _, err = cli("fly", "--task", "ghh08", "--episodes", episodes, "--record", str(path))
        assert rc == 0, err
    assert nh.FlightData.load(path).n_episodes == 2


@pytest.mark.parametrize(("text", "message"), [
    ("delay=9.0000000000000001", "sensor delay='9.0000000000000001' is not a whole number of control steps"),
    ("level=0.5,delay=3.0000000000000001", "sensor delay='3.0000000000000001' is not a whole number of control steps"),
    ("delay=99999999999999999999", "sensor delay=99999999999999999999 is out of range: allowed an integer in 0..10"),
])  # fmt: skip
def test_a05_a06_a_sensor_delay_is_read_from_its_text(cli, text: str, message: str) -> None:
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--obs-noise", text)
    assert rc == 2 and message in err, err


@pytest.mark.parametrize(("text", "delay"), [("delay=2.0", 2), ("delay=1e0", 1), ("delay=2", 2), ("level=0.5,delay=3", 3)])
def test_a05_whole_delays_in_any_form_are_taken(text: str, delay: int) -> None:
    assert nh.Sensor.parse(text).delay == delay


_PAST_PYTHON = "9" * 5000  # more digits than int() reads (sys.get_int_max_str_digits(): 4,300)
_OUT_OF_RANGE = "9999999999...(5,000 digits) is out of range: past every range neurohover allows"


def test_a01_a03_integers_past_python_digits_are_out_of_range(tmp_path: Path, cli, capsys) -> None:
    record = tmp_path / "f.npz"
    nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), n_steps=10, record=True).flight_data.save(record)
    Store(tmp_path / "s.sqlite").close()
    cases = [
        (("plot", str(record), "--out", str(tmp_path / "p"), "--episodes", f"0-{_PAST_PYTHON}"), "--episodes "),
        (("wins", "fig2", "--store", str(tmp_path / "s.sqlite"), "--runs", f"1,{_PAST_PYTHON}"), "--runs "),
        (("compete", "--task", "ghh08", "--agent", "baseline", "--out", str(tmp_path / "c"), "--runs", _PAST_PYTHON), "argument --runs: "),
        (("compete", "--task", "ghh08", "--agent", "baseline", "--out", str(tmp_path / "c"), "--drift", f"walk=0.01@1-{_PAST_PYTHON}"), "drift "),
    ]
    for args, option in cases:
        try:
            rc, _, err = cli(*args)
        except SystemExit as stop:  # argparse's own refusal (an option's type), in this process
            rc, err = stop.code, capsys.readouterr().err
        assert rc == 2 and option in err and _OUT_OF_RANGE in err and "Traceback" not in err, (args[0], err[-400:])
    assert not (tmp_path / "c").exists() and not (tmp_path / "p").exists()


def test_a01_a03_integers_python_reads_keep_their_messages() -> None:
    from neurohover.cli.options import integer
    from neurohover.errors import FloatRangeError, int_of

    assert integer("9" * 4300) == int("9" * 4300) and int_of(" -12 ") == -12
    with pytest.raises(FloatRangeError, match=r"\(4,301 digits\) is out of range"):
        int_of("+" + "1" * 4301)
    with pytest.raises(ValueError, match="invalid literal") as err:
        int_of("12a")
    assert not isinstance(err.value, FloatRangeError)
