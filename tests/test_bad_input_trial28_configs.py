"""The twenty-eighth bad-input trial's findings in experiment configs, KEY=VALUE options and --only (T28-A02, T28-A03,
T28-A06, T28-A07, T28-A09, T28-A10, T28-A11): a [settings] or [scales] table of the wrong TOML shape was a TypeError and
``scales = "quick"`` named the scales c, i, k, q, u (A02); a group label naming another agent passed for that agent in
wins, the report and the paper's claims (A03); a newline in a --set, --agent-setting or --setting VALUE dropped what
followed it (A06); a newline in a title or paper_ref put headings into the report, and a title of 20,000 characters was
taken (A07); [paper] table and table3 of a test-runs config were checked, then never shown (A09); a name differing from
a shipped one (or a stored one) only in case was taken (A10); --only's '*' crossed the '/' inside a group label (A11)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CliRun, tiny_test_runs
from store_edits import begin, error

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store
from neurohover.experiments.config import load_config, make_config, parse_override
from neurohover.experiments.keys import key_matches
from neurohover.experiments.runner import selected

BASE = tiny_test_runs("baseline", "model-free", name="mini")


def _config(tmp_path: Path, text: str, name: str = "c.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _refused(tmp_path: Path, text: str, *needles: str) -> str:
    path = _config(tmp_path, text)
    with pytest.raises(NeurohoverError) as err:
        load_config(str(path), "quick")
    message = str(err.value)
    assert "\n" not in message and all(n in message for n in needles), message
    return message


# ------------------------------------------------------------------------------------------------ T28-A02


@pytest.mark.parametrize(
    ("edit", "needles"),
    [
        (lambda t: t.replace("[scales.quick]", "[[scales.quick]]"), ("scales.quick = [", "give a table of settings ([scales.quick], not [[scales.quick]])")),
        (lambda t: t + "[[scales.paper]]\nepisodes = 3\n", ("scales.paper = [", "not [[scales.paper]]")),
        (lambda t: t.split("[scales.quick]")[0].replace("[settings]", "scales = { quick = 5 }\n[settings]"), ("scales.quick = 5 is not allowed",)),
        (lambda t: t.split("[scales.quick]")[0].replace("[settings]", "scales = 5\n[settings]"), ("scales = 5 is not allowed: give a table of scale tables",)),
        (lambda t: t.split("[scales.quick]")[0].replace("[settings]", 'scales = "quick"\n[settings]'), ("scales = 'quick' is not allowed",)),
        (
            lambda t: 'name = "mini"\nkind = "test_runs"\nsettings = 5\n[scales.quick]\nepisodes = 2\n',
            ("settings = 5 is not allowed: give a table of settings",),
        ),
        (lambda t: t.replace("[settings]", "[[settings]]"), ("settings = [", "([settings], not [[settings]])")),
    ],
    ids=["scales-quick-array", "scales-paper-array", "scales-quick-int", "scales-int", "scales-str", "settings-int", "settings-array"],
)
def test_a02_tables_of_the_wrong_toml_shape_are_refused_by_name(tmp_path: Path, edit, needles) -> None:
    _refused(tmp_path, edit(BASE), *needles)


def test_a02_the_cli_names_the_table_and_makes_no_store(tmp_path: Path, cli: CliRun) -> None:
    config = _config(tmp_path, BASE.replace("[scales.quick]", "[[scales.quick]]"))
    rc, _, err = cli("reproduce", str(config), "--store", str(tmp_path / "s.sqlite"), "--no-progress")
    assert rc == 2 and "scales.quick = [" in error(err, "reproduce"), err
    assert not (tmp_path / "s.sqlite").exists()


# ------------------------------------------------------------------------------------------------ T28-A03

GROUPS_FIG7 = [
    {"agent": "model-free", "mdps": "test", "n_mdps": 1},
    {"agent": "baseline", "label": "incremental", "mdps": "test", "n_mdps": 1},
]


def test_a03_a_label_naming_another_agent_is_refused(tmp_path: Path) -> None:
    swapped = BASE.replace('agent = "baseline"\n', 'agent = "baseline"\nlabel = "model-free"\n').replace(
        'agent = "model-free"\n', 'agent = "model-free"\nlabel = "baseline"\n'
    )
    _refused(tmp_path, swapped, "group label 'model-free' is not allowed for agent 'baseline': it is the name of the agent 'model-free'")
    settings = {"task": "ghh08", "seed": 1, "policies": "shipped", "episodes": 2, "n_steps": 20, "groups": GROUPS_FIG7}
    with pytest.raises(NeurohoverError, match="group label 'incremental' is not allowed for agent 'baseline': it is the name of the agent 'incremental'"):
        make_config("x28", "test_runs", "quick", settings)
    with pytest.raises(NeurohoverError, match="group label 'Incremental' is not allowed for agent 'baseline'"):  # case aside
        make_config("x28", "test_runs", "quick", {**settings, "groups": [{**GROUPS_FIG7[1], "label": "Incremental"}]})
    own = make_config("x28", "test_runs", "quick", {**settings, "groups": [{**GROUPS_FIG7[0], "label": "model-free"}, {**GROUPS_FIG7[1], "label": "base"}]})
    assert [g["label"] for g in own.settings["groups"]] == ["model-free", "base"]


def test_a03_fig7_with_the_baseline_labelled_incremental_is_refused(cli: CliRun, tmp_path: Path) -> None:
    groups = '[{agent="model-free",mdps="test",n_mdps=1},{agent="baseline",label="incremental",mdps="test",n_mdps=1}]'
    rc, _, err = cli("reproduce", "fig7", "--store", str(tmp_path / "s.sqlite"), "--set", "policies=shipped", "--set", f"groups={groups}", "--no-progress")
    assert rc == 2 and "it is the name of the agent 'incremental'" in error(err, "reproduce"), err
    assert not (tmp_path / "s.sqlite").exists()


# ------------------------------------------------------------------------------------------------ T28-A06


@pytest.mark.parametrize("text", ["episodes=3\nseed=5", "episodes=3\n[settings]\nseed = 5", "episodes=3\r", "episodes=\t3", "seed\x00=1"])
def test_a06_a_key_value_with_a_control_character_is_refused(text: str) -> None:
    for option in ("--set", "--agent-setting", "--setting"):
        with pytest.raises(NeurohoverError, match=rf"^{option} .* is not allowed: it holds the control character .*; give one KEY=VALUE on one line$"):
            parse_override(text, option)
    assert parse_override("episodes=3") == ("episodes", 3) and parse_override('title="a b"') == ("title", "a b")


def test_a06_the_commands_refuse_it_before_running(tmp_path: Path, cli: CliRun) -> None:
    config = _config(tmp_path, BASE)
    rc, _, err = cli("reproduce", str(config), "--store", str(tmp_path / "s.sqlite"), "--set", "episodes=3\nseed=5", "--no-progress")
    assert rc == 2 and "--set 'episodes=3\\nseed=5' is not allowed: it holds the control character \\n" in error(err, "reproduce"), err
    assert not (tmp_path / "s.sqlite").exists()
    argv = ("compete", "--task", "ghh08", "--agent", "continual", "--episodes", "2", "--episode-steps", "20", "--runs", "1")
    rc, _, err = cli(*argv, "--out", str(tmp_path / "c"), "--agent-setting", "cooldown=10\ncooldown=999")
    assert rc == 2 and "--agent-setting 'cooldown=10\\ncooldown=999' is not allowed" in error(err, "compete"), err
    rc, _, err = cli("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "20", "--out", str(tmp_path / "p.json"), "--setting", "a=1\nb=2")
    assert rc == 2 and "--setting 'a=1\\nb=2' is not allowed" in error(err, "evolve"), err
    assert not (tmp_path / "p.json").exists()


# ------------------------------------------------------------------------------------------------ T28-A07


@pytest.mark.parametrize(
    ("line", "needle"),
    [
        ('title = "a\\n# injected heading\\n"', "title = 'a\\n# injected heading\\n' is not allowed: it holds the control character \\n"),
        ('paper_ref = "Fig. 7\\n## injected"', "paper_ref = 'Fig. 7\\n## injected' is not allowed: it holds the control character \\n"),
        ('title = "a\\u2028b"', "title = 'a\\u2028b' is not allowed: it holds the control character \\u2028"),
        (f'title = "{"x" * 20000}"', "(20,000 characters) is not allowed: give at most 200 characters"),
        (f'paper_ref = "{"x" * 201}"', "give at most 200 characters"),
    ],
    ids=["title-newline", "paper-ref-newline", "title-line-separator", "title-20000", "paper-ref-201"],
)
def test_a07_one_line_texts_are_one_line_and_bounded(tmp_path: Path, line: str, needle: str) -> None:
    text = BASE.replace('title = "tiny"', "") + ""
    _refused(tmp_path, text.replace('kind = "test_runs"', f'kind = "test_runs"\n{line}'), needle)


def test_a07_paper_notes_claims_p_and_labels_are_one_line(tmp_path: Path) -> None:
    for paper, needle in (
        ('notes = ["a\\n## b"]', "[paper] notes entry = 'a\\n## b' is not allowed: it holds the control character \\n"),
        ('claims = ["a\\tb"]', "[paper] claims entry = 'a\\tb' is not allowed"),
        ('ttests = [{ a = "baseline", b = "model-free", p = "< 0.01\\n# x" }]', "[paper] ttests p = '< 0.01\\n# x' is not allowed"),
    ):
        _refused(tmp_path, BASE + f"[paper]\n{paper}\n", needle)
    settings = {"task": "ghh08", "seed": 1, "budget": 10, "runs": 1, "target": "train", "n_mdps": 1}
    variants = [{"key": "a", "label": "SLP\n# x", "topology": "slp"}]
    with pytest.raises(NeurohoverError, match=r"variant label = 'SLP\\n# x' is not allowed: it holds the control character \\n"):
        make_config("ev28", "evolution", "quick", {**settings, "variants": variants})
    ok = make_config("ev28", "evolution", "quick", {**settings, "variants": [{**variants[0], "label": "SLP, zero seed"}]}, title="t" * 200)
    assert ok.title == "t" * 200


# ------------------------------------------------------------------------------------------------ T28-A09


@pytest.mark.parametrize(
    ("paper", "key"),
    [("[paper.table.baseline]\nt = 1\nsd = 1\nr_m = 1\nr_a = 1\n", "table"), ("[paper.table3.baseline]\nr = -5\nsd = 1\n", "table3")],
)
def test_a09_paper_keys_the_kind_never_shows_are_refused(tmp_path: Path, paper: str, key: str) -> None:
    kind = "model_learning" if key == "table" else "evolution"
    _refused(
        tmp_path,
        BASE + paper,
        f"[paper] {key} is not allowed in a test_runs experiment: its report never shows it ({key} belongs to the {kind} report); "
        "allowed: notes, claims, ttests, groups",
    )
    load_config(str(_config(tmp_path, BASE + "[paper.groups.baseline]\ncrash_rate = 0\n", "ok.toml")), "quick")


# ------------------------------------------------------------------------------------------------ T28-A10


def test_a10_a_shipped_name_but_for_case_is_refused(tmp_path: Path, cli: CliRun) -> None:
    for name in ("FIG7", "Table3", "ALL", "Compete-ghh08-baseline"):
        config = _config(tmp_path, BASE.replace('name = "mini"', f'name = "{name}"'), f"{name}.toml")
        rc, _, err = cli("reproduce", str(config), "--store", str(tmp_path / "s.sqlite"), "--no-progress")
        assert rc == 2 and f"name = {name!r} is" in error(err, "reproduce"), err
    assert "the shipped name 'fig7' but for case" in error(cli("reproduce", str(tmp_path / "FIG7.toml"), "--store", str(tmp_path / "s.sqlite"))[2], "reproduce")
    assert not (tmp_path / "s.sqlite").exists()


def test_a10_a_store_refuses_a_name_differing_from_a_stored_one_only_in_case(tmp_path: Path) -> None:
    with Store(tmp_path / "s.sqlite") as store:
        begin(store, "mini")
        begin(store, "mini", "paper")  # the same experiment at another scale
        with pytest.raises(NeurohoverError, match=r"already holds experiment 'mini', and 'MINI' differs from it only in case"):
            begin(store, "MINI")
        assert [e[0] for e in store.experiments()] == ["mini", "mini"]


# ------------------------------------------------------------------------------------------------ T28-A11


def test_a11_a_star_stays_within_one_part_of_a_key() -> None:
    assert selected("run/base/test0/rep0", ["run/base/*/rep0"]) and not selected("run/base/mf/test0/rep0", ["run/base/*/rep0"])
    assert not selected("run/base/mf/test0/rep0", ["run/base/*"]) and selected("run/base/mf/test0/rep0", ["run/base/**"])
    assert key_matches("evolve/k5/run3", "evolve/k5/*") and key_matches("evolve/k1/run3", "**/run3")
    assert key_matches("run/a/test0/rep0", "run/[!m]*/test?/rep0") and not key_matches("run/a/b", "run/a[!x]b")
    assert key_matches("run/[a", "run/[a") and not key_matches("run/a/b", "run/a?b") and not key_matches("run/a/b", "run/a[/]b")


def test_a11_only_runs_the_group_it_names(tmp_path: Path, cli: CliRun) -> None:
    text = BASE.replace('agent = "baseline"\n', 'agent = "baseline"\nlabel = "base"\n').replace(
        'agent = "model-free"\n', 'agent = "model-free"\nlabel = "base/mf"\n'
    )
    config = _config(tmp_path, text)
    rc, out, err = cli("reproduce", str(config), "--store", str(tmp_path / "s.sqlite"), "--only", "run/base/*/rep0", "--no-progress")
    assert rc == 0 and "ran 1 unit, 0 already in the store, 1/2 done" in out, (out, err)
    rc, _, err = cli("reproduce", str(config), "--store", str(tmp_path / "s.sqlite"), "--only", "run/*", "--no-progress")
    assert rc == 2 and "matches no unit ('*' matches within one part of a key, not across '/': give '**' to cross parts)" in err, err
