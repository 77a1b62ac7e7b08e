"""The competition harness: R independent test runs of an agent, summary, files and plots.

A competition is a small inline experiment (kind ``test_runs``, one group): it runs through the
same planner, units, executor, unit seeds and results store as ``neurohover reproduce``, so a
run of ``compete`` and the same group in an experiment config fly the same MDPs, and an
interrupted competition resumes where it stopped. ``neurohover compete`` writes to its output
directory:

- ``results.sqlite``: the results store (or the one given with ``--store``); running the same
  command again skips the finished runs;
- ``episodes.csv``: one row per (run, episode): run, mdp, episode, return, crashed, steps, policy,
  safeguard_fired (steps is the crash step, or the episode length);
- ``summary.json``: the summary table below plus the settings;
- ``cumulative.png``: mean cumulative error (minus cumulative return) per episode, on a linear
  and a log scale, like the paper's Figures 4 and 7.

Summary per agent: mean and sd of the cumulative return over runs, crash rate (share of runs
with at least one crash, and crashes per episode), and the mean return per episode after
learning (from the first episode after which the agent's policy no longer changes).

Seeds: every unit's seed is ``unit_seed(seed, experiment name, unit key)``
(:func:`neurohover.experiments.units.unit_seed`); a competition's experiment is named
``compete-<task>-<agent>``, and MDPs sampled from G come from ``SeedSequence([seed, tag, i])``
exactly as in the experiments.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from .agents.hybrid import HybridSettings
from .compete_folder import note_replaced, refuse_other_files, sole_competition, write_episodes, write_partial, write_summary
from .errors import NeurohoverError, brief, check_arity, first_difference, whole_in
from .evolution.seeding import check_seed
from .plots import plot_cumulative
from .sim.constants import EPISODE_STEPS, MAX_EPISODE_STEPS
from .tasks import N_TEST, N_TRAINING, Drift, Sensor, get_task_family
from .tasks.drift import MAX_RUN_EPISODES  # a run's episodes, the bound of a drifting MDP's episodes too

#: The entry points, which check what they are given (summarise: compete's helper over its own store's results, unchecked; T43-B15).
__all__ = [
    "FINISHED_RUNS", "LR_FIT_KEYS", "MAX_RUNS", "STORE_FILE", "agents_with_settings", "check_against_store", "check_agent_settings", "check_sizes",
    "compete", "competition_config",
]  # fmt: skip

STORE_FILE = "results.sqlite"
#: The attribute an interrupted :func:`compete`'s KeyboardInterrupt carries once its runs began: how many had finished.
FINISHED_RUNS = "finished_runs"


#: The LR-fit settings a competition takes (``lr_fit``): the experiment groups' keys of the same names.
LR_FIT_KEYS = ("d_u", "noise", "model_policy", "model_substeps")


def summarise(results: Sequence) -> dict:
    """Summary figures over test runs (:class:`~neurohover.experiments.results.TestRunResult`; see the module docstring)."""
    if not len(results):  # a mean of nothing was numpy's "Mean of empty slice" and NaN figures (T30-A02)
        raise NeurohoverError("summarise needs at least one test run: results holds none")
    scores = np.array([float(r.score) for r in results])
    returns = [np.array(r.returns, dtype=float) for r in results]
    after = [ret[r.learning_episodes :] for r, ret in zip(results, returns, strict=True)]
    crashes = np.array([len(r.crash_episodes) for r in results])
    return {
        "runs": len(results),
        "episodes": int(returns[0].size) if results else 0,
        "mean_cumulative_return": float(scores.mean()),
        "sd_cumulative_return": float(scores.std(ddof=1)) if len(results) > 1 else 0.0,
        "crash_rate_runs": float(np.mean(crashes > 0)),
        "crashes_per_episode": float(crashes.sum() / sum(ret.size for ret in returns)),
        "mean_return_after_learning": float(np.mean(np.concatenate(after))),
        "mean_seconds_per_run": float(np.mean([r.timing.seconds for r in results])),
        "mean_offline_seconds_per_run": float(np.mean([r.timing.offline_seconds for r in results])),
    }


#: The largest competition (planned in memory, each episode's results stored): its runs (MAX_RUN_EPISODES: its episodes over all runs).
MAX_RUNS = 100_000


def check_sizes(runs: int, episodes: int) -> None:
    """Refuse a competition too large to plan in memory and store (every episode's results are kept)."""
    # T24-11: 1.5 or True "is not allowed" (a type), 0 "is out of range" (both said out of range); the upper bounds
    # stay the check below, which names both counts (whole_in would name one)
    for name, value, high in (("runs", runs, MAX_RUNS), ("episodes", episodes, MAX_RUN_EPISODES)):
        if type(value) is not int:  # a Python int, as before: the competition's config is stored as JSON
            raise NeurohoverError(f"{name}={brief(value)} is not allowed: allowed an integer in 1..{high:,}")
        if value < 1:
            raise NeurohoverError(f"{name}={value} is out of range: allowed an integer in 1..{high:,}")
    if runs > MAX_RUNS or runs * episodes > MAX_RUN_EPISODES:
        raise NeurohoverError(
            f"runs={runs} x episodes={episodes} is out of range: at most {MAX_RUNS:,} runs and {MAX_RUN_EPISODES:,} episodes in all "
            "(each episode's results are kept in the store); split the competition or use fewer runs"
        )


def _group(task: str, runs: int, mdps: str) -> dict:
    """The experiment group of ``runs`` runs on the MDP set ``mdps``, the set's MDPs in turn."""
    size = {"test": N_TEST, "train": N_TRAINING}.get(mdps)
    if mdps not in ("test", "train", "sample"):
        raise NeurohoverError(f"unknown --mdps {mdps!r}: allowed test, sample, train")
    if size is None or runs <= size:
        return {"mdps": mdps, "n_mdps": runs, "runs_per_mdp": 1}
    if runs % size:
        raise NeurohoverError(
            f"runs={runs} on the {size} {mdps} MDPs of {task}: give at most {size} runs, or a multiple of {size} (each MDP then gets the same number of runs)"
        )
    return {"mdps": mdps, "n_mdps": size, "runs_per_mdp": runs // size}


#: The UNIT_KEYs of agents' settings classes that are settings of the whole experiment, not a group's own table (the
#: incremental agents' max_learning_episodes): compete's one group takes them as such.
_EXPERIMENT_WIDE = ("max_learning_episodes",)


def check_agent_settings(agent: str, values: Mapping[str, object], n_steps: int | None = None) -> dict:
    """``values`` as the agent's own settings table, checked by its spec's settings class (one clear message): every
    agent that ``neurohover settings`` lists settings for takes them here, but the hybrid agents, whose settings are
    the ``hybrid`` argument (the --safeguard-*/--hybrid-* options). ``n_steps``: the episode length they must act in."""
    from .agents.registry import agent_spec
    from .agents.spec import unused_reason

    spec = agent_spec(agent)
    if not isinstance(values, Mapping):  # None was dict()'s TypeError (T43-B15)
        raise NeurohoverError(f"agent_settings={brief(values)} is not allowed: give a dict of the agent's own settings (`neurohover settings {agent}`)")
    if spec.settings is None or spec.settings.UNIT_KEY not in ("agent_settings", *_EXPERIMENT_WIDE):
        # incremental's max_learning_episodes was refused here while `neurohover settings incremental` listed it (eleventh trial, U2)
        hybrid = " (its settings, `neurohover settings hybrid`, are the --safeguard-*/--hybrid-* options, hybrid= in Python)" if spec.settings else ""
        raise NeurohoverError(f"agent {agent!r} takes no settings table of its own{hybrid}; agents that do: {', '.join(agents_with_settings())}")
    checked = spec.settings.from_dict(dict(values))
    why = unused_reason(spec.settings, agent, dict(values))  # its answer checked (T60-B06)
    if why is not None:
        raise NeurohoverError(f"agent {agent!r}: {why}")
    if n_steps is not None:  # before any run: continual's safeguard_after past the episode would never test (twelfth trial, S3)
        # as every n_steps is checked: 'zz' was a TypeError, NaN and True were taken, -1 blamed the setting (T47-B02)
        checked.check_episode_steps(whole_in(n_steps, "n_steps", 1, MAX_EPISODE_STEPS))
    return checked.to_dict()


def agents_with_settings() -> list[str]:
    """The registered agents that take --agent-setting (agent_settings=): those with settings of their own but the hybrid agents."""
    from .agents.registry import usable_agents

    return sorted(n for n, s in usable_agents().items() if s.settings is not None and s.settings.UNIT_KEY in ("agent_settings", *_EXPERIMENT_WIDE))


def competition_config(
    task: str,
    agent: str,
    *,
    runs: int,
    episodes: int,
    mdps: str = "test",
    seed: int = 0,
    sigma: float | None = None,
    n_steps: int = EPISODE_STEPS,
    policy_dir: str | None = None,
    hybrid: HybridSettings | Mapping[str, object] = HybridSettings(),
    sensor: Sensor | None = None,
    drift: Drift | None = None,
    wind_model: str = "none",
    lr_fit: Mapping[str, object] | None = None,
    agent_settings: Mapping[str, object] | None = None,
):
    """The inline experiment of a competition (an ``ExperimentConfig`` of kind ``test_runs``).

    Its scale is a digest of the settings, so competitions with other settings in the same store
    are kept apart and the same settings resume.
    """
    from .agents.registry import HYBRID_AGENTS, agent_spec
    from .experiments.canonical import typed_numbers
    from .experiments.config import compete_name, make_config, settings_scale

    spec_settings = agent_spec(agent).settings  # an unknown agent, or a bad registry entry, named first (T44-B14)
    check_sizes(runs, episodes)
    check_seed(seed)  # the range every command takes
    group: dict[str, object] = {"agent": agent, **_group(task, runs, mdps)}
    if isinstance(hybrid, Mapping):  # the plain settings a config's hybrid table holds
        hybrid = HybridSettings.from_dict(dict(hybrid))
    if not isinstance(hybrid, HybridSettings):  # 'x' was an AttributeError (second trial)
        allowed = ", ".join(HybridSettings().to_dict())
        raise NeurohoverError(f"hybrid={hybrid!r:.60} is not allowed: give a HybridSettings or a dict of its settings ({allowed})")
    if agent in HYBRID_AGENTS:
        group["hybrid"] = typed_numbers(HybridSettings().to_dict(), hybrid.to_dict())  # box = 1 as 1.0 (T29-A07)
    elif hybrid != HybridSettings():  # would be ignored without a word
        raise NeurohoverError(f"hybrid settings apply to the hybrid agents only ({', '.join(HYBRID_AGENTS)}), not to agent {agent!r}")
    if wind_model != "none":  # the wind of the LR models the agent learns (absent: the digest of older competitions)
        group["wind_model"] = wind_model
    if lr_fit is not None and not isinstance(lr_fit, Mapping):  # 'noise=rms' was an AttributeError (T49-B04)
        raise NeurohoverError(f"lr_fit={brief(lr_fit)} is not allowed: give a dict of LR fit choices (keys {', '.join(LR_FIT_KEYS)}), or None")
    for key, choice in (lr_fit or {}).items():  # LR as the authors fitted it (absent: ours, the digest of older competitions)
        if key not in LR_FIT_KEYS:
            raise NeurohoverError(f"lr_fit key {key!r} is not allowed: choose from {', '.join(LR_FIT_KEYS)}")
        group[key] = choice
    wide: dict[str, object] = {}  # the incremental agents' max_learning_episodes: a setting of the whole experiment
    own: dict = {}
    if agent_settings is not None and (agent_settings or not isinstance(agent_settings, Mapping)):  # the agent's own settings, checked by its class
        own = check_agent_settings(agent, agent_settings, n_steps)
        defaults = spec_settings().to_dict()  # type: ignore[misc]  # an agent that takes settings has a class
        own = typed_numbers(defaults, own)  # level=1 as 1.0 ...
        own = {} if own == defaults else own  # ... and the defaults given as left out: one competition, not three (T29-A07)
    if spec_settings is not None and spec_settings.UNIT_KEY == "agent_settings":  # the defaults too: trials 2 in 3 episodes
        spec_settings.from_dict(dict(own)).check_episodes(agent, episodes)  # before any run (T32-A07), as --drift's change_at
    if own:
        if getattr(spec_settings, "UNIT_KEY", None) in _EXPERIMENT_WIDE:  # by the class, not by its keys: continual has one of the same name
            wide = own
        else:
            group["settings"] = own
    settings: dict[str, object] = {
        "task": task,
        "sigma": sigma,
        "seed": seed,
        "n_steps": n_steps,
        "episodes": episodes,
        "policies": policy_dir if policy_dir is not None else "shipped",
        "groups": [group],
        **wide,
    }
    get_task_family(task, sigma, sensor, drift)  # the family's own checks of the sensor and drift ('x' was an AttributeError)
    if sensor is not None and not sensor.exact:
        settings["sensor"] = sensor.to_dict()
    if drift is not None and not drift.none:
        settings["drift"] = drift.to_dict()
    return make_config(compete_name(task, agent), "test_runs", settings_scale(settings), settings, title=f"compete: {agent} on {task}")


def compete(
    task: str,
    agent: str,
    *,
    runs: int = 10,
    episodes: int = 1000,
    mdps: str = "test",
    seed: int = 0,
    jobs: int = 1,
    out: str | Path,
    sigma: float | None = None,
    n_steps: int = EPISODE_STEPS,
    policy_dir: str | None = None,
    hybrid: HybridSettings | Mapping[str, object] = HybridSettings(),
    store: str | Path | None = None,
    progress: bool | None = False,
    on_result: Callable[[str, object], None] | None = None,
    device: str = "cpu",
    sensor: Sensor | None = None,
    drift: Drift | None = None,
    wind_model: str = "none",
    lr_fit: Mapping[str, object] | None = None,
    agent_settings: Mapping[str, object] | None = None,
) -> tuple[dict, list]:
    """Run ``runs`` test runs of ``agent`` as an inline experiment; write results and plot to ``out``.

    Parameters
    ----------
    task, agent : str
        The task family and the agent (:data:`neurohover.agents.registry.AGENTS`).
    runs, episodes : int
        Test runs, and episodes per run.
    mdps : {"test", "train", "sample"}
        The fixed test or training MDPs in turn, or fresh MDPs from G.
    jobs : int
        Local worker processes.
    store : path, optional
        Results store (default ``out/results.sqlite``; not a file compete writes in ``out``); finished runs in it are not flown again.
    hybrid : HybridSettings or mapping
        The hybrid agents' safeguard and replacement rule (or a dict of its ``to_dict`` keys); refused for other agents.
    on_result : callable, optional
        ``on_result(unit key, TestRunResult)`` after each run finished in this call.
    device : {"cpu", "cuda"}
        Passed to the executor (:func:`neurohover.experiments.units.run_unit`); not part of the
        config. The test-run units fly on the CPU whatever it says (docs/gpu.md).
    sensor, drift : Sensor, Drift, optional
        The harder task (docs/benchmarks.md): every MDP seen through ``sensor``, its dynamics drifting by ``drift``.
    wind_model : {"none", "constant", "sinusoid"}
        The wind of the LR models a model-based agent learns (docs/model.md, Wind-aware models).
    lr_fit : mapping, optional
        How a model-based agent fits LR and evolves on it, where it differs from ours: ``d_u``
        (``"keep"``/``"discard"``), ``noise`` (``"innovations"``/``"rms"``), ``model_policy``
        (``"ours"``/``"authors"``), ``model_substeps`` (10/1; absent: the task's default,
        :func:`~neurohover.models.model.default_model_substeps`) (:class:`~neurohover.agents.model_based.ModelEvolution`); checked
        with the config (a bad value is refused with the allowed ones).
    agent_settings : mapping, optional
        The agent's own settings (its spec's settings class, e.g. ``{"criterion": "lcb", "level": 3}``
        for ``hybrid-risk``, ``{"cooldown": 10}`` for ``continual``, ``{"max_learning_episodes": 10}`` for the incremental
        agents, as ``neurohover settings AGENT`` lists them); refused for an agent without one and for the hybrid agents
        (their settings are ``hybrid``).

    Returns
    -------
    (dict, list of TestRunResult)
        The summary and the runs in order.

    Raises
    ------
    KeyboardInterrupt
        When interrupted (SIGTERM too while ``jobs > 1``), after writing ``episodes.csv`` of every
        finished run, an earlier competition's summary.json and cumulative.png in ``out`` removed (none finished: no file is
        written or removed); the store keeps them, and the same call resumes. Once the runs
        began, the exception's attribute ``finished_runs`` (:data:`FINISHED_RUNS`) says how many had finished.
    """
    from .agents.registry import agent_spec, check_agent
    from .paths import output_dir

    _check_run(jobs, device, on_result, progress)  # every check before the output directory is made (third trial)
    agent_spec(agent)  # an unknown agent named before the task is looked at
    check_agent(agent, get_task_family(task, sigma), policy_dir, agent_settings or None)  # its build, with its settings (T55-B07)
    config = competition_config(
        task, agent, runs=runs, episodes=episodes, mdps=mdps, seed=seed, sigma=sigma, n_steps=n_steps, policy_dir=policy_dir, hybrid=hybrid,
        sensor=sensor, drift=drift, wind_model=wind_model, lr_fit=lr_fit, agent_settings=agent_settings,
    )  # fmt: skip
    store_path = _checked_store(store)
    out = output_dir(out, "out")  # made once every setting is checked (None was a TypeError, /dev/full a FileExistsError)
    with sole_competition(out):
        store_path = store_path or out / STORE_FILE
        refuse_other_files(out, store_path)
        _refuse_other_settings(config, store_path)
        note_replaced(out / "summary.json", task, agent, config.scale)
        ordered = _run_into_store(config, store_path, out / "episodes.csv", jobs=jobs, device=device, progress=progress, on_result=on_result)
        flown = get_task_family(task, sigma).set_name(mdps)  # the set its rows' MDPs name: seeded-test at FGHH sigma 0.2 (T37-A02)
        summary = {"task": task, "agent": agent, "mdps": flown, "seed": seed, "store": str(store_path.absolute()),  # where plot --compete checks it
                   **_flown_under(n_steps, sigma, sensor, drift)}  # fmt: skip
        summary |= {"experiment": config.name, "scale": config.scale, **summarise(ordered)}
        write_summary(out / "summary.json", summary)
        curves = np.array([np.cumsum(np.array(r.returns, dtype=float)) for r in ordered])
        plot_cumulative({agent: curves}, out / "cumulative.png", f"{task}: {agent}, {len(ordered)} runs")
    return summary, ordered


def _flown_under(n_steps: int, sigma: float | None, sensor: Sensor | None, drift: Drift | None) -> dict:
    """What the episodes were flown under, kept in summary.json so that ``plot --compete`` names where overlaid runs
    differ (50-step drifting episodes were overlaid on 6000-step ones without a word; eleventh trial, S4)."""
    return {
        "episode_steps": n_steps,
        "sigma": sigma,
        "sensor": None if sensor is None else sensor.to_dict(),
        "drift": None if drift is None else drift.to_dict(),
    }


def _checked_store(store) -> Path | None:
    """The store's path, refused before the output directory is made: a bad path, a file that is no store (third trial),
    or a clock whose times its readers refuse (T50-A03)."""
    from .experiments.store_checks import new_store
    from .experiments.store_clock import clock_time
    from .filekinds import refuse_long_store_name
    from .paths import output_file

    clock_time(f"results store {str(store)!r}" if store is not None else "compete's results store")
    if store is None:
        return None
    refuse_long_store_name(store, "store")  # its -journal too (T31-A03)
    path = output_file(store, "store", store=True)
    if not new_store(path):  # an empty file becomes the store, as reproduce's does (T49-A02)
        from .experiments import Store

        with Store(path, create=False) as db:
            db.check_sound()  # a file SQLite calls malformed: refused before the output directory is made (T27-A09)
    return path


def _check_run(jobs, device, on_result, progress) -> None:
    """:func:`compete`'s run settings, refused by name (a bad on_result was a TypeError after the first run)."""
    from .evaluate import check_device
    from .experiments.executors import check_jobs

    check_jobs(jobs)
    check_device(device)
    if on_result is not None and not callable(on_result):
        raise NeurohoverError(f"on_result={on_result!r:.60} is not allowed: give a callable (unit key, TestRunResult), or None")
    # one of the wrong arity was a TypeError after the first unit was stored (T40-B02)
    check_arity("on_result", on_result, 2, "it is called as on_result(unit key, TestRunResult)", "a callable of those two arguments, or None")
    if progress not in (None, True, False):
        raise NeurohoverError(f"progress={progress!r:.60} is not allowed: give True, False or None (a bar only on a terminal)")


def _run_into_store(config, store_path: Path, episodes_csv: Path, *, jobs: int, device: str, progress: bool | None, on_result) -> list:
    """Run the competition's units into the store (finished ones are reused); its runs in order, written to
    ``episodes_csv`` also when interrupted."""
    from .experiments import Store, make_executor, reproduce
    from .experiments.results import TestRunResult

    def finished(key: str, result: dict) -> None:
        if on_result is not None and key.startswith("run/"):
            on_result(key, TestRunResult.from_dict(result, key))

    def stored_runs(db) -> list:
        stored = db.results(config.name, config.scale, missing_ok=True)  # interrupted before its first unit
        return [TestRunResult.from_dict(stored[k], k) for k in sorted((k for k in stored if k.startswith("run/")), key=_run_order)]

    _note_other_runs(config, store_path)  # before flying (T56-A02)
    executor = make_executor("local", jobs=jobs, device=device)
    with Store(store_path) as db:
        try:
            run = reproduce(config, db, executor, progress=progress, on_unit=finished)
            if run.units_before:  # say so, as reproduce does: these runs were not flown again
                reused = f"{run.units_before} of {run.units_total} units (runs and the policies they fly)"
                print(f"neurohover compete: {reused} were already in {store_path}: reused", file=sys.stderr)
        except KeyboardInterrupt as stop:  # the finished runs written, for the user to see (the same call resumes them)
            executor.close()
            ordered = stored_runs(db)
            if ordered:  # none: the folder stays as it was (an earlier competition's rows were replaced by a header; tenth trial)
                write_partial(episodes_csv, ordered, config.typed.n_steps)
            setattr(stop, FINISHED_RUNS, len(ordered))  # for the command's line: none finished is said so (T26-A08)
            raise
        finally:
            executor.close()
        ordered = stored_runs(db)  # a failure (a full disk) left above: the folder as it was
        if run.failed:  # said as reproduce says it, never summarised (all runs failed: "Mean of empty slice"; T30-A02)
            if ordered:
                write_partial(episodes_csv, ordered, config.typed.n_steps)
            raise NeurohoverError(f"{run.line()}; the finished runs are kept in {str(store_path)!r}, and the same call resumes")
        write_episodes(episodes_csv, ordered, config.typed.n_steps)
    return ordered


def _refuse_other_settings(config, store_path: Path) -> None:
    """A store holding this competition run with other settings (another policy set, say), refused before anything
    is written, saying what differs; reproduce's refusal named two hashes and --update / --fresh, which compete does not
    take (tenth trial)."""
    from .errors import first_difference
    from .experiments import Store
    from .experiments.store_checks import new_store

    if new_store(store_path):  # nothing there, or an empty file (reproduce's new store, just made: "in use" as it runs)
        return
    with Store(store_path, create=False) as db:
        held = db.config_hash(config.name, config.scale)
        if held is None or held == config.hash:
            return
        stored = db.config(config.name, config.scale)
    if config.same_but_unflown_digest(stored):  # reproduce re-labels its runs (T35-A02)
        return
    diff = first_difference("config", stored, config.to_dict())
    if diff.startswith("config.external_digest:"):  # the policy files' digest: said in words
        diff = "the policy set's files differ from those its runs flew, " + diff.removeprefix("config.external_digest: ").replace("the stored", "digest")
    raise NeurohoverError(
        f"results store {str(store_path)!r} holds this competition ({config.name}) run with other settings ({diff}): its runs would "
        "not be comparable; give another --store (or --out), or the settings it was run with (its runs stay in the store)"
    )


def _note_other_runs(config, store_path: Path) -> None:
    """Say on stderr, before flying, that the store holds this competition with another run count only: the count is
    part of the settings digest (its scale), so those runs are not reused, and --runs N flew them all again without a
    word (T56-A02; stores keep their scales, so the digest is not changed)."""
    from .experiments import Store
    from .experiments.store_checks import new_store

    def runs_apart(stored: dict) -> tuple[dict, int]:  # the config less its scale, hash and run count; the run count
        settings = dict(stored.get("settings") or {})
        groups = [dict(g) for g in settings.get("groups") or [] if isinstance(g, dict)]
        count = sum(int(g.pop("n_mdps", 0)) * int(g.pop("runs_per_mdp", 1)) for g in groups)
        rest = {k: v for k, v in stored.items() if k not in ("scale", "hash")}
        return rest | {"settings": settings | {"groups": groups}}, count

    if new_store(store_path):
        return
    mine, runs = runs_apart(config.to_dict())
    with Store(store_path, create=False) as db:
        if db.config_hash(config.name, config.scale) is not None:  # this competition's own runs are resumed
            return
        for _, scale, _, units in (e for e in db.experiments() if e[0] == config.name and e[1] != config.scale):
            try:
                other, count = runs_apart(db.config(config.name, scale))
            except (TypeError, ValueError):  # a config edited by hand (NeurohoverError too): not this competition's to note
                continue
            if other == mine and units:
                print(
                    f"neurohover compete: note: results store {str(store_path)!r} holds this competition with {count} runs ({scale}, "
                    f"{units} finished units): they are not reused, as the run count is part of a competition's settings digest; "
                    f"its {runs} runs are flown anew under {config.scale}. To reuse them, give --runs {count} (results and wins "
                    "then name a competition by --scale)",
                    file=sys.stderr,
                )
                return


def _run_order(key: str) -> tuple[int, int]:
    """Runs in the order of their MDP, then repetition (keys ``run/<agent>/<set><i>/rep<r>``)."""
    from .experiments.keys import UnitKey

    parsed = UnitKey.parse(key)
    index = parsed.mdp_index
    return (index if index is not None else -1, parsed.rep if parsed.rep is not None else 0)


def _holds_store(path: str | Path) -> bool:
    """Whether ``path`` (as given: 'x.sqlite/' names no file) is a file that starts as a neurohover results store does:
    SQLite's header, with neurohover's application id. A path that now holds an empty file, one of another kind, or
    another program's SQLite file (an archive restored elsewhere, the path reused) holds no store, as a path with
    nothing there; :func:`_store_of` reads neither (T46-A01)."""
    from .experiments.store import APPLICATION_ID
    from .filekinds import SQLITE_HEADER

    try:
        if not Path(path).is_file():  # a pipe, opened, would wait for a writer
            return False
        with open(path, "rb") as f:
            head = f.read(72)  # the application id is the big-endian integer at bytes 68 to 71 of SQLite's header
    except (OSError, ValueError):  # a directory, a path NUL in it, nothing there
        return False
    return head.startswith(SQLITE_HEADER) and len(head) == 72 and int.from_bytes(head[68:72], "big") == APPLICATION_ID


def _store_of(folder: Path, recorded: object, name: str, scale: str) -> str | None:
    """The store :func:`check_against_store` reads for compete folder ``folder``, whose summary records ``recorded`` and
    experiment (name, scale), or None: the folder's own :data:`STORE_FILE` (compete's default store, which travels with
    the folder) where it holds the experiment at that scale, else the recorded path where a store is there
    (:func:`_holds_store`), else the folder's own where the summary names a default store. A folder moved elsewhere was
    not checked at all, and once a new study ran at its old path it was checked against that study's store (T46-B05,
    T46-B06); an own file left by an earlier compete into the same folder, whose summary names its --store, is not this
    competition's store, and is not read (T47-A01)."""
    from .experiments import Store

    own = folder / STORE_FILE
    there = recorded if isinstance(recorded, str) and _holds_store(recorded) else None
    if not _holds_store(own):
        return there
    if there is None:  # the recorded store gone: the own file is this competition's only if the summary names a default store
        return str(own) if not isinstance(recorded, str) or Path(recorded).name == STORE_FILE else None
    with Store(own, create=False) as held:
        holds = (name, scale) in {(n, s) for n, s, _, _ in held.experiments()}
    return str(own) if holds else there


def check_against_store(folder: str | Path) -> None:
    """Refuse a compete folder whose ``summary.json`` names a flight condition (sigma, sensor, drift, episode steps, seed)
    that the config its store holds contradicts (a sensor edited into the summary labelled curves with a condition never
    flown, and nothing in the folder contradicts it; T38-B06). ``neurohover plot --compete`` calls it after
    :func:`~neurohover.compete_files.read_compete_dir` (whose layer reads no store). The store read is the folder's own
    results.sqlite, compete's default store, which moves with the folder (:func:`_store_of`); else the one the summary
    names by its absolute path (a relative one, which older versions wrote, from the working directory); a store no
    longer there, or holding no such experiment, is not read; one holding the experiment at other scales only refuses the summary's
    (T42-A02), and one holding the summary's scale under another experiment refuses its name: a settings-HASH digests
    the agent and task with the settings, so it names one competition (agent and experiment edited together; T45-B09)."""
    from .compete_files import COMPETE_SUMMARY, read_summary
    from .experiments import Store
    from .paths import input_dir, refuse_special_file

    folder = input_dir(folder, "--compete")  # None or 5 was os.fspath's TypeError (T49-B03)
    summary_path = folder / COMPETE_SUMMARY
    refuse_special_file(summary_path, "--compete", instead="give directories written by neurohover compete --out")
    if not summary_path.exists():  # an interrupted competition's: nothing to check
        return
    summary = read_summary(summary_path)  # as read_compete_dir reads it: a key given twice, [1, 2] leaked (T49-B03)
    name, scale = summary.get("experiment"), summary.get("scale")
    if not (isinstance(name, str) and isinstance(scale, str)):
        return
    store = _store_of(folder, summary.get("store"), name, scale)
    if store is None:
        return
    held = Store(store, create=False)
    try:
        experiments = held.experiments()
        scales = sorted({s for n, s, _, _ in experiments if n == name})
        others = sorted({n for n, s, _, _ in experiments if s == scale and n != name and s.startswith("settings-")})
        if scale not in scales:  # the experiment held at other scales only: a scale edited too (T42-A02)
            if scales:
                raise NeurohoverError(
                    f"--compete {str(summary_path)!r}: its scale {brief(scale)} is not one its store {store!r} holds for "
                    f"{name}: it holds {', '.join(scales)} (an edit by hand, or another store now at that path?)"
                )
            if others:  # T45-B09
                raise NeurohoverError(
                    f"--compete {str(summary_path)!r}: its experiment {brief(name)} is not the one its store {store!r} holds its scale "
                    f"{scale} under: {', '.join(others)} (a settings digest names one competition: an edit by hand of its agent and experiment?)"
                )
            return
        settings = held.config(name, scale).get("settings", {})
    finally:
        held.close()
    stored = {"sigma": settings.get("sigma"), "episode_steps": settings.get("n_steps"), "seed": settings.get("seed"),
              "sensor": Sensor.from_dict(settings.get("sensor") or {}).to_dict(), "drift": Drift.from_dict(settings.get("drift") or {}).to_dict()}  # fmt: skip
    given = {**{key: summary.get(key, stored[key]) for key in ("sigma", "episode_steps", "seed")},
             "sensor": Sensor.from_dict(summary.get("sensor") or {}).to_dict(), "drift": Drift.from_dict(summary.get("drift") or {}).to_dict()}  # fmt: skip
    if given != stored:  # the first differing key, a sensor's level (its dict cut at 60 characters read alike; T38-B06)
        differs = first_difference("", stored, given, "its store's").lstrip(".")
        raise NeurohoverError(
            f"--compete {str(summary_path)!r} is not what its store {store!r} holds for {name} ({scale}): {differs} "
            "(an edit by hand, or the store run again with other settings?)"
        )
