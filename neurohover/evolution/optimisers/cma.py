"""CMA-ES (pycma) as a population optimiser: the optimiser, its settings and its registry entry.

Built on :class:`cma.CMAEvolutionStrategy`. pycma minimises, so the returns told here (MAXIMISED,
negative in the helicopter domain) are negated before being passed on (:func:`losses_of`).
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import io
import pickle
import struct
import sys
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import NeurohoverError, brief, whole_number
from .. import common
from ..common import (
    MAX_POPULATION,
    ChampionTracker,
    Clock,
    EntryError,
    PopulationOptimiser,
    TellInfo,
    check_entries,
    check_genomes,
    check_prototype,
    check_state,
    read_entry,
    require_int,
    require_population,
    require_spread,
)
from ..seeding import check_seed
from . import OptimiserSpec

__all__ = ["CMAES", "SIGMA0", "CMASettings", "losses_of"]

#: The initial step size for the baseline-seeded policies: a sweep on GHH-08 train:1 (600-step
#: episodes, 1000 episodes, SLP and MLP from the baseline) found 0.01-0.03 best and 0.1 crashing
#: nearly every SLP candidate (pycma's usual 0.5 belongs to problems scaled to unit boxes).
SIGMA0 = 0.02


def pycma() -> Any:
    """pycma, imported where a CMA optimiser is made or restored, not with neurohover: under ``python -OO``
    (PYTHONOPTIMIZE=2) it fails at import, reading docstrings that are stripped, and took every command down (T30-A01)."""
    try:
        import cma
    except AttributeError as err:
        if sys.flags.optimize < 2:
            raise
        raise NeurohoverError(
            f"the CMA optimisers need pycma, which cannot be imported with PYTHONOPTIMIZE={sys.flags.optimize} (python -OO strips "
            f"the docstrings it reads: {err}): unset PYTHONOPTIMIZE, or set it to 1, to use them"
        ) from None
    return cma


#: Where classes pickled in earlier checkpoints now live (module, name) -> (module, name).
_MOVED = {
    ("neurohover.evolution.neuroevolution", "_ChampionTracker"): (common, "ChampionTracker"),
    ("neurohover.evolution.neuroevolution", "_Clock"): (common, "Clock"),
    ("neurohover.evolution.neuroevolution", "ChampionRecord"): (common, "ChampionRecord"),
    ("neurohover.evolution.cmaes", "CMAES"): (sys.modules[__name__], "CMAES"),  # one file since 2026-12-04
}


#: The names of pycma's globals a CMA or UH-CMA state's pickle holds, in whichever ``cma.*`` module the installed pycma
#: keeps them (found by pickling the states of both optimisers with pycma 3.4, 4.0, 4.2, 4.3, 4.4 and 4.5, in 5 to 301
#: dimensions, after several generations, with a budget, and in earlier trials a noise handler's settings of each kind and
#: a run to pycma's own stop: CMAOptions moved from cma.evolution_strategy to cma.options_parameters, BoundTransform from
#: cma.constraints_handler to cma.boundary_handler): nothing else of pycma is looked up when a state is read back. Any
#: class of a ``cma.*`` module was let through, and cma.logger.Logger deleted a file or made directories before the
#: checkpoint was refused (T45-B03; os.mkdir: T23-12).
_PYCMA = frozenset(
    {
        "BestSolution", "BlancClass", "BoundNone", "BoundTransform", "CMAAdaptSigmaCSA", "CMAAdaptSigmaTPA", "CMADataLogger",
        "CMAEvolutionStrategy", "CMAOptions", "CMAParameters", "DiagonalDecoding", "DictFromTagsInString", "ElapsedWCTime",
        "GaussFullSampler", "GenoPheno", "MoreToWrite", "NoiseHandler", "RecombinationWeights", "RoundIntegerVariables",
        "SolutionDict", "_CMAParameters", "_CMASolutionDict_functional", "_CMAStopDict", "_StopTolXStagnation", "_TPAParameters",
        "_pass", "is_feasible",
    }
)  # fmt: skip


def _of_pycma(module: str, name: str) -> bool:
    """Whether ``module.name`` is one of :data:`_PYCMA`'s globals of pycma."""
    return (module == "cma" or module.startswith("cma.")) and name in _PYCMA


