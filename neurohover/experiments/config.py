"""Experiment configs: plain TOML files, one per experiment, with a ``quick`` and a ``paper`` scale.

File layout (see ``neurohover/experiments/configs/*.toml``; copy one and edit it)::

    name = "fig7"                     # what `neurohover reproduce NAME` and the store call it
    title = "Figure 7: ..."           # heading in the report
    kind = "test_runs"                # evolution | model_learning | test_runs (what the units are)
    paper_ref = "Figure 7, Section 3.4"
    aliases = []                      # other names that select this experiment (optional)

    [settings]                        # shared by both scales
    task = "ghh08"
    ...

    [scales.quick]                    # a few minutes on 2 cores at most (used by the tests)
    episodes = 20                     # each key replaces the [settings] key of the same name
    [scales.paper]                    # the paper's protocol
    episodes = 1000

    [paper]                           # what the paper reports; the report compares against it
    ttests = [{ a = "incremental", b = "model-free", p = "< 0.0002" }]   # a: the one the paper found better

A resolved config is ``[settings]`` updated with ``[scales.<scale>]`` and validated against the
kind's schema (:mod:`neurohover.experiments.schema`) (unknown keys, wrong types and out-of-range values are refused with a message
naming the allowed ones). Its hash covers every setting that changes results, plus
``UNITS_VERSION`` and, for policies read from a directory, a digest of their genomes; title and
``[paper]`` are left out so that editing the reference numbers never invalidates stored results.
"""

from __future__ import annotations

import copy
import functools
import hashlib
import json
import math
import os
import re
import sys
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..compete_labels import COMPETE_SCALE
from ..errors import NeurohoverError, brief, unknown_keys
from ..jsontext import toml_odd_character, toml_twice
from ..models.lr import LEGACY_NOISE_ESTIMATE
from ..models.model import LEGACY_MODEL_SUBSTEPS
from .canonical import canonical_settings
from .paper_checks import check_paper, check_paper_table, check_texts, control_character
from .readonly import read_only
from .schema import SCHEMAS, check_given, check_kind, check_used, switched_settings, validate_table
from .settings import ExperimentSettings, typed_settings

CONFIG_DIR = Path(__file__).parent / "configs"
SCALES = ("quick", "paper")
KINDS = ("evolution", "model_learning", "test_runs")
#: Experiments in report order (the shipped configs).
ORDER = (
    "fig2", "table4", "fig7", "fig8", "fig11", "fig12", "fig13", "fig15", "fig16", "ablation-plateau", "ablation-hybrid", "ablation-fghh",
    "fig15-rules", "fig15-champion", "fig15-bandits", "fig15-uh-cma", "topology-ghh08", "topology-fghh", "fig16-slp-zero", "lr-authors-table4",
    "lr-authors-fig8", "lr-substeps-table4", "lr-substeps-fig8", "lr-noise-fig7", "lr-noise-fig11",
    "bench-sensors", "bench-sensors-fallback", "bench-sensor-models", "bench-drift", "bench-drift-armed", "wind-fig7", "wind-fig8", "wind-fig11", "risk-ghh09",
)  # fmt: skip
#: Bump when a unit function changes what it computes: stores written before are then refused.
UNITS_VERSION = 2  # 2: competition MDP sets, the authors' safeguard, OLS, the no-crash plateau


def _respelled(settings: dict, old: str, new: str) -> dict:
    """``settings`` with the optimizer tables (the experiment's and its variants') under key ``new`` instead of ``old``.

    The table was spelled ``optimiser`` until 2026-12-02: the config hash reads it under that name (so
    stores written before keep their hash and resume), and stored configs are read in today's spelling.
    """
    if old not in settings:
        return settings
    out = {(new if k == old else k): v for k, v in settings.items()}
    out["variants"] = [{(new if k == old else k): v for k, v in var.items()} for var in settings["variants"]]
    return out


