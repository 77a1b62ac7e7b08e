"""The options several commands share, and how they become a task family, an MDP and a sensor (one place each)."""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields

import numpy as np

from ..envs.arguments import refuse_idle_sigma
from ..errors import FloatRangeError, NeurohoverError, float_of, int_of, whole_number
from ..tasks.sensor import Sensor


def parse_floats(text: str, what: str) -> list[float]:
    """Comma-separated numbers of option ``what``, or one clear error."""
    parts = text.split(",")
    if any(p.strip() == "" for p in parts):  # '1,,1' is no pair of numbers, nor is '1,1,'
        raise NeurohoverError(f"{what} must be comma-separated numbers with none left empty, got {text!r}")
    try:
        return [float_of(x) for x in parts]
    except ValueError as err:
        why = str(err) if isinstance(err, FloatRangeError) else f"got {text!r}"
        raise NeurohoverError(f"{what} must be comma-separated numbers, {why}") from None


def explicit_mdp(args: argparse.Namespace, family):
    """The MDP set by --wind or --params, with its description (``"wind=..."``), or None without them.

    Refuses both together, either with --mdp, and --wind for a family other than GHH-08
    (shared by ``fly`` and ``evolve``).
    """
    if args.wind is not None and args.params is not None:
        raise NeurohoverError("give either --wind (GHH-08) or --params, not both")
    if (args.wind is not None or args.params is not None) and args.mdp is not None:
        given = "--wind" if args.wind is not None else "--params"
        raise NeurohoverError(f"{given} sets the MDP explicitly; it cannot be combined with --mdp {args.mdp}")
    if args.wind is not None:
        if family.name != "ghh08":
            raise NeurohoverError(f"--wind U,V sets a GHH-08 MDP; task {args.task!r} takes --params")
        return family.make(parse_floats(args.wind, "--wind")), f"wind={args.wind}"
    if args.params is not None:
        if getattr(args, "sigma", None) is not None:  # it changed nothing (fourth trial)
            raise NeurohoverError("--sigma is the breadth of the MDPs drawn from FGHH's distribution; --params sets the MDP itself: give one")
        return family.make(parse_floats(args.params, "--params")), f"params={args.params}"
    return None


def refuse_sigma_on_zero(args: argparse.Namespace, mdp: str | None) -> None:
    """Refuse --sigma beside the zero setting ``mdp``, the same MDP at every breadth (it changed nothing; sixth trial):
    the environments' rule (:func:`~neurohover.envs.arguments.refuse_idle_sigma`), in the option's words."""
    refuse_idle_sigma(getattr(args, "sigma", None), mdp, flags=True, default=getattr(args, "mdp", None) != "zero")  # tenth trial: the default named


@dataclass(frozen=True)
class SettingOption:
    """A command-line option made from one field of a settings dataclass: ``--flag`` sets ``field``."""

    flag: str
    field: str

    @property
    def dest(self) -> str:
        return self.flag[2:].replace("-", "_")


def _converter(default):
    """The argparse ``type`` of a field from its default (a bool reads true/false, as TOML writes it)."""
    if isinstance(default, bool):

        def boolean(text: str) -> bool:
            if text not in ("true", "false"):
                raise argparse.ArgumentTypeError(f"invalid value {text!r}: give true or false")
            return text == "true"

        return boolean
    return real if isinstance(default, float) else integer if isinstance(default, int) else str


def add_setting_options(
    p,
    cls: type,
    names: Sequence[str],
    *,
    prefix: str = "",
    flags: Mapping[str, str] | None = None,
    who: str = "",
    default_text: Mapping[str, str] | None = None,
) -> tuple[SettingOption, ...]:
    """Add one option per field ``names`` of the settings dataclass ``cls`` to ``p`` (a parser or group).

    Everything an option says comes from the class, so it cannot drift from it: its type from the
    field's default, its choices (as metavar) and help from the class's NumPy docstring entry, its
    default from the field (or ``default_text``, where the default depends on the task). The flag
    is ``--{prefix}{name}`` (``flags`` renames one); an option not given is None, so the class's
    default applies. The values are checked by the class (:func:`check_given`), as a config's are.
    """
    from dataclasses import MISSING

    from ..settingsdoc import plain, settings_rows

    rows = {row.name: row for row in settings_rows(cls)}
    fields_of = {f.name: f for f in fields(cls)}
    made = []
    for name in names:
        row, f = rows[name], fields_of[name]
        default = f.default if f.default is not MISSING else None
        flag = f"--{(flags or {}).get(name) or prefix + name.replace('_', '-')}"
        text = plain(row.help).rstrip(".")
        text = text[:1].lower() + text[1:] if who and text[1:2].islower() else text  # "who: keep ..." reads as one sentence
        shown = (default_text or {}).get(name, str(default).lower() if isinstance(default, bool) else str(default))
        choices = re.fullmatch(r"\{(.*)\}", row.type.strip())
        metavar = "{" + ",".join(c.strip().strip('"') for c in choices[1].split(",")) + "}" if choices else None
        option = SettingOption(flag, name)
        described = f"{who}: {text} (default {shown})" if who else f"{text} (default {shown})"
        p.add_argument(flag, dest=option.dest, type=_converter(default), metavar=metavar, help=described.replace("%", "%%"))  # argparse formats help
        made.append(option)
    return tuple(made)