#: The globals a state's pickle calls (pickle's REDUCE): NumPy's array, scalar, dtype and generator rebuilders and plain
#: data. pycma's and neurohover's classes are only made empty and filled (NEWOBJ, BUILD), never called: a call of
#: CMADataLogger or CMAEvolutionStrategy runs their constructors with the pickle's arguments (T45-B03).
_CALLED = frozenset(
    {
        ("numpy", "dtype"),
        ("numpy.random._pickle", "__bit_generator_ctor"),
        ("numpy.random._pickle", "__generator_ctor"),
        ("numpy.random.bit_generator", "__pyx_unpickle_SeedSequence"),
        *((core, name) for core in ("numpy._core.multiarray", "numpy.core.multiarray") for name in ("_reconstruct", "scalar")),
        *(("builtins", name) for name in ("range", "slice", "complex", "set", "frozenset", "bytearray", "object")),  # plain data
        ("collections", "OrderedDict"),  # pycma 4.2 to 4.4's options
    }
)

_PICKLED = frozenset(
    {
        *_CALLED,
        ("neurohover.evolution.common", "ChampionRecord"),
        ("neurohover.evolution.common", "ChampionTracker"),
        ("neurohover.evolution.common", "Clock"),
        ("neurohover.evolution.optimisers.cma", "CMAES"),
        ("neurohover.evolution.optimisers.uh_cma", "UHCMAES"),
        ("numpy", "median"),
        ("numpy", "ndarray"),
        ("numpy.linalg", "eigh"),
        ("numpy.random._pcg64", "PCG64"),
        ("numpy.random.bit_generator", "SeedSequence"),
    }
)


class _Randn:
    """pycma's ``randn`` option drawing from the CMAES wrapper's private generator (rebuilt on load). It holds the
    generator itself, so a pickle or deepcopy of the optimiser draws from the copy's own generator."""

    def __init__(self, holder: list) -> None:
        self.holder = holder

    def __call__(self, *shape):
        return self.holder[0].standard_normal(shape)


class _Pickler(pickle.Pickler):
    """Pickles a :class:`CMAES`, replacing its ``randn`` closure(s) by a persistent id."""

    def __init__(self, file, randn) -> None:
        super().__init__(file, protocol=4)
        self._randn = randn

    def persistent_id(self, obj):
        return "randn" if obj is self._randn or isinstance(obj, _Randn) else None


def _name(obj: Any) -> str:
    """A global's module.name (its kind's name for anything else)."""
    name = getattr(obj, "__qualname__", None)
    return f"{getattr(obj, '__module__', '?')}.{name}" if isinstance(name, str) else f"a {type(obj).__name__}"


def _load_reduce(self: Any) -> None:
    """pickle's REDUCE (a call), only of :data:`_CALLED`'s globals."""
    if id(self.stack[-2]) not in self.callable_ids:
        raise EntryError(f"its pickle calls {brief(_name(self.stack[-2]))}, which no CMA state calls: allowed the pickle state_dict() wrote")
    pickle._Unpickler.load_reduce(self)  # type: ignore[attr-defined]


def _load_build(self: Any) -> None:
    """pickle's BUILD (an object's state set), not of a global: its attributes would be replaced for every user."""
    if id(self.stack[-2]) in self.global_ids:
        raise EntryError(f"its pickle sets the attributes of {brief(_name(self.stack[-2]))}, which no CMA state does: allowed the pickle state_dict() wrote")
    pickle._Unpickler.load_build(self)  # type: ignore[attr-defined]


def _load_call(self: Any) -> None:
    """pickle's INST and OBJ (protocols 0 and 1), which call a class: never in a state written with protocol 4."""
    raise EntryError("its pickle makes an object with INST or OBJ (pickle protocols 0 and 1), which no CMA state does: allowed the pickle state_dict() wrote")


def _load_bytearray8(self: Any) -> None:
    """pickle's BYTEARRAY8 (protocol 5), never in a state written with protocol 4: its length is allocated before it is
    read, so a damaged one asked for terabytes (a MemoryError, the rest of the machine's memory taken first)."""
    raise EntryError("its pickle holds a bytearray (pickle protocol 5), which no CMA state does: allowed the pickle state_dict() wrote")