def _legacy_dropped(settings: dict) -> dict:
    """``settings`` without the values that an absent setting meant before its default changed: a group's
    (or a model-learning experiment's) ``noise = "innovations"`` and a group's, a fit's or a
    model-learning experiment's ``model_substeps = 1`` (both defaults changed on 2026-12-04).

    A config naming the old value hashes as it did then (its stored results resume), and one that leaves
    it out takes the new default (the schema writes it in), so its hash changes.
    """
    both = {"noise": LEGACY_NOISE_ESTIMATE, "model_substeps": LEGACY_MODEL_SUBSTEPS}

    def dropped(table: dict, legacy: dict) -> dict:
        return {k: v for k, v in table.items() if not (k in legacy and v == legacy[k] and not isinstance(v, bool))}

    out = dropped(settings, both)
    if "groups" in settings:
        out["groups"] = [dropped(g, both) for g in settings["groups"]]
    if "fits" in settings:  # a fit always wrote its noise estimate in: only its substeps are new
        out["fits"] = [dropped(f, {"model_substeps": LEGACY_MODEL_SUBSTEPS}) for f in settings["fits"]]
    return out


@dataclass(frozen=True)
class ExperimentConfig:
    """A resolved, validated experiment config at one scale.

    Read-only, its ``settings`` too: they are a :class:`~.readonly.ReadOnlyDict` of the settings given (nested tables and
    lists read-only as well), which refuses an edit with a NeurohoverError. An edit went through unchecked, and was honoured
    or ignored as ``typed`` (cached) had been read or not (T43-B13); a change is an override
    (``load_config(..., overrides=...)``) or settings of one's own to :func:`make_config`, both checked."""

    name: str
    title: str
    kind: str
    scale: str
    settings: dict
    paper: dict = field(default_factory=dict)
    paper_ref: str = ""
    source: str = ""
    external_digest: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "settings", read_only(self.settings))  # a read-only copy: the caller's dict is no alias

    def __deepcopy__(self, memo: dict) -> ExperimentConfig:
        return replace(self, paper=copy.deepcopy(self.paper, memo))  # settings kept read-only (a deep copy of them is plain)

    @functools.cached_property
    def typed(self) -> ExperimentSettings:
        """The settings as their kind's frozen dataclass (:mod:`neurohover.experiments.settings`)."""
        return typed_settings(self.kind, self.settings)

    @property
    def hash(self) -> str:
        """Hash of everything that changes results (16 hex digits)."""
        settings = _legacy_dropped(_respelled(self.settings, "optimizer", "optimiser"))
        payload = {"kind": self.kind, "settings": settings, "units_version": UNITS_VERSION, "external": self.external_digest}
        return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]

    def same_but_unflown_digest(self, stored: dict) -> bool:
        """Whether ``stored`` (a store's config) is this one but for the digest of a policy set none of its units fly:
        written before T35-A02, when every named set was hashed, and its results do not depend on the set's files."""
        if self.external_digest:
            return False
        try:
            old = ExperimentConfig.from_dict(stored)
        except NeurohoverError:  # a damaged one is named by the store's own checks
            return False
        return bool(old.external_digest) and replace(old, external_digest="").hash == self.hash

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "title": self.title,
            "kind": self.kind,
            "scale": self.scale,
            "settings": self.settings,
            "paper": self.paper,
            "paper_ref": self.paper_ref,
            "source": self.source,
            "external_digest": self.external_digest,
            "hash": self.hash,
        }

    @classmethod
    def from_dict(cls, d: dict) -> ExperimentConfig:
        """A config as :meth:`to_dict` wrote it (a store's), in today's spelling (:func:`_respelled`); NeurohoverError
        naming what is missing or of the wrong kind in a damaged one."""
        kinds = {"name": str, "title": str, "kind": str, "scale": str, "settings": dict}
        if not isinstance(d, dict) or any(not isinstance(d.get(k), t) for k, t in kinds.items()):  # a KeyError in report (fifth trial)
            bad = [f"{k} ({d.get(k)!r:.30})" for k, t in kinds.items() if not isinstance(d.get(k), t)] if isinstance(d, dict) else ["the whole config"]
            raise NeurohoverError(f"a stored experiment config is damaged: {', '.join(bad)} missing or of the wrong kind")
        if d["kind"] not in KINDS:  # a KeyError in report (eighth trial)
            raise NeurohoverError(f"a stored experiment config is damaged: kind {d['kind']!r:.30} is none of {', '.join(KINDS)}")
        cfg = cls(
            d["name"],
            d["title"],
            d["kind"],
            d["scale"],
            _respelled(d["settings"], "optimiser", "optimizer"),
            d.get("paper", {}),
            d.get("paper_ref", ""),
            d.get("source", ""),
            d.get("external_digest", ""),
        )
        try:
            cfg.typed  # noqa: B018  (groups "x" was a RuntimeError in report; eighth trial)
        except (RuntimeError, TypeError, ValueError, AttributeError, KeyError) as err:
            raise NeurohoverError(f"a stored experiment config is damaged: its settings do not read as a {cfg.kind} experiment's ({str(err)[:80]})") from None
        return cfg


