"""The fourteenth bad-input trial's findings in neurohover.experiments' store, plans, unit params and executors: a Store write
refuses a flag that is no bool, a name, scale, config, result, duration or count of the wrong kind before anything is
written (T14-4, T14-5); RayExecutor names a malformed address before Ray starts (T14-22); plan and unit_params name what
they take (T14-23). One NeurohoverError each, naming the value and what is allowed."""

from __future__ import annotations

from pathlib import Path

import pytest
from store_edits import begin, tiny_config

from neurohover.errors import NeurohoverError
from neurohover.experiments import RayExecutor, Store, Unit, plan, reproduce, run_unit
from neurohover.experiments.config import make_config
from neurohover.experiments.params import unit_params

NAN = float("nan")
UNIT = Unit("e", "k", "diagnostic", {"value": 1})
OK = {"value": 1, "seed": None}  # a diagnostic unit's result as run_unit gives it
H = tiny_config().hash  # what each store.begin below registers (T29-B07: a real config)
SETTINGS = dict(task="ghh08", seed=1, policies="shipped", episodes=2, n_steps=20, groups=[dict(agent="baseline", mdps="test", n_mdps=1)])


def _stored(path: Path) -> Store:
    """A store holding experiment e (quick) with one finished unit."""
    store = Store(path)
    begin(store, "e")
    assert store.put("e", "quick", H, UNIT, {"value": 1, "seed": None}, 0.5)
    return store


@pytest.mark.parametrize("fresh", ["no", 1, None, "False"])
def test_begin_refuses_a_fresh_flag_that_is_no_bool(tmp_path: Path, fresh) -> None:
    """T14-4: fresh='no' counted as True and deleted every stored unit of the experiment."""
    with _stored(tmp_path / "s.sqlite") as store:
        with pytest.raises(NeurohoverError, match=r"fresh=.* is not allowed: give True \(delete the experiment's stored units first\) or False"):
            begin(store, "e", fresh=fresh)
        assert store.results("e", "quick") == {"k": {"value": 1, "seed": None}}


@pytest.mark.parametrize(("flag", "message"), [("fresh", "fresh='no' is not allowed: give True"), ("update", "update='no' is not allowed: give True")])
def test_reproduce_refuses_fresh_or_update_flags_that_are_no_bools(tmp_path: Path, flag: str, message: str) -> None:
    """T14-4: reproduce passed fresh='no' on to the store (every unit deleted) and took update='no' as True."""

    class Idle:  # no unit may run
        name, cores = "idle", 1

        def run(self, units, on_result, on_error) -> None:
            raise AssertionError("no unit may run")

    with _stored(tmp_path / "s.sqlite") as store:
        with pytest.raises(NeurohoverError, match=message):
            reproduce(make_config("mc14", "test_runs", "quick", SETTINGS), store, Idle(), progress=False, **{flag: "no"})
        assert [e[0] for e in store.experiments()] == ["e"] and store.results("e", "quick") == {"k": {"value": 1, "seed": None}}


