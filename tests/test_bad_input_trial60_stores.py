"""Bad-input trial 60, side B (stores of run-time agents): a compete store of an agent registered at run time, read by a
process without it registered (every ``neurohover results`` and ``report``), skipped the plan check: ``_replannable``
took the agent's "unknown agent" for a policy directory gone, so a unit's seed edited to 12345, or its key changed to a
run the config never plans, was exported and reported, exit 0, where a shipped agent's store refuses both (T60-B04);
and the report of such a store, complete, said "INCOMPLETE (1 of None units)" (T60-B05). The agent's plan is now made
from what the store records (its runs' policies); where the plan needs what the store cannot show, the refusal names
the agent and says to register it."""

from __future__ import annotations

import re
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover.agents import registry as R
from neurohover.agents.protocol import Agent, Choice
from neurohover.agents.spec import AgentSpec
from neurohover.compete import compete
from neurohover.errors import NeurohoverError
from neurohover.experiments import LocalExecutor, Store, export_results, plan, reproduce, write_report
from neurohover.experiments.config import make_config

AGENT = "t60store1"
FGHH_AGENT = "t60store2"
EXPERIMENT = f"compete-ghh08-{AGENT}"


class Flies60(Agent):
    """Flies its generic policy every episode."""

    name = AGENT

    def __init__(self, generic) -> None:
        self.generic = generic

    def choose(self, episode):
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome) -> None:
        pass


def _spec(name: str, runs_on: str = "specialised", generic_kind: str | None = None) -> AgentSpec:
    return AgentSpec(name, runs_on, frozenset({"generic"}), lambda p, o: Flies60(p.generic), generic_kind=generic_kind)


def _competed(where: Path, task: str, spec: AgentSpec, policy_dir: str | None = None) -> Path:
    """A store of a compete run of ``spec``'s agent, registered only while it ran (as in the script that ran compete)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(R.AGENTS, spec.name, spec)
        compete(task, spec.name, runs=2, episodes=2, n_steps=20, out=where / "out", store=where / "s.sqlite", policy_dir=policy_dir)
    assert spec.name not in R.AGENTS
    return where / "s.sqlite"


@pytest.fixture(scope="module")
def store(tmp_path_factory) -> Path:
    return _competed(tmp_path_factory.mktemp("t60st"), "ghh08", _spec(AGENT))


def _edited(store: Path, tmp_path: Path, sql: str) -> Path:
    copy = tmp_path / "edited.sqlite"
    copy.write_bytes(store.read_bytes())
    with sqlite3.connect(copy) as conn:
        conn.execute(sql)
    return copy


SEED = "update units set params = json_set(params, '$.seed', 12345) where key = 'run/{a}/test1/rep0'"
KEY = "update units set key = 'run/{a}/test9/rep0' where key = 'run/{a}/test1/rep0'"
EDITS = {
    "seed": (SEED, r"unit 'run/t60store1/test1/rep0' holds other settings than its config plans for it \(unit\.params\.seed: the stored 12345, planned "),
    "key": (KEY, r"it holds unit 'run/t60store1/test9/rep0', which the config does not plan"),
    "policy": (
        "update units set params = json_set(params, '$.policies.generic.genome[0]', 0.5) where key = 'run/{a}/test1/rep0'",
        r"unit 'run/t60store\d/test1/rep0' holds other settings than its config plans for it "
        r"\(unit\.params\.policies\.generic\.genome\[0\]: the stored 0\.5, planned ",
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("edit", sorted(EDITS))
def test_an_edited_store_of_an_unregistered_agent_is_refused(store, tmp_path, capsys, edit) -> None:
    """T60-B04: exported as the run's (the seed 12345; the unplanned key as 'rep 9'), where a shipped agent's is refused."""
    sql, message = EDITS[edit]
    edited = _edited(store, tmp_path, sql.format(a=AGENT))
    with pytest.raises(NeurohoverError, match=f"is damaged: {message}"):
        export_results(Store(edited), EXPERIMENT)
    with pytest.raises(NeurohoverError, match="every experiment asked for is damaged"):
        write_report(Store(edited), tmp_path / "rep", refuse_all_damaged=True)
    assert re.search(f"{EXPERIMENT} .* is not reported: .*{message}", capsys.readouterr().err)


@pytest.mark.slow
@pytest.mark.parametrize("command", ["results", "report"])
def test_the_commands_refuse_an_edited_store_of_an_unregistered_agent(store, tmp_path, command) -> None:
    """T60-B04: `neurohover results` and `report` exited 0 on the edited seed."""
    edited = _edited(store, tmp_path, SEED.format(a=AGENT))
    args = [EXPERIMENT, "--store", str(edited)] if command == "results" else ["--store", str(edited), "--out", str(tmp_path / "rep")]
    done = subprocess.run([sys.executable, "-m", "neurohover", command, *args], capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert "(unit.params.seed: the stored 12345, planned " in done.stderr


@pytest.mark.slow
def test_the_report_of_an_unregistered_agents_store_says_it_is_complete(store, tmp_path) -> None:
    """T60-B05: "- Units: 2 finished, INCOMPLETE (2 of None units)"; with the agent registered, "complete"."""
    write_report(Store(store), tmp_path / "rep")
    text = (tmp_path / "rep" / "report.md").read_text(encoding="utf-8")
    assert "- Units: 2 finished, complete\n" in text
    assert "None units" not in text
    assert '"seed": 12345' not in export_results(Store(store), EXPERIMENT, "json")  # the unedited store is read as before


@pytest.mark.slow
def test_a_store_of_an_unregistered_fghh_agent_is_checked_by_its_generics_kind(tmp_path) -> None:
    """T60-B04 on a family of generics by kind: the kind the agent flies is the one whose plan gives its runs' generic."""
    stored = _competed(tmp_path, "fghh", _spec(FGHH_AGENT, "generics-by-kind", "race"))
    write_report(Store(stored), tmp_path / "rep")
    assert "- Units: 2 finished, complete\n" in (tmp_path / "rep" / "report.md").read_text(encoding="utf-8")
    edited = _edited(stored, tmp_path, EDITS["policy"][0].format(a=FGHH_AGENT))
    with pytest.raises(NeurohoverError, match=EDITS["policy"][1]):
        export_results(Store(edited), f"compete-fghh-{FGHH_AGENT}")