def shipped_configs() -> dict[str, Path]:
    """Name -> path of the shipped configs, in report order."""
    found = {p.stem: p for p in CONFIG_DIR.glob("*.toml")}
    order = [n for n in ORDER if n in found] + sorted(n for n in found if n not in ORDER)
    return {n: found[n] for n in order}


def _aliases() -> dict[str, str]:
    """Alias -> name of the shipped configs, read again only where a file changed (every name was resolved by
    parsing all 35 files: a quarter of planning every stored experiment)."""
    files = []
    for name, path in shipped_configs().items():
        try:
            st = path.stat()
        except OSError:
            continue
        files.append((name, str(path), st.st_mtime_ns, st.st_size))
    return dict(_aliases_of(tuple(files)))


@functools.lru_cache(maxsize=4)
def _aliases_of(files: tuple[tuple[str, str, int, int], ...]) -> tuple[tuple[str, str], ...]:
    out = []
    for name, path, _, _ in files:
        try:
            out += [(alias, name) for alias in tomllib.loads(Path(path).read_text(encoding="utf-8")).get("aliases", [])]
        except (tomllib.TOMLDecodeError, OSError, UnicodeDecodeError):
            pass
    return tuple(out)


def shipped_name(name):
    """The shipped experiment an alias names (``table3`` -> ``fig2``), or ``name`` itself: no config of one's own takes
    a shipped name or alias (:func:`check_own_name`), so a store holds a shipped experiment under its name only."""
    return _aliases().get(name, name) if isinstance(name, str) else name


def experiment_names() -> list[str]:
    return list(shipped_configs())


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except (OSError, ValueError):  # a name too long to be a file's is no file
        return False


def check_experiment_name(name: object) -> None:
    """Refuse an experiment name that is neither text nor a path: a NumPy string array was its text ("['fig2']"), and
    load_configs took np.array(["all"]) for 'all' and two names for NumPy's "truth value is ambiguous" (T46-B09)."""
    if not isinstance(name, str) and not (isinstance(name, os.PathLike) and isinstance(os.fspath(name), str)):
        raise NeurohoverError(f"experiment {brief(name)} is not allowed: give one experiment's name, 'all', or a path to a .toml config file (as text)")


def resolve_name(name: str | Path) -> Path:
    """The config file of a shipped experiment name (or alias), or of a path to a .toml file."""
    check_experiment_name(name)
    name = os.fspath(name)  # a pathlib.Path of a .toml file too
    path = Path(name)
    if name.lower().endswith(".toml"):  # base.TOML too, as .JSON and .NPZ are read (T33-A01)
        from ..paths import checked_path

        checked_path(name, "config file")  # a name too long was an OSError (fourth trial)
        if path.is_dir():  # it was called missing (fifth trial)
            raise NeurohoverError(f"config file {name!r} is a directory; give a .toml config file")
        if not path.is_file():
            raise NeurohoverError(f"config file {name!r} does not exist" if not path.exists() else f"config file {name!r} is not a regular file")
        return path
    shipped = shipped_configs()
    name = _aliases().get(name, name)
    if name not in shipped:
        if len(path.parts) > 1 or _is_file(path):  # a path, taken for a name (T33-A02)
            raise NeurohoverError(f"config file {name!r} is not allowed: a config file's name ends .toml; give a path ending .toml, or an experiment name")
        raise NeurohoverError(f"unknown experiment {name!r}: known experiments are {', '.join(shipped)} (or 'all', or a path to a .toml config file)")
    return shipped[name]