class _Opcodes(dict):
    """pickle's opcodes: an unknown one is pickle's UnpicklingError, as in its C unpickler (a bare KeyError said nothing)."""

    def __missing__(self, key: int):
        raise pickle.UnpicklingError(f"invalid load key, {bytes([key])!r}.")


class _Unpickler(pickle._Unpickler):
    """pickle's own (Python) unpickler, so that its calls and attribute settings can be checked too (T45-B03)."""

    dispatch = _Opcodes(
        {
            **pickle._Unpickler.dispatch,
            pickle.REDUCE[0]: _load_reduce,
            pickle.BUILD[0]: _load_build,
            pickle.INST[0]: _load_call,
            pickle.OBJ[0]: _load_call,
            pickle.BYTEARRAY8[0]: _load_bytearray8,
        }
    )

    def __init__(self, file, holder: list) -> None:
        super().__init__(file)
        self._randn = _Randn(holder)
        self.callable_ids: set[int] = set()  # ids of the globals looked up: they live on beyond the load
        self.global_ids: set[int] = set()

    def persistent_load(self, pid):
        if pid != "randn":
            raise pickle.UnpicklingError(f"unknown persistent id {pid!r}")
        return self._randn

    def find_class(self, module: str, name: str):
        """Only what a CMA state holds (:data:`_PICKLED`): any other global was looked up and called as the pickle said,
        and made a directory (os.mkdir, T23-12) or deleted a file (cma.logger.Logger, T45-B03) before the resume was refused."""
        moved = _MOVED.get((module, name))
        if moved is None and (module, name) not in _PICKLED and not _of_pycma(module, name):
            raise EntryError(f"its pickle names {brief(f'{module}.{name}')}, which no CMA state holds: allowed the pickle state_dict() wrote")
        found = getattr(*moved) if moved is not None else super().find_class(module, name)
        self.global_ids.add(id(found))
        if (module, name) in _CALLED:
            self.callable_ids.add(id(found))
        return found


def losses_of(returns: np.ndarray) -> np.ndarray:
    """pycma's losses for maximised ``returns``: negated, a non-finite one (NaN, ``-inf``) made worse than every
    finite loss of the batch (pycma only ranks within a batch, so its update treats it as the worst)."""
    losses = -np.asarray(returns, dtype=np.float64)
    bad = ~np.isfinite(losses)
    if bad.any():
        finite = losses[~bad]
        worst = float(finite.max()) if finite.size else 0.0
        losses[bad] = worst + max(1.0, abs(worst))
    return losses