@pytest.mark.slow
def test_a_store_whose_policy_directory_is_gone_is_still_read_by_key(tmp_path) -> None:
    """What _replannable was written for (T21-02) stays: a policy directory removed leaves the runs checked by key, kind
    and result alone, and the report says why it cannot count the units rather than "of None units" (T60-B05)."""
    shutil.copytree(Path(R.__file__).resolve().parents[1] / "data" / "policies" / "ghh08", tmp_path / "pd" / "ghh08")
    stored = _competed(tmp_path, "ghh08", _spec(AGENT), policy_dir=str(tmp_path / "pd"))
    shutil.rmtree(tmp_path / "pd")
    assert "run/t60store1/test1/rep0" in export_results(Store(stored), EXPERIMENT)
    write_report(Store(stored), tmp_path / "rep")
    text = (tmp_path / "rep" / "report.md").read_text(encoding="utf-8")
    assert "- Units: 2 finished, of a total this process cannot count: it cannot plan the experiment again (policies = " in text
    assert "None units" not in text


def _evolving_config(agent: str):
    """A test-runs config that evolves its own policies, a baseline group beside ``agent``'s."""
    settings = {"task": "ghh08", "seed": 1, "policies": "evolve", "policy_budget": 20, "episodes": 2, "n_steps": 20}
    settings["groups"] = [{"agent": "baseline", "n_mdps": 1}, {"agent": agent, "n_mdps": 1}]
    return make_config("t60evolving", "test_runs", "quick", settings)


@pytest.mark.slow
def test_a_plan_that_needs_what_an_unregistered_agent_flies_names_it(tmp_path) -> None:
    """Where the store holds no run of the agent, and the policy units its config evolves depend on what it flies, the
    refusal names the agent and says to register it (not a check skipped, nor "of None units")."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(R.AGENTS, AGENT, _spec(AGENT))
        config = _evolving_config(AGENT)
        store = Store(tmp_path / "s.sqlite")
        reproduce(config, store, LocalExecutor(1), only="run/baseline/**")
    message = rf"agent '{AGENT}' is not registered in this process, and the store holds no run of it .* registers the agent first"
    with pytest.raises(NeurohoverError, match=rf"^results store .*, experiment t60evolving \(quick\): {message}"):
        export_results(Store(tmp_path / "s.sqlite"), "t60evolving")
    from neurohover.experiments.stored_agents import StoredAgent  # new with the fix (the check above fails without it)

    with pytest.raises(NeurohoverError, match=message):
        plan(config, {}, None, {AGENT: StoredAgent(AGENT, shown=False)})