COMPETE_PREFIX = "compete-"  # neurohover compete stores its competition as experiment compete-TASK-AGENT


def compete_name(task: str, agent: str) -> str:
    """The experiment name ``neurohover compete`` stores a competition of ``agent`` on ``task`` under."""
    return f"{COMPETE_PREFIX}{task}-{agent}"


def code_written_name(name: str) -> str | None:
    """Whose name ``name`` is where the code itself writes it into a store (a shipped experiment, its alias, 'all',
    or compete's ``compete-TASK-AGENT``), or None for a name free for a config of one's own. The one predicate
    :func:`check_own_name` refuses by. Case is ignored: 'FIG7' beside fig7 wrote figures that are one file on a
    case-insensitive file system (T28-A10)."""
    if name == "all" or name in shipped_configs():
        return "a shipped experiment's (or 'all')"
    if name in _aliases():
        return f"an alias of the shipped experiment {_aliases()[name]!r}"
    if name.lower().startswith(COMPETE_PREFIX):
        return "in the name space compete-TASK-AGENT of `neurohover compete`'s own experiments"
    taken = next((n for n in ["all", *shipped_configs(), *_aliases()] if n.lower() == name.lower()), None)
    if taken is not None:
        return f"the shipped name {taken!r} but for case (their figures would be one file where case is ignored)"
    return None


def check_own_name(cfg: ExperimentConfig) -> None:
    """Refuse a config file of one's own that takes a name the code itself writes (:func:`code_written_name`): stored,
    its results and report would pass for the shipped experiment's (the report gives a shipped name the paper's claims
    and discussion), or would be mixed with a competition's as another scale of one experiment (T27-A06)."""
    whose = code_written_name(cfg.name)
    if whose is None:
        return
    shipped = shipped_configs()
    if cfg.name in shipped and cfg.source and Path(cfg.source).resolve() == shipped[cfg.name].resolve():
        return  # the shipped config itself
    if cfg.name.startswith(COMPETE_PREFIX) and not cfg.source:
        return  # compete's inline config (make_config with no source file; a config file always has one)
    alias_of = _aliases().get(cfg.name)
    if alias_of is not None:  # `reproduce table3` ran fig2 while `results table3` showed this config's (eleventh trial, S8)
        raise NeurohoverError(
            f"config {cfg.source!r}: name = {cfg.name!r} is an alias of the shipped experiment {alias_of!r}: a config of your own needs a name "
            f"of its own, or `reproduce {cfg.name}` would run {alias_of} while its results pass under the same name"
        )
    if cfg.name.lower().startswith(COMPETE_PREFIX):
        raise NeurohoverError(
            f"config {cfg.source!r}: name = {cfg.name!r} is not allowed: it is {whose}; a config of your own needs a name of its own "
            f"(not starting with {COMPETE_PREFIX!r}), or its results would be mixed with a competition's as another scale of one experiment"
        )
    raise NeurohoverError(
        f"config {cfg.source!r}: name = {cfg.name!r} is {whose}: a config of your own needs a name of its own, "
        "or its results and report would pass for the shipped experiment's"
    )