def given_settings(args: argparse.Namespace, options: Sequence[SettingOption]) -> dict[str, object]:
    """Field -> value of the generated ``options`` given on the command line."""
    return {o.field: getattr(args, o.dest) for o in options if getattr(args, o.dest) is not None}


def check_given(cls: type, values: Mapping[str, object], options: Sequence[SettingOption]) -> None:
    """Check the generated ``options``' ``values`` with their class up front (before any output is made), the
    message naming the options given."""
    try:
        cls(**values)
    except (NeurohoverError, ValueError, TypeError) as err:
        given = ", ".join(f"{o.flag} {values[o.field]}" for o in options if o.field in values)
        raise NeurohoverError(f"{given}: {err}") from None


def add_sensor_options(p: argparse.ArgumentParser) -> None:
    """--obs-noise and --obs-delay: the task seen through noisy or late sensors (:mod:`neurohover.tasks.sensor`)."""
    g = p.add_argument_group("noisy sensors (docs/benchmarks.md; default: exact sensors)")
    g.add_argument(
        "--obs-noise",
        action="append",
        help="sensor noise on what the policy sees: a level (e.g. 0.5: std 0.05 m/s, 0.05 m, 0.05 rad/s, 0.005) or key=value pairs "
        f"of {', '.join(f.name for f in fields(Sensor) if f.name != 'delay')} or level (docs/benchmarks.md)",
    )
    g.add_argument("--obs-delay", type=integer, help="control steps (0..10, 0.1 s each) the readings arrive late (default 0)")


def sensor_of(args: argparse.Namespace):
    """The sensor of --obs-noise/--obs-delay (None where neither is given: exact sensors)."""
    noise, delay = getattr(args, "obs_noise", None), getattr(args, "obs_delay", None)
    if noise is not None and len(noise) > 1:  # the option is appended to catch a repeat, which would silently keep the last
        raise NeurohoverError(f"--obs-noise is given {len(noise)} times ({', '.join(map(repr, noise))}): give it once, key=value pairs joined by commas")
    noise = None if noise is None else noise[0]
    return None if noise is None and delay is None else Sensor.of(noise, delay)


def task_family_of(args: argparse.Namespace):
    """The task family of --task/--sigma, seen through the sensor of --obs-noise/--obs-delay."""
    from ..tasks import get_task_family

    return get_task_family(args.task, args.sigma, sensor_of(args))


def family_and_mdps(args: argparse.Namespace, n: int, rng: np.random.Generator):
    """The task family and the MDP of each of ``n`` episodes, from --task/--mdp/--wind/--params/--sigma/--obs-noise/--obs-delay."""
    family = task_family_of(args)
    explicit = explicit_mdp(args, family)
    if explicit is not None:
        return family, [explicit[0]] * n
    refuse_sigma_on_zero(args, "zero" if args.mdp is None else args.mdp)
    if args.mdp == "sample":  # a fresh MDP from G for every episode
        return family, [family.sample(rng, label=f"{family.name}/sample:{i}") for i in range(n)]
    return family, [family.mdp("zero" if args.mdp is None else args.mdp)] * n  # an empty --mdp is refused, not the zero setting


def add_task_option(p: argparse.ArgumentParser) -> None:
    """--task: one of the registered task families (every command that flies takes it)."""
    from ..tasks import TASK_NAMES

    p.add_argument("--task", required=True, type=task_name, help=f"task family: {', '.join(TASK_NAMES)}")


def task_name(text: str) -> str:
    """--task as its family's name where it spells one as the task lookup reads it ('GHH-08' is ghh08), else as given
    (each command's own check names it): compete built its experiment from 'GHH-08' and refused what every other
    command flew (T43-A01)."""
    from ..tasks import task_key

    return str(task_key(text))


def real(text: str) -> float:
    """A command-line number: one past a float's range is refused as typed (a 400-digit --sigma became sigma=inf;
    seventh trial); 'nan' and 'inf' as written are left to the option's own range check."""
    try:
        return float_of(text)
    except FloatRangeError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


_INTEGER = re.compile(r"\s*[+-]?[0-9]+\s*")