class CMAES(PopulationOptimiser):
    """CMA-ES over flat genomes, ask/tell, maximising returns.

    Randomness: pycma's ``seed`` option reseeds NumPy's GLOBAL random state,
    so instead the strategy samples through its ``randn`` option from a
    private ``numpy.random.Generator`` seeded with ``seed`` (and ``seed`` is
    set to NaN, which tells pycma not to touch the global state). Runs are
    reproducible and independent of other code using ``np.random``. No
    output is printed and no files are written.

    Non-finite returns (NaN, ``-inf``) are passed to pycma as a loss worse
    than every finite loss of the batch (pycma only ranks within a batch,
    so its update treats them as the worst); they never become champion.

    Parameters
    ----------
    prototype : np.ndarray
        1-D initial mean (D >= 2, a pycma requirement).
    sigma0 : float, default :data:`SIGMA0` (0.02)
        Initial step size (>= 1e-100 and <= 1e100).
    seed : int, default 0
        Seed of the private generator.
    popsize : int, optional
        Offspring per generation; pycma's default ``4 + 3 ln D`` if None.
    budget : int, optional
        Stop once this many evaluations were told.
    """

    def __init__(
        self,
        prototype: np.ndarray,
        sigma0: float = SIGMA0,
        seed: int = 0,
        popsize: int | None = None,
        budget: int | None = None,
    ) -> None:
        x0 = check_prototype(prototype)
        if x0.size < 2:
            raise NeurohoverError(f"CMAES needs a genome of length >= 2, got {x0.size}")
        sigma0 = require_spread("sigma0", sigma0, positive=True)
        if popsize is not None:  # 10**12 ran on in pycma's constructor (fifteenth trial)
            require_population("popsize", popsize)
        if budget is not None:  # True was taken as a budget of 1 (fifteenth trial)
            require_int("budget", budget, 1)
        self._rng = np.random.default_rng(check_seed(seed))
        opts: dict = {
            "seed": float("nan"),
            # an object, not a closure: a lambda made pickle.dumps fail and copy.deepcopy share the generator (T34-B01, B04)
            "randn": _Randn([self._rng]),
            "verbose": -9,
            "verb_disp": 0,
            "verb_log": 0,
        }
        if popsize is not None:
            opts["popsize"] = int(popsize)
        super().__init__()
        self._es = pycma().CMAEvolutionStrategy(x0, float(sigma0), opts)
        self.budget = None if budget is None else int(budget)

    def _ask(self) -> np.ndarray:
        """One generation of genomes, shape ``(popsize, D)``."""
        return np.vstack([np.asarray(x, dtype=np.float64) for x in self._es.ask()])

    def _tell(self, genomes: np.ndarray, returns: np.ndarray, info: TellInfo | None) -> None:
        """pycma's update on the generation's losses (``info`` is not used)."""
        self._es.tell(list(genomes), losses_of(returns).tolist())

    def __setstate__(self, state: dict) -> None:
        """A checkpoint written before the base class held the asked batch as one array (a list then)."""
        if isinstance(state.get("_pending"), list):
            state["_pending"] = np.vstack(state["_pending"])
        self.__dict__.update(state)

    def stop(self) -> bool:
        """True once the budget is spent or a pycma termination criterion fired."""
        if self.budget is not None and self._tracker.evaluations >= self.budget:
            return True
        return self._tracker.evaluations > 0 and bool(self._es.stop())

    @property
    def popsize(self) -> int:
        """Genomes per :meth:`ask`."""
        return int(self._es.popsize)

    @property
    def mean(self) -> np.ndarray:
        """Current distribution mean."""
        return np.array(self._es.mean, dtype=np.float64)

    @property
    def sigma(self) -> float:
        """Current overall step size."""
        return float(self._es.sigma)

    # ----------------------------------------------------------------- checkpoint

    def state_dict(self) -> dict[str, Any]:
        """JSON-serialisable snapshot: the whole optimiser pickled (pycma's state has no plainer
        form), base64-encoded, with the private generator's draws reconnected on load."""
        buf = io.BytesIO()
        _Pickler(buf, self._es.opts["randn"]).dump(self)
        data = buf.getvalue()
        return {"type": type(self).__name__, "version": common.STATE_VERSION, "pickle": base64.b64encode(data).decode("ascii"),
                "sha256": hashlib.sha256(data).hexdigest()}  # fmt: skip

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> CMAES:
        """Rebuild an optimiser from :meth:`state_dict`; it continues identically.

        Raises
        ------
        NeurohoverError
            A state that is not one of :meth:`state_dict`, naming its missing or damaged entry (only load states
            you trust: unpickling runs code).
        """
        kind = cls.__name__
        if not isinstance(state, dict):
            raise NeurohoverError(f"state dict is a {type(state).__name__}, not a dict")
        # its type checked as the others' are: 'SteadyStateNE', None or no type was taken (T18-5); states written
        # before 2026-12-06 have no version, and a UHCMAES one then said 'CMAES'
        legacy = kind != "CMAES" and isinstance(state.get("type"), str) and state["type"] == "CMAES"
        check_state({"version": common.STATE_VERSION, **state, **({"type": kind} if legacy else {})}, kind)
        check_entries(state, kind, ("type", "version", "pickle", "sha256"))  # states written before 2026-12-07 have no sha256
        digest = read_entry(state, kind, "sha256", _digest) if "sha256" in state else None
        holder: list = [None]
        pycma()  # the pickle names pycma's classes: imported here, with its one message under -OO

        def unpickle(text: str) -> CMAES:
            try:
                data = base64.b64decode(text, validate=True)
            except binascii.Error:  # its type's name, "Error", would say nothing
                raise EntryError("not base64 text: allowed the text state_dict() wrote") from None
            if digest is not None and hashlib.sha256(data).hexdigest() != digest:  # a byte changed in a dtype's state was a
                # SystemError, or a RuntimeError raised later from NumPy's internals (the closing check's fuzz of T45-B03)
                raise EntryError("its bytes are not those state_dict() wrote (their sha256 differs from the state's): it was damaged or edited")
            try:
                opt = _Unpickler(io.BytesIO(data), holder).load()
            except (struct.error, pickle.PickleError, SystemError, MemoryError) as err:  # cut short, NumPy's generator state of another kind
                raise pickle.UnpicklingError(str(err) if isinstance(err, pickle.PickleError) else f"pickle data was damaged ({type(err).__name__})") from None
            if not isinstance(opt, cls):  # a pickle of something else was returned as it was
                raise TypeError(f"it holds a {type(opt).__name__}, not a {kind}")
            # its champion tracking read back as SteadyStateNE's is: evaluations -1 was taken (sixteenth trial)
            ChampionTracker.from_dict(opt._tracker.to_dict(), int(opt._es.N))
            _check_parts(opt)
            return opt

        opt = read_entry(state, kind, "pickle", unpickle)  # {}, 'x': a bare KeyError, binascii.Error (fourteenth trial)
        holder[0] = opt._rng
        return opt