def parse_override(text: str, option: str = "--set") -> tuple[str, Any]:
    """``KEY=VALUE`` of command-line ``option`` with VALUE in TOML syntax (a bare word is taken as a string)."""
    if not isinstance(text, str):  # None was an AttributeError (eighth trial)
        raise NeurohoverError(f"{option} {text!r:.40} is not allowed: give KEY=VALUE as text (VALUE in TOML syntax)")
    bad = control_character(text)
    if bad is not None:  # TOML read the lines after a newline, and they were dropped without a word (T28-A06)
        raise NeurohoverError(f"{option} {brief(text)} is not allowed: it holds the control character {bad}; give one KEY=VALUE on one line")
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise NeurohoverError(f'bad {option} {text!r}: expected KEY=VALUE (VALUE in TOML syntax, e.g. runs=3 or policies="evolve")')
    try:
        parsed = tomllib.loads(f"v = {value.strip()}")["v"]
    except RecursionError:  # tomllib follows nesting by recursion (seventh trial)
        raise NeurohoverError(f"bad {option} {text[:40]!r}...: VALUE is nested too deeply") from None
    except tomllib.TOMLDecodeError as err:
        if value.strip()[:1] in ("{", "[", '"', "'"):  # meant as TOML, not a bare word: say why it is not (a repeated key, ...)
            why = re.sub(r" \(at (line \d+, column \d+|end of document)\)$", "", str(err))  # positions in our wrapper, not in VALUE
            raise NeurohoverError(f"bad {option} {text!r}: VALUE is not valid TOML ({why})") from None
        parsed = value.strip()
        number = _toml_number(parsed)
        if number is not None:  # '.5' was refused as "must be a finite number", as if no number were given (T41-A03)
            raise NeurohoverError(f"bad {option} {brief(text)}: {brief(parsed)} is text, not a TOML number: write {key}={number}") from None
    except ValueError:  # tomllib's int() past 4,300 digits, not a TOMLDecodeError (T36-A01)
        raise NeurohoverError(f"bad {option} {brief(text)}: VALUE holds {_TOO_LONG}") from None
    return key, parsed


def _toml_number(text: str) -> str | None:
    """How TOML writes the number ``text`` reads as where TOML reads no number there ('.5', '5.', '+.5', '01', '1.e5'),
    else None (a word, inf, nan)."""
    if not re.fullmatch(r"[+-]?[0-9_.]*[0-9][0-9_.]*(?:[eE][+-]?[0-9_]+)?", text):
        return None
    try:
        number = float(text)
    except ValueError:
        return None
    if re.fullmatch(r"[+-]?[0-9_]+", text):
        return str(int(text))
    return repr(number) if math.isfinite(number) else None


#: What tomllib cannot read (Python's int_max_str_digits): past every setting's range (T36-A01).
_TOO_LONG = f"an integer of more than {sys.get_int_max_str_digits() or 4300} digits, past every setting's range: give a number in the setting's range"


def parse_overrides(texts: list[str] | None, option: str = "--set") -> dict[str, Any]:
    """Repeated ``option KEY=VALUE`` as a dict; a key given twice is refused (the last would win without a word)."""
    if texts is not None and not isinstance(texts, (list, tuple)):  # 5 was a TypeError, 'a=1' read as a, =, 1 (T17-5)
        raise NeurohoverError(f"{option} {brief(texts)} is not allowed: give a list of KEY=VALUE texts, or None")
    out: dict[str, Any] = {}
    for text in texts or []:
        key, value = parse_override(text, option)
        if key in out:
            raise NeurohoverError(f"{option} {key}=... is given more than once ({key}={out[key]!r} and {key}={value!r}): give it once")
        out[key] = value
    return out


def bad_byte(err: UnicodeDecodeError) -> str:
    """Where ``err`` found the first byte that is no UTF-8 in the text it decoded: "byte 0xe9 at line 1, column 9"."""
    data = bytes(err.object)  # utf-8-sig: the text after a byte-order mark, which the line and column count from
    start = max(0, min(err.start, len(data) - 1))
    line = data.count(b"\n", 0, start) + 1
    column = len(data[data.rfind(b"\n", 0, start) + 1 : start].decode()) + 1  # in characters: all before it is UTF-8
    return f"byte {data[start]:#04x} at line {line}, column {column}"


def _check_shape(raw: dict, where: str) -> None:
    """Refuse [settings] and [scales] tables of the wrong TOML shape, by name: ``[[scales.quick]]`` (a list) or
    ``settings = 5`` were TypeErrors where they are merged, and ``scales = "quick"`` named the scales c, i, k, q, u (T28-A02)."""
    if not isinstance(raw["settings"], dict):
        raise NeurohoverError(f"{where}: settings = {brief(raw['settings'])} is not allowed: give a table of settings ([settings], not [[settings]])")
    scales = raw.get("scales", {})
    if not isinstance(scales, dict):
        raise NeurohoverError(f"{where}: scales = {brief(scales)} is not allowed: give a table of scale tables ([scales.quick] and [scales.paper])")
    for name, table in scales.items():
        if name in SCALES and not isinstance(table, dict):  # an unknown name is refused as such (load_config)
            raise NeurohoverError(f"{where}: scales.{name} = {brief(table)} is not allowed: give a table of settings ([scales.{name}], not [[scales.{name}]])")


