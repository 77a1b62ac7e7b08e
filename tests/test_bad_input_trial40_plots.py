"""Bad-input trial 40, side B, plots and the rest: plot_cumulative took no str path and failed on a list, None or text
curve (T40-B09), wrote PNG data under .pdf/.jpg names and drew NaN, 3-D or no curves without a word (T40-B11);
new_figure took a figure narrower than one pixel, which save_figure could not write (T40-B10); plot_flight_data's
stem takes a newline as a file name does (T40-B13, pinned); a manifest without its lineage was refused for its ancestor.json digest, naming no
lineage (T40-B07); compete's on_result of the wrong arity was a TypeError after the first unit (T40-B02); a user
optimiser's own stop reason was refused in its champion's record and its checkpoint, and a set built by a user
optimiser was refused by the process that built it (after T40-B14)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover import plots
from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve
from neurohover.evolution.optimisers import OPTIMISERS, OptimiserSpec

PNG = b"\x89PNG\r\n\x1a\n"
CURVE = {"agent": np.cumsum(-np.ones((2, 10)), axis=1)}


@pytest.mark.slow
def test_plot_cumulative_takes_a_str_path_and_a_one_run_curve(tmp_path: Path) -> None:
    path = plots.plot_cumulative(CURVE, str(tmp_path / "sub" / "cum.png"), "title")
    assert path == tmp_path / "sub" / "cum.png" and path.read_bytes()[:8] == PNG
    one_run = plots.plot_cumulative({"a": [-1.0, -2.0, -4.0]}, tmp_path / "one.png", "one run")
    assert one_run.read_bytes()[:8] == PNG


@pytest.mark.parametrize(
    ("curves", "message"),
    [
        ({"a": None}, r"curve 'a'=None is not allowed: give a 2-D array of runs x episodes \(or 1-D, one run\) of cumulative rewards"),
        ({"a": np.array(["x", "y"])}, r"curve 'a'=array\(\['x', 'y'\].* is not allowed: give a 2-D array"),
        ({"a": "text"}, r"curve 'a'='text' is not allowed"),
        ({"a": np.full(5, np.nan)}, r"curve 'a''s entry nan is not allowed: give .* finite numbers <= 0"),
        ({"a": [-1.0, 2.0]}, r"curve 'a''s entry 2.0 is not allowed"),
        ({"a": np.zeros((2, 2, 5))}, r"curve 'a' of shape \(2, 2, 5\) is not allowed"),
        ({"a": np.zeros((2, 0))}, r"curve 'a' of shape \(2, 0\) is not allowed"),
        ({}, r"curves=\{\} is not allowed: give a dict of one or more label -> a 2-D array"),
        ([-1.0, -2.0], r"curves=\[-1.0, -2.0\] is not allowed: give a dict"),
        ({5: [-1.0]}, r"curves' label 5 is not allowed: give text naming the curve"),
    ],
)
def test_plot_cumulative_refuses_a_bad_curve_by_name(curves, message, tmp_path: Path) -> None:
    with pytest.raises(NeurohoverError, match=message):
        plots.plot_cumulative(curves, tmp_path / "cum.png", "t")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["cum.pdf", "c.jpg"])
def test_plot_cumulative_writes_png_names_only(name: str, tmp_path: Path) -> None:
    with pytest.raises(NeurohoverError, match=r"a plot is PNG; give a path ending .png"):
        plots.plot_cumulative(CURVE, tmp_path / name, "t")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("width", "height", "dpi"), [(0.001, 1, 100), (1e-300, 1, 100), (1, 0.5, 1)])
def test_a_figure_side_under_one_pixel_is_refused(width, height, dpi) -> None:
    name, value = ("width", width) if width * dpi < 1 else ("height", height)
    with pytest.raises(NeurohoverError, match=rf"figure {name}={value!r} is out of range: .* pixels, and a side is at least 1 pixel \(allowed"):
        plots.new_figure(width, height, dpi)


def test_a_figure_of_one_pixel_is_written(tmp_path: Path) -> None:
    assert plots.save_figure(plots.new_figure(0.01, 1), tmp_path / "tiny.png").read_bytes()[:8] == PNG


@pytest.mark.slow
def test_plot_flight_data_takes_a_stem_as_a_file_name_takes_it(tmp_path: Path) -> None:
    """T40-B13 (plot part), not a bug: a stem is a file-name prefix, and file names take control characters (``neurohover
    plot 'a\\nb.npz'`` writes 'a\\nb-episode0.png', its stem the file's: T14-24's test), escaped where they are shown;
    the title shows it escaped. A separator, NUL or '' is refused (trial 11)."""
    data = nh.FlightData((np.zeros((6, 12)),), (np.zeros((5, 4)),), {"episode_steps": 5, "crashed": [False]})
    assert plots.plot_flight_data(data, tmp_path, stem="run\n1") == [tmp_path / "run\n1-episode0.png"]
    with pytest.raises(NeurohoverError, match=r"stem='a\\x00b' is not allowed: give a non-empty file-name prefix"):
        plots.plot_flight_data(data, tmp_path, stem="a\x00b")


def test_a_manifest_without_its_lineage_is_refused_naming_it(tmp_path: Path) -> None:
    shutil.copytree(Path(nh.__file__).parent / "data" / "policies" / "ghh08", tmp_path / "ghh08")
    path = tmp_path / "ghh08" / "manifest.json"
    manifest = json.loads(path.read_text())
    assert manifest.pop("lineage") == "chain"
    path.write_text(json.dumps(manifest))
    from neurohover.policysets import load_policy_set

    with pytest.raises(NeurohoverError, match=r"manifest.json' has no lineage, and its genome_sha256 records ancestor.json, .*: give lineage 'chain'"):
        load_policy_set("ghh08", tmp_path)


def test_compete_refuses_on_result_of_the_wrong_arity_up_front(tmp_path: Path) -> None:
    from neurohover.compete import compete

    message = r"on_result of signature '\(result\)' is not allowed: it is called as on_result\(unit key, TestRunResult\)"
    with pytest.raises(NeurohoverError, match=message):
        compete("ghh08", "baseline", runs=1, episodes=2, n_steps=20, out=tmp_path / "cmp", on_result=lambda result: None)
    assert list(tmp_path.iterdir()) == []


class _Stops:
    """An optimiser wrapper whose own stop() ends the run at once (its spec's stop_reason 'my-stop')."""

    def __init__(self, inner) -> None:
        self.inner = inner

    def __getattr__(self, name):
        return getattr(self.inner, name)

    def stop(self) -> bool:
        return True

    @classmethod
    def from_state_dict(cls, *args, **kwargs):
        return cls(type(OPTIMISERS["openai-es"].make(np.zeros(40), OPTIMISERS["openai-es"].settings(), 0)).from_state_dict(*args, **kwargs))


@pytest.fixture
def my_stop(monkeypatch):
    spec = OPTIMISERS["openai-es"]
    mine = OptimiserSpec("my-es", "mine", spec.settings, lambda proto, settings, seed: _Stops(spec.make(proto, settings, seed)), stop_reason="my-stop")
    monkeypatch.setitem(OPTIMISERS, "my-es", mine)


def test_a_user_optimisers_own_stop_is_saved_and_resumed(my_stop, tmp_path: Path) -> None:
    mdp = nh.get_task_family("ghh08").mdp("train:0")
    run = {"optimizer": "my-es", "topology": "slp", "budget": 100, "seed": 0, "n_steps": 20, "checkpoint": tmp_path / "ck.json"}
    result = evolve(mdp, **run)
    assert result.champion.metadata["stop_reason"] == "my-stop"
    nh.save_policy(result.champion, tmp_path / "champ.json")
    assert nh.load_policy(tmp_path / "champ.json").metadata["method"] == "user:my-es"
    assert evolve(mdp, **run, resume=True).champion.metadata["stop_reason"] == "my-stop"
    record = json.loads((tmp_path / "champ.json").read_text())
    (tmp_path / "bad.json").write_text(json.dumps({**record, "stop_reason": "my\nstop"}))
    with pytest.raises(NeurohoverError, match=r"its stop_reason='my\\nstop' is not allowed: give a non-empty text \(one line, printable\)"):
        nh.load_policy(tmp_path / "bad.json")


@pytest.mark.slow
def test_a_set_built_by_a_user_optimiser_loads_where_it_was_built(monkeypatch, tmp_path: Path) -> None:
    from neurohover.manifest import built_as
    from neurohover.policysets import build_policy_set, load_policy_set, policy_set_roles

    spec = OPTIMISERS["openai-es"]
    monkeypatch.setitem(OPTIMISERS, "my-es", OptimiserSpec("my-es", "mine", spec.settings, spec.make, stops_itself=False))
    build_policy_set("ghh08", tmp_path, budget=12, n_steps=20, safety_episodes=1, optimizer="my-es")
    assert load_policy_set("ghh08", tmp_path).generic.metadata["method"] == "user:my-es"
    role = policy_set_roles("ghh08")[0]
    assert built_as({"optimizer": "my-es"}, role, 0)["method"] == "user:my-es"
    assert "method" not in built_as({"optimizer": "user:my-es"}, role, 0)  # a user's optimiser named as its policies name it
