"""Bad-input trial 22, flight data and compete directories as ``neurohover plot`` and ``learn-model`` read them: an
uncrashed episode shorter than its budget (T22-01), a NaN reading named by learn-model as by plot (T22-02)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FORMAT, FlightData
from neurohover.models.transitions import Transitions


def _episodes(*lengths: int) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    """Observations and actions of episodes of ``lengths`` steps, hovering about the spot (finite, unit quaternions)."""
    return tuple(np.full((n + 1, 12), 0.01) for n in lengths), tuple(np.zeros((n, 4)) for n in lengths)


def _write(path: Path, lengths: list[int], metadata: dict, obs: np.ndarray | None = None, act: np.ndarray | None = None) -> Path:
    """A flight-data file written as save() writes one, its metadata as given (not checked): an edited recording."""
    observations, actions = _episodes(*lengths)
    np.savez_compressed(
        path,
        format=np.array(FORMAT),
        lengths=np.array(lengths, dtype=np.int64),
        observations=np.concatenate(observations) if obs is None else obs,
        actions=np.concatenate(actions) if act is None else act,
        metadata=np.array(json.dumps(metadata)),
    )
    return path


SHORT = r"episode 0 has 30 steps, fewer than its metadata's episode_steps=60, yet its crashed flag is false"


def test_an_uncrashed_episode_shorter_than_its_budget_is_refused_by_plot_and_learn_model(tmp_path: Path, cli) -> None:
    """T22-01: a 6000-step recording cut to 3000 steps, its metadata unchanged (episode_steps 6000, crashed false), was
    drawn as "3000 steps, no crash" and learned from; now the file is refused naming the episode, its length, the
    budget and the flag, by FlightData.load, plot and learn-model."""
    path = _write(tmp_path / "short_nocrash.npz", [30, 60], {"episode_steps": 60, "crashed": [False, False], "returns": [-1.0, -2.0]})
    with pytest.raises(NeurohoverError, match=f"^flight-data file '{path}': {SHORT} "):
        FlightData.load(path)
    for argv in (
        ["plot", str(path), "--episodes", "0", "--out", str(tmp_path / "p")],
        ["learn-model", "--flight-data", str(path), "--method", "lr", "--out", str(tmp_path / "m.json")],
    ):
        rc, out, err = cli(*argv)
        assert rc == 2 and "Traceback" not in err and SHORT.replace("\\", "") in err, err
        assert out == "" and not list(tmp_path.glob("p/*.png")) and not (tmp_path / "m.json").exists()
    obs, act = _episodes(30, 60)
    with pytest.raises(NeurohoverError, match=f"^flight data: {SHORT}"):
        FlightData(obs, act, {"episode_steps": 60, "crashed": [False, False]})


def test_what_fly_and_older_files_record_of_short_episodes_is_taken(tmp_path: Path) -> None:
    """T22-01: what is not refused: a crash on the budget's last step (the kernel tests it after every step), a crashed
    shorter episode, a file with no crashed flags (recorded before they were) or no budget, and recordings of two budgets
    joined (their shorter full episodes or crashes: the joined data keep no budget, as none holds for all)."""
    obs, act = _episodes(30, 60)
    FlightData.load(_write(tmp_path / "a.npz", [30, 60], {"episode_steps": 60, "crashed": [True, True]}))
    FlightData.load(_write(tmp_path / "b.npz", [30, 60], {"episode_steps": 60}))
    FlightData.load(_write(tmp_path / "c.npz", [30, 60], {"crashed": [False, False]}))
    short = FlightData(obs[:1], act[:1], {"episode_steps": 30, "crashed": [False]})
    long = FlightData(obs[1:], act[1:], {"episode_steps": 60, "crashed": [False]})
    assert "episode_steps" not in (short + long).metadata and (short + long).metadata["crashed"] == [False, False]
    crashed = FlightData(obs[:1], act[:1], {"episode_steps": 30, "crashed": [True]})
    # every episode fits the longer budget, but the crash was charged for its own 30 (session 27: no budget kept)
    assert "episode_steps" not in (crashed + long).metadata
    assert (long + long).metadata["episode_steps"] == 60
    assert FlightData.load((short + long).save(tmp_path / "joined.npz")).n_episodes == 2


NAN_X = "episode 0: step 5 reads x = nan: no flight records a NaN or infinite observation, a crash's last one included; give flight data as flown"


def test_a_nan_reading_is_named_with_its_file_episode_step_and_variable_by_learn_model_and_plot(tmp_path: Path, cli) -> None:
    """T22-02: learn-model said only "flight data holds non-finite observations or actions" of a file whose
    observations[5, 3] was NaN, while plot named the episode, step and variable; now both name the file too."""
    obs = np.concatenate(_episodes(30, 30)[0])
    obs[5, 3] = np.nan
    path = _write(tmp_path / "nanobs.npz", [30, 30], {"episode_steps": 30, "crashed": [False, False]}, obs=obs)
    for argv in (
        ["learn-model", "--flight-data", str(path), "--method", "lr", "--out", str(tmp_path / "m.json")],
        ["plot", str(path), "--out", str(tmp_path / "p")],
    ):
        rc, out, err = cli(*argv)
        assert rc == 2 and "Traceback" not in err and f"flight-data file '{path}', {NAN_X}" in err, err
        assert out == "" and not (tmp_path / "m.json").exists() and not list(tmp_path.glob("p/*.png"))


def test_transitions_name_a_non_finite_reading_and_drop_a_crashed_episodes_last_nan_action() -> None:
    """T22-02: flight data made in Python are checked by the same function as a file, by Transitions (so every learner):
    a NaN observation or a NaN action but a crashed episode's last is refused by name; that last one's transition is
    dropped, not learned from (the simulator never flew it)."""
    obs, act = _episodes(30, 30)
    nan_obs = (obs[0].copy(), obs[1])
    nan_obs[0][5, 3] = np.nan
    with pytest.raises(NeurohoverError, match=f"^flight data, {NAN_X}"):
        Transitions(FlightData(nan_obs, act, {"episode_steps": 30, "crashed": [False, False]}))
    nan_act = (act[0], act[1].copy())
    nan_act[1][-1, 2] = np.inf
    with pytest.raises(
        NeurohoverError, match="^flight data, episode 1: step 29 reads rudder = inf: no flight records a NaN or infinite action, but as a crashed"
    ):
        Transitions(FlightData(obs, nan_act, {"episode_steps": 30, "crashed": [False, False]}))
    short = (act[0], act[1][:20].copy())
    short[1][-1] = np.nan
    tr = Transitions(FlightData((obs[0], obs[1][:21]), short, {"episode_steps": 30, "crashed": [False, True]}))
    assert tr.n == 30 + 19 and np.isfinite(tr.act).all() and tr.n_episodes == 2


def _competition(folder: Path, rows: str, **summary: object) -> Path:
    """A compete output directory as ``compete --task ghh08 --agent baseline --runs 2 --episodes 2 --episode-steps 20``
    writes one (its crash figures left out of the summary, as a hand edit may), with the episodes.csv rows given."""
    folder.mkdir()
    (folder / "episodes.csv").write_text("run,mdp,episode,return,crashed,steps,policy,safeguard_fired\n" + rows)
    base = {"task": "ghh08", "agent": "baseline", "mdps": "test", "episode_steps": 20, "sigma": None, "sensor": None, "drift": None, "runs": 2}
    (folder / "summary.json").write_text(json.dumps({**base, "experiment": "compete-ghh08-baseline", "episodes": 2, **summary}))
    return folder


ROWS = ["0,ghh08/test:0,0,-58.5,0,20,baseline,0", "0,ghh08/test:0,1,-66.4,0,20,baseline,0", "1,ghh08/test:1,0,-35.4,0,20,baseline,0"]
ROWS += ["1,ghh08/test:1,1,-49.2,0,20,baseline,0"]


def _rows(line: int = 0, value: str = "", column: int = 0) -> str:
    """The four rows of :data:`ROWS`, row ``line`` (2: the first) with ``column`` set to ``value``."""
    rows = [r.split(",") for r in ROWS]
    if line:
        rows[line - 2][column] = value
    return "".join(",".join(r) + "\n" for r in rows)


@pytest.mark.parametrize("value", ["-1", "5"])
def test_a_compete_crash_flag_other_than_0_or_1_is_refused_with_its_line(tmp_path: Path, cli, value: str) -> None:
    """T22-03: episodes.csv line 2's crashed set to -1 (the summary's crash figures removed) was plotted as "-1 crashes"
    and read as CompeteResult.crashes == -1; now refused, naming the line and the value, status 2 on the command line."""
    from neurohover.compete_files import read_compete_dir

    assert read_compete_dir(_competition(tmp_path / "ok", _rows())).crashes == 0
    folder = _competition(tmp_path / "c1", _rows(2, value, 4))
    message = f"--compete '{folder / 'episodes.csv'}', line 2: crashed '{value}' is not allowed: 0 or 1 (whether the episode crashed)"
    with pytest.raises(NeurohoverError, match=f"^{re.escape(message)}$"):
        read_compete_dir(folder)
    rc, out, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "p"))
    assert rc == 2 and "Traceback" not in err and message in err and out == "", err


COMPETE_ROWS = "episodes.csv', line 2: "


@pytest.mark.parametrize(
    ("column", "value", "summary", "message"),
    [
        (5, "-5", {"episode_steps": None}, f"{COMPETE_ROWS}steps '-5' is not allowed: an episode's steps, an integer in 1..10,000,000"),
        (0, str(10**18), {}, f"{COMPETE_ROWS}run 1000000000000000000 is not allowed: compete numbers its runs 0, 1, 2, ..."),
        (0, str(10**30), {}, f"{COMPETE_ROWS}run '1000000000000000000000000000000' is not allowed: allowed a whole number (at most 19 digits)"),
        (1, "zzz", {}, f"{COMPETE_ROWS}mdp 'zzz' is not allowed: a ghh08 MDP's label, ghh08/SET:I (SET test, train, seeded-test, seeded-train or sample)"),
        (7, "7", {}, f"{COMPETE_ROWS}safeguard_fired '7' is not allowed: 0 or 1 (whether the safeguard took over)"),
        (0, "0", {"sigma": float("nan")}, "summary.json' says sigma nan, which compete never flies under: a family's breadth is a finite number >= 0"),
        (0, "0", {"sensor": {"level": -5}}, "summary.json' says sensor {'level': -5}, which compete never flies under: sensor noise level=-5 is out of range"),
        (0, "0", {"drift": "junk"}, "summary.json' says drift 'junk', which compete never flies under: a drift must be a table of settings"),
    ],
    ids=["steps", "run", "run-digits", "mdp", "safeguard_fired", "sigma", "sensor", "drift"],
)
def test_compete_rows_and_conditions_compete_never_writes_are_refused_by_name(tmp_path: Path, column: int, value: str, summary: dict, message: str) -> None:
    """T22-04: in episodes.csv steps -5 (a summary without episode_steps), run 10**30, mdp 'zzz' and safeguard_fired 7, and
    in summary.json sigma NaN, sensor {"level": -5} and drift "junk" were all plotted without a word; each is refused,
    naming the file, line or key and the value."""
    from neurohover.compete_files import read_compete_dir

    with pytest.raises(NeurohoverError, match=f"^--compete '{re.escape(str(tmp_path / 'c'))}/{re.escape(message)}"):
        read_compete_dir(_competition(tmp_path / "c", _rows(2, value, column), **summary))


def test_compete_conditions_compete_writes_are_read(tmp_path: Path) -> None:
    """T22-04: what compete writes is read: a sigma, a sensor's and a drift's settings, and no drift written as Drift()
    writes itself (walk 0, no change), which Drift.from_dict alone would call a drift of nothing."""
    from neurohover.compete_files import read_compete_dir
    from neurohover.tasks import Drift, Sensor

    for i, (name, value) in enumerate(
        # sigma None: what compete writes for ghh08, which has no breadth (its 0.5 was read; T23-06: fghh's in trial 23's tests)
        (("sigma", None), ("sensor", Sensor.at_level(1.0).to_dict()), ("drift", Drift().to_dict()), ("drift", Drift(0.01).to_dict()))
    ):
        assert read_compete_dir(_competition(tmp_path / str(i), _rows(), **{name: value})).conditions[name] == value