def load_config(name_or_path: str, scale: str, overrides: dict[str, Any] | None = None) -> ExperimentConfig:
    """Load, resolve and validate an experiment config at ``scale`` (``quick`` or ``paper``)."""
    if not isinstance(scale, str) or scale not in SCALES:  # an array was numpy's 'truth value is ambiguous' (T18-3)
        raise NeurohoverError(f"unknown scale {brief(scale)}: allowed {', '.join(SCALES)}")
    # a TypeError (fourth trial); the example is a setting of every shipped config ('episodes' was not fig2's, T48-B09)
    if overrides is not None and not (isinstance(overrides, dict) and all(isinstance(k, str) for k in overrides)):
        raise NeurohoverError(
            f"overrides={overrides!r:.60} is not allowed: give a dict whose keys are setting names (text), e.g. {{'seed': 3}} (the CLI's --set seed=3)"
        )
    path = resolve_name(name_or_path)
    try:
        raw = tomllib.loads(text := path.read_text(encoding="utf-8-sig"))  # TOML is UTF-8; a byte-order mark was "Invalid statement" (ninth trial)
    except tomllib.TOMLDecodeError as err:  # a curly quote pasted from a slide named (T49-A04)
        raise NeurohoverError(f"config {str(path)!r} is not valid TOML: {toml_twice(text, err) or err}{toml_odd_character(text, err)}") from None
    except RecursionError:  # a value nested thousands deep (seventh trial)
        raise NeurohoverError(f"config {str(path)!r} is not allowed: its TOML is nested too deeply") from None
    except UnicodeDecodeError as err:  # was "cannot be read (UnicodeDecodeError)", naming neither the rule nor the place (T19-15)
        raise NeurohoverError(f"config {str(path)!r} cannot be read: a config must be UTF-8 text, and {bad_byte(err)} is not (save it as UTF-8)") from None
    except ValueError:  # tomllib's int() past 4,300 digits (T36-A01; after UnicodeDecodeError, a ValueError too)
        raise NeurohoverError(f"config {str(path)!r} is not allowed: it holds {_TOO_LONG}") from None
    except OSError as err:
        raise NeurohoverError(f"config {str(path)!r} cannot be read ({err.strerror or type(err).__name__})") from None
    where = f"config {str(path)!r}"
    allowed_top = {"name", "title", "kind", "paper_ref", "aliases", "settings", "scales", "paper"}
    unknown = unknown_keys(raw, allowed_top)  # each as its repr: the key '' was named as nothing
    if unknown:
        raise NeurohoverError(f"{where}: unknown top-level key(s) {unknown}; allowed: {', '.join(sorted(allowed_top))}")
    for key in ("name", "kind", "settings"):
        if key not in raw:
            raise NeurohoverError(f"{where}: missing top-level key {key!r}")
    own = path.resolve().parent != CONFIG_DIR.resolve()
    if own and "aliases" in raw and raw.get("name") not in shipped_configs():  # only the shipped configs' are read (seventh trial);
        # a copy of a shipped config keeps its name and aliases: check_own_name refuses the name first, the clearer message
        raise NeurohoverError(f"{where}: aliases apply to the shipped experiments only (a config of your own is named by its path): remove the key")
    for key in ("title", "paper_ref"):  # title = 5 was stored, then refused as a damaged store's (sixth trial)
        if key in raw and not isinstance(raw[key], str):
            raise NeurohoverError(f"{where}: {key} = {brief(raw[key])} is not allowed: give text")
    kind = raw["kind"]
    if kind not in KINDS:
        raise NeurohoverError(f"{where}: kind = {brief(kind)} is not allowed: expected one of {', '.join(KINDS)}")
    _check_shape(raw, where)
    scales = raw.get("scales", {})
    bad_scales = sorted(set(scales) - set(SCALES))
    if bad_scales:
        raise NeurohoverError(f"{where}: unknown scale table(s) {', '.join(bad_scales)}; allowed: {', '.join(SCALES)}")
    if scale not in scales:
        raise NeurohoverError(f"{where}: has no [scales.{scale}] table")
    _check_shared(raw["settings"], scales, scale, overrides or {}, kind, where)
    merged = {**raw["settings"], **scales[scale], **(overrides or {})}
    # the file's own settings whose source --set switched (policies, generic, methods): they stay accepted (T60-A02)
    switched = switched_settings({*raw["settings"], *scales[scale]}, overrides or {})
    config = make_config(
        raw["name"],
        kind,
        scale,
        merged,
        title=raw.get("title", raw["name"]),
        paper=raw.get("paper", {}),
        paper_ref=raw.get("paper_ref", ""),
        source=str(path),
        where=f"{where} at scale {scale!r}",
        switched=switched,
    )  # the run's own scale first: a mistake found in both was named by the other scale (T42-A01)
    for other in scales:  # a typo in the scale not run now must not wait for the day it runs
        if other != scale:
            resolved = validate_table({**raw["settings"], **scales[other]}, SCHEMAS[kind], f"{where} at scale {other!r}")
            check_kind(resolved, kind, f"{where} at scale {other!r}")
    check_paper(raw.get("paper", {}), raw, where)  # after the settings: a bad agent is named as such, not as a t test naming nothing
    _check_seeds_of(config, where)
    if overrides and not own:  # the report would judge other conditions against the paper's claims (T29-A02)
        from .overrides import check_shipped_overrides

        check_shipped_overrides(raw["name"], str(path), load_config(str(path), scale).settings, config.settings, f"{where} at scale {scale!r}")
    return config


