"""Items left by bad-input trials 42-44, taken up in the twenty-sixth session: `results --out .json` suggested the name
'.json.csv' (a hidden file '.json' has no suffix; 'out.json' was meant); `reproduce --only P --only P` was taken without a
word, where a repeated --obs-noise key is refused; `fly --record` took a 248-character name whose figures `plot` then
refused as too long."""

from __future__ import annotations

import pytest

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize(("given", "like"), [(".json", "out.json"), ("sub/.CSV", "sub/out.CSV"), ("x.txt", "x.csv")])
def test_a_hidden_name_that_is_only_a_suffix_is_suggested_with_a_name(cli, tmp_path, monkeypatch, committed_store, given, like) -> None:
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli("results", "table3", "--store", str(committed_store), "--out", given)
    assert rc == 2
    assert f"(e.g. '{like}')" in err, err
    assert not (tmp_path / "sub").exists()


def test_reproduce_refuses_one_only_pattern_given_twice(cli, tmp_path) -> None:
    store = tmp_path / "s.sqlite"
    rc, _, err = cli("reproduce", "table3", "--store", str(store), "--only", "run/*", "--only", "run/*")
    assert rc == 2
    assert "--only names the pattern 'run/*' twice: give each pattern once" in err, err
    assert not store.exists()


def test_the_api_refuses_one_only_pattern_given_twice(tmp_path) -> None:
    from neurohover.experiments import LocalExecutor, Store, load_config, reproduce

    with Store(tmp_path / "s.sqlite") as store, pytest.raises(NeurohoverError, match="only names the pattern 'a' twice"):
        reproduce(load_config("table3", "quick"), store, LocalExecutor(1), only=["a", "b", "a"])
    with Store(tmp_path / "s.sqlite") as store:
        assert store.experiments() == []


@pytest.mark.slow
def test_plot_cuts_a_recorded_name_too_long_for_its_figures(cli, tmp_path) -> None:
    flight = tmp_path / ("a" * 244 + ".npz")
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "2", "--record", str(flight))
    assert rc == 0, err
    rc, out, err = cli("plot", str(flight), "--out", str(tmp_path / "pl"))
    assert rc == 0, err
    names = sorted(p.name for p in (tmp_path / "pl").iterdir())
    assert len(names) == 2 and all(len(n.encode()) <= 255 and n.startswith("a" * 200) for n in names), names
    assert names[0].endswith("-episode0.png") and names[1].endswith("-episode1.png")
    assert "the flight's whole name is too long for them" in err
    assert out.split() == [str(tmp_path / "pl" / n) for n in names]


@pytest.mark.slow
def test_plot_keeps_a_name_that_fits(cli, tmp_path) -> None:
    flight = tmp_path / "short.npz"
    assert cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(flight))[0] == 0
    rc, _, err = cli("plot", str(flight), "--out", str(tmp_path / "pl"))
    assert rc == 0 and "too long" not in err
    assert [p.name for p in (tmp_path / "pl").iterdir()] == ["short-episode0.png"]