def test_store_refuses_a_create_flag_that_is_no_bool(tmp_path: Path) -> None:
    """T14-4 (the shared check): create='no' stays refused, by the same message as fresh."""
    with pytest.raises(NeurohoverError, match=r"create='no' is not allowed: give True \(make the store if missing\) or False"):
        Store(tmp_path / "s.sqlite", create="no")


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda s: s.begin("x", None, "h", {}), "begin: scale = None is not allowed: give one of quick, paper (or a compete run's settings-HASH)"),
        (lambda s: s.begin("x", "weird", "h", {}), "scale = 'weird' is not allowed: give one of quick, paper"),
        (lambda s: s.begin(5, "quick", "h", {}), "begin: name = 5 is not allowed: give 1-100 ASCII letters (A-Z, a-z), digits"),
        (lambda s: s.begin("", "quick", "h", {}), "name = '' is not allowed"),
        (lambda s: s.begin("a\x00b", "quick", "h", {}), "name = 'a\\x00b' is not allowed"),
        (lambda s: s.begin("x", "quick", None, {}), "begin: config_hash = None is not allowed: give non-empty text without NUL characters"),
        (lambda s: s.begin("x", "quick", "h", [1]), "begin: config = [1] is not allowed: give a dict (a JSON object)"),
        (lambda s: s.begin("x", "quick", "h", {"a": NAN}), "begin: config = {'a': nan} is not allowed: give a JSON object of text, finite numbers"),
        (lambda s: s.begin("x", "quick", "h", {"a": {1}}), "begin: config = {'a': {1}} is not allowed: give a JSON object"),
        (lambda s: s.begin("x", "quick", "h", {1: 1, "1": 2}), "is not allowed: give a JSON object"),  # two keys "1" once written
        (lambda s: s.update("e", "quick", "h2", {}, keep=None), "update: keep = None is not allowed: give a list or set of unit keys"),
        (lambda s: s.update("e", "quick", "h2", {}, keep="k"), "update: keep = 'k' is not allowed"),
        (lambda s: s.put("e", "quick", H, None, {}, 1.0), "put: unit = None is not allowed: give the Unit that finished"),
        (
            lambda s: s.put("e", "quick", H, Unit("e", "k2", "diagnostic", {}), OK, NAN),
            "put: seconds = nan is not allowed: give a finite number of seconds >= 0",
        ),
        (lambda s: s.put("e", "quick", H, Unit("e", "k2", "diagnostic", {}), OK, -1.0), "seconds = -1.0 is not allowed"),
        (lambda s: s.put("e", "quick", H, Unit("e", "k2", "diagnostic", {}), {"a": NAN}, 1.0), "put: unit k2's result = {'a': nan} is not allowed"),
        (lambda s: s.put("e", "quick", H, Unit("e", "k2", "diagnostic", {}), [1], 1.0), "put: unit k2's result = [1] is not allowed: give a dict"),
        (lambda s: s.put("e", "quick", H, Unit("e", "k2", "diagnostic", {}), OK, 1.0, worker=None), "put: worker = None is not allowed: give text"),
        (lambda s: s.start_session("e", "quick", H, "local", 0, 0), "start_session: cores = 0 is not allowed: give a whole number >= 1"),
        (lambda s: s.start_session("e", "quick", H, "local", "x", 0), "start_session: cores = 'x' is not allowed"),
        (lambda s: s.start_session("e", "quick", H, "local", 1, -1), "start_session: units_before = -1 is not allowed: give a whole number >= 0"),
        (lambda s: s.end_session(1, object()), "end_session: status = <object object"),
        (lambda s: s.end_session(None, "finished"), "end_session: session = None is not allowed: give a whole number >= 1"),
    ],
)
def test_store_writes_refuse_bad_arguments_before_writing(tmp_path: Path, call, message: str) -> None:
    """T14-5: IntegrityError, json's ValueError/TypeError, AttributeError, ProgrammingError; a list config stored (every later
    read called the store damaged), 5 stored as '5', '' and NUL taken, cores=0 stored (sessions() then damaged), and
    seconds=nan a unit silently dropped (a lost result). Each is one message now, and the store is as it was."""
    with _stored(tmp_path / "s.sqlite") as store:
        store.end_session(store.start_session("e", "quick", H, "local", 1, 0), "finished")
        before = (store.experiments(), store.units("e", "quick"), store.sessions("e", "quick"))
        with pytest.raises(NeurohoverError) as info:
            call(store)
        assert message in str(info.value)
        assert (store.experiments(), store.units("e", "quick"), store.sessions("e", "quick")) == before


def test_store_takes_a_compete_scale_and_the_units_it_always_took(tmp_path: Path) -> None:
    """T14-5: the checks leave a compete run's settings-HASH scale and a unit of no worker, in a session, as they were."""
    with Store(tmp_path / "s.sqlite") as store:
        begin(store, "mc", "settings-0123456789")
        session = store.start_session("mc", "settings-0123456789", H, "local", 2, 0)
        assert store.put("mc", "settings-0123456789", H, Unit("mc", "k", "diagnostic", {}), {"value": 1, "seed": None}, 0, session=session)
        store.end_session(session, "finished")
        assert store.sessions("mc", "settings-0123456789")[0]["units_run"] == 1


def test_ray_executor_names_an_address_that_is_no_text() -> None:
    """T14-22: RayExecutor(address=5) was an AttributeError ('int' object has no attribute 'startswith'); refused before
    Ray is imported or started."""
    with pytest.raises(NeurohoverError, match=r"--address 5 is not a Ray cluster address: allowed host:port"):
        RayExecutor(address=5)  # type: ignore[arg-type]


def test_plan_refuses_arguments_of_the_wrong_kinds() -> None:
    """T14-23: plan(cfg, None), plan(cfg, []) and plan(None, {}) were AttributeErrors."""
    cfg = make_config("mc14", "test_runs", "quick", SETTINGS)
    for results in (None, []):
        with pytest.raises(NeurohoverError, match=r"plan: results = .* is not allowed: give a dict of unit key -> result dict"):
            plan(cfg, results)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"plan: cfg = None is not allowed: give an experiment's config"):
        plan(None, {})  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"plan: sources = \[1\] is not allowed: give None or a dict of experiment name"):
        plan(cfg, {}, [1])  # type: ignore[arg-type]
    assert plan(cfg, {}, None).total == 1


def test_unit_params_name_the_missing_and_unknown_params() -> None:
    """T14-23: run_unit(Unit('fig7', 'k', 'evolve', {})) was "EvolveParams.__init__() missing 9 keyword-only arguments"."""
    with pytest.raises(NeurohoverError, match=r"'evolve' unit's params lack target, topology, prototype, .*seed, which EvolveParams needs"):
        run_unit(Unit("fig7", "k", "evolve", {}))
    with pytest.raises(NeurohoverError, match=r"params hold 'x', which SafetyParams does not declare and lack policies, mdps, episodes, n_steps, seed"):
        unit_params("safety", {"x": 1})
    with pytest.raises(NeurohoverError, match=r"'safety' unit's params = \[1\] are not allowed: give a dict of SafetyParams's fields"):
        unit_params("safety", [1])  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"unit kind 'diagnostic' is not allowed here: give one of evolve, robustness"):
        unit_params("diagnostic", {})