def _check_shared(settings: dict, scales: dict, scale: str, overrides: dict, kind: str, where: str) -> None:
    """Check each setting [settings] gives that some scale uses (one its scale table, or --set on the run's scale, does
    not replace) on its own, naming [settings]: ``seed = "7"`` there was named by the first scale checked, 'paper' under
    --scale quick too (T42-A01). The checks across settings need the merged table: they name the scale, the run's first."""
    used = {k: v for k, v in settings.items() if any(k not in table and (other != scale or k not in overrides) for other, table in scales.items())}
    validate_table(used, SCHEMAS[kind], f"{where}, [settings]", given_only=True)


def _check_seeds_of(config: ExperimentConfig, where: str) -> None:
    """Refuse a ``seeds_of`` naming an experiment that is neither shipped nor this one: its seeds are derived from the
    name, so a typo ("fig1l") paired nothing without a word (seventh trial). Its group is a name the seeds are derived
    from too (bench-drift's conditions), not necessarily a group the experiment runs."""
    tables = [config.settings.get("seeds_of"), *(g.get("seeds_of") for g in config.settings.get("groups", []))]
    known = [*shipped_configs(), config.name]
    for table in tables:
        if table is not None and table["experiment"] not in known:
            raise NeurohoverError(
                f"{where}: seeds_of names experiment {table['experiment']!r:.60}, which is neither shipped nor this one: give one of {', '.join(known)}"
            )


#: An experiment's name becomes file names (figures, discussions, exports): letters, digits, '.', '_' and '-',
#: starting with a letter or digit, so that no name can reach outside the report's folder.
_SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}")


def settings_scale(settings: dict) -> str:
    """The scale of an experiment run inline (``compete``) with ``settings``: a digest of them, so that competitions of
    other settings in one store are kept apart and the same settings resume."""
    return f"settings-{hashlib.sha256(json.dumps(settings, sort_keys=True).encode()).hexdigest()[:10]}"


def check_name(name, where: str) -> None:
    """Refuse an experiment name that is not a safe file name (``../x``, ``""``, a slash)."""
    if not isinstance(name, str) or not _SAFE_NAME.fullmatch(name):
        raise NeurohoverError(
            f"{where}: name = {brief(name)} is not allowed: give 1-100 ASCII letters (A-Z, a-z), digits, '.', '_' or '-', starting with a letter or digit"
        )