def _digest(value: object) -> str:
    """A state's ``sha256`` entry: 64 lower-case hex digits."""
    if not (isinstance(value, str) and len(value) == 64 and all(c in "0123456789abcdef" for c in value)):
        raise EntryError(f"{brief(value)} is not allowed: the 64 hex digits of the pickle's sha256 that state_dict() wrote")
    return value


def _check_parts(opt: CMAES) -> None:
    """EntryError unless an unpickled optimiser's own parts are of their kinds: a generator of None, a clock of None
    or a pending batch of text was a traceback at the first ask() or tell(), a budget of -1 or True was taken (T19-03)."""
    if not isinstance(opt._rng, np.random.Generator) or not isinstance(opt._clock, Clock):
        raise EntryError(f"its generator {brief(opt._rng)} or clock {brief(opt._clock)} is of the wrong kind: allowed what state_dict() pickled")
    if opt.budget is not None and not (whole_number(opt.budget) and opt.budget >= 1):
        raise EntryError(f"its budget={brief(opt.budget)} is not allowed: None or an integer >= 1")
    if opt._pending is not None and not (isinstance(opt._pending, np.ndarray) and opt._pending.ndim == 2):
        raise EntryError(f"its pending batch {brief(opt._pending)} is not allowed: None or genomes, one a row")
    check_genomes(opt._pending, int(opt._es.N), "pending genomes")


@dataclass(frozen=True)
class CMASettings:
    """CMA-ES settings.

    Attributes
    ----------
    sigma0 : float
        The initial step size (>= 1e-100 and <= 1e100, :data:`~neurohover.evolution.common.MAX_SPREAD`; 0.02: :data:`SIGMA0` says why).
    popsize : int or None
        Genomes per generation (>= 2; None: pycma's 4 + 3 ln D).
    """

    sigma0: float = SIGMA0
    popsize: int | None = None

    def __post_init__(self) -> None:
        pop = self.popsize
        s0 = require_spread("sigma0", self.sigma0, positive=True, what="CMA-ES ")  # 1e308 was pycma's AssertionError (eleventh trial)
        if pop is not None and (not whole_number(pop) or not 2 <= pop <= MAX_POPULATION):
            raise NeurohoverError(f"CMA-ES popsize={brief(pop)} must be None or an integer in 2..{MAX_POPULATION:,}")
        object.__setattr__(self, "sigma0", s0)
        object.__setattr__(self, "popsize", None if pop is None else int(pop))


def _make(genome: np.ndarray, settings: CMASettings, seed: int) -> CMAES:
    return CMAES(genome, sigma0=settings.sigma0, seed=seed, popsize=settings.popsize)


OPTIMISER_SPECS = (OptimiserSpec("cma", "CMA-ES (pycma), the step size adapted", CMASettings, _make, min_genes=2, stop_reason="cma-stop", label="cma-es"),)