class IntegerRangeError(FloatRangeError, argparse.ArgumentTypeError):
    """:func:`integer`'s refusal of a whole number past every range: argparse prints its text ("invalid integer value"
    before), and the callers that read lists of integers catch it as the ValueError it is."""


def integer(text: str) -> int:
    """A command-line whole number, in the digits 0-9: int() also reads '1_0' as 10 (``--episodes 1_0`` flew 10
    episodes, every integer option alike; sixteenth trial, T16-4), which :func:`~neurohover.errors.float_of` refuses
    for a real number. The type of every integer option (argparse: "invalid integer value: '1_0'")."""
    if not isinstance(text, str) or not _INTEGER.fullmatch(text):
        raise ValueError(f"invalid literal for an integer: {text!r:.60} (digits 0-9 only, no '_')")
    try:
        return int_of(text)
    except FloatRangeError as err:  # past 4,300 digits: argparse shows an ArgumentTypeError's own text (T53-A01)
        raise IntegerRangeError(str(err)) from None


def add_sigma_option(p: argparse.ArgumentParser) -> None:
    """--sigma: FGHH's breadth."""
    p.add_argument("--sigma", type=real, help="FGHH breadth sigma (default 0.3)")


#: ``fly``'s --mdp; ``evolve`` adds G (evolution over the family's distribution).
MDP_HELP = "zero (default), train:N, test:N (the competition sets), seeded-train:N, seeded-test:N, or sample (a fresh MDP from G per episode)"


def add_task_options(p: argparse.ArgumentParser, mdp_help: str = MDP_HELP, verb: str = "fly") -> None:
    """--task, --mdp, --wind, --params, --sigma and the sensor options: the task family and the MDP a command ``verb``s on."""
    add_task_option(p)
    p.add_argument("--mdp", help=mdp_help)
    p.add_argument("--wind", help=f"GHH-08 only: {verb} on the constant wind U,V in m/s, each in [-5, 5] (instead of --mdp; a negative U: --wind=-3,1)")
    p.add_argument(
        "--params",
        help=f"{verb} on explicit MDP parameters, comma-separated (instead of --mdp): GHH-08 wind_u,wind_v; "
        "GHH-09 its 8 parameters in [0,1]; FGHH the 11 dynamics parameters (a list that starts with a minus sign "
        "is written --params=-0.18,...)",
    )
    add_sigma_option(p)
    add_sensor_options(p)


def max_in_memory(bytes_each: int) -> int:
    """How many items of ``bytes_each`` bytes fit in half the memory free now (checked before any work)."""
    from ..procs import half_free_memory

    return max(1, half_free_memory() // bytes_each)


def note_policy_name(text: str, option: str, names: tuple[str, ...] = ("baseline",)) -> None:
    """Say on standard error when ``text`` is one of the policy ``names`` the option takes (``baseline``; --seed-policy's
    ``zero`` too) and also a file here: the name is flown, and the file only as ``./NAME`` (``--policy baseline`` flew the
    built-in beside a file 'baseline' without a word; T54-B09)."""
    from pathlib import Path

    if text in names and Path(text).exists():
        said = f"{option} {text} is the built-in {text} policy, not the file {text!r} here (give {option} ./{text} for the file)"
        print(f"neurohover: note: {said}", file=sys.stderr)


def note_policy_task(policy, task: str, option: str) -> None:
    """Say on standard error when a policy file was evolved for another task than the one it flies (a transfer can be
    meant, so it is flown; a `task` of the wrong kind in its metadata is refused; seventh trial)."""
    own = policy.metadata.get("task")
    if own is None:
        return
    if not isinstance(own, str):
        raise NeurohoverError(f"{option}: the policy's metadata task={own!r:.40} is not allowed: give a task family's name")
    if own != task:
        print(f"neurohover: note: {option} was evolved for {own}; flying it on {task}", file=sys.stderr)


def resumed_budget(checkpoint, budget: int | None) -> int | None:
    """``evolve --resume``'s budget: ``--budget`` where given, else the checkpoint's own (left out, it was none, and a finished
    100-episode run went on to the plateau without a word; T44-A03). A checkpoint that is missing is refused here, one whose
    budget is damaged by the resume's own checks."""
    from ..evolution.config import MAX_BUDGET
    from ..evolution.records import read_checkpoint

    if not checkpoint.is_file():
        raise NeurohoverError(f"--resume: no checkpoint {str(checkpoint)!r} (it is written next to --out by an earlier run)")
    if budget is not None:
        return budget
    state = read_checkpoint(checkpoint)
    own = state.get("budget") if isinstance(state, dict) else None
    return own if whole_number(own) and 1 <= own <= MAX_BUDGET else None