def check_scale(scale, where: str) -> None:
    """Refuse a scale no experiment has: quick, paper, or a compete run's settings-HASH (:func:`settings_scale`); 'weird'
    was stored (twelfth trial, S7). Shared by :func:`make_config` and the store's writes."""
    if not isinstance(scale, str) or (scale not in SCALES and not COMPETE_SCALE.fullmatch(scale)):
        raise NeurohoverError(f"{where}: scale = {brief(scale)} is not allowed: give one of {', '.join(SCALES)} (or a compete run's settings-HASH)")


def make_config(
    name: str,
    kind: str,
    scale: str,
    settings: dict[str, Any],
    *,
    title: str = "",
    paper: dict | None = None,
    paper_ref: str = "",
    source: str = "",
    where: str | None = None,
    switched: frozenset[str] = frozenset(),
) -> ExperimentConfig:
    """Validate ``settings`` of an experiment of ``kind`` and resolve them into a config.

    The one path from settings to a config: shipped TOML files (:func:`load_config`) and inline
    experiments (``neurohover compete``) both come through here. ``switched``: the settings a config file gives where
    ``--set`` switched the source they apply to (:func:`~.schema.switched_settings`; :func:`~.schema.check_used` accepts them).
    """
    where = where or f"experiment {name!r}"
    check_name(name, where)
    if not isinstance(kind, str) or kind not in KINDS:  # an array was numpy's 'truth value is ambiguous' (T18-3)
        raise NeurohoverError(f"{where}: kind = {brief(kind)} is not allowed: expected one of {', '.join(KINDS)}")
    check_scale(scale, where)
    if not isinstance(source, str):  # title=5 was later called a damaged store (twelfth trial, U2)
        raise NeurohoverError(f"{where}: source = {brief(source)} is not allowed: give text")
    check_texts(title, paper_ref, settings if isinstance(settings, dict) else {}, where)  # one line each: a newline put headings into the report (T28-A07)
    resolved = validate_table(dict(settings), SCHEMAS[kind], where)
    check_given(settings, where)
    check_kind(resolved, kind, where)
    check_used(settings, resolved, kind, where, switched)
    canonical_settings(resolved)  # equal settings spelt otherwise hash alike (T29-A07)
    paper = {} if paper is None else paper
    check_paper_table(paper, where, kind)  # after the settings: a bad agent is named as such
    from .external import external_digest

    digest = external_digest(kind, resolved)
    return ExperimentConfig(name, title or name, kind, scale, resolved, paper, paper_ref, source, digest)


def load_configs(name: str, scale: str, overrides: dict[str, Any] | None = None) -> list[ExperimentConfig]:
    """``all`` (every shipped experiment) or one name / path."""
    check_experiment_name(name)
    if name == "all":
        return [load_config(n, scale, overrides) for n in shipped_configs()]
    return [load_config(name, scale, overrides)]


#: Settings that say where an experiment's policies come from; a paper-scale run may have set them on the
#: command line (`--set policies=shipped`), and an --update that forgets them would run every unit again.
POLICY_SOURCES = ("policies", "generic")


def shipped_counterpart(cfg: ExperimentConfig) -> ExperimentConfig | None:
    """The shipped config of a stored config's experiment, with the stored policy source (:data:`POLICY_SOURCES`; None:
    no shipped config of that name): what a ``reproduce`` of it would run now."""
    if cfg.name not in shipped_configs():
        return None
    return load_config(cfg.name, cfg.scale, {k: cfg.settings[k] for k in POLICY_SOURCES if k in cfg.settings})


def with_shipped_paper(cfg: ExperimentConfig, shipped: ExperimentConfig | None) -> ExperimentConfig:
    """A stored config with its shipped counterpart's ``[paper]`` table (the paper's numbers, claims and our protocol
    notes: documentation, outside the hash), so a corrected note reaches the report without running anything again."""
    return cfg if shipped is None else replace(cfg, paper=shipped.paper, paper_ref=shipped.paper_ref)
