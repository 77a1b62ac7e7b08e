"""Generic policies: the baseline, SLP and MLP networks, genomes and policy files (docs/model.md, Policies).

Networks see 9 of the 12 observation entries (u, v, w, x, y, z, qx, qy, qz) and output the four
actions (aileron, elevator, rudder, collective). A genome is the flat vector of a network's weights
and biases in the fixed order of docs/model.md, Policies, so policies can be exchanged between tools.

Policy files are JSON: ``{"topology": "slp" | "mlp", "genome": [...]}`` plus optional metadata
keys. The name ``baseline`` stands for the competition's baseline policy wherever a file is taken.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import NeurohoverError, as_floats, brief, float64_of, key_text, masked_note, refuse_non_text_keys
from .sim.constants import MLP_STEEPNESS, OBS_NAMES

TOPOLOGIES = ("slp", "mlp")
GENOME_LENGTH = {"slp": 40, "mlp": 42}
#: The largest gene magnitude a policy takes (T30-B01: genes of 1e308 were taken and acted NaN/inf). Far above anything
#: evolution produces (the shipped policies and the committed store's champions stay under 20; a run at the largest
#: spread, MAX_SPREAD 1e100, draws genes near 1e101, and eonn and the champion become Policies mid-run), yet an MLP's
#: deepest product, gene x gene x (sum of five inputs), stays finite for observations up to 3e67, far past any flown
#: state (crash limits of 20 m, 5 m/s, 4 pi rad/s, and sensor noise of std <= 1e4).
MAX_GENE = 1e120
#: The largest observation entry :meth:`Policy.act` takes (T31-B05: 1e190 and 1.7e308 acted inf and NaN): with genes
#: <= MAX_GENE an MLP's actions stay below about 3e300 (an SLP's 9e180), finite, for entries up to it; flown states
#: stay far below (the crash limits above, sensor noise of std <= 1e4).
MAX_OBSERVATION = 1e60
INPUT_NAMES = ("u", "v", "w", "x", "y", "z", "qx", "qy", "qz")
MLP_BIAS_NAMES = ("hy", "hx", "hz", "L1", "L2", "L3", "L4", "S1", "S2", "S3", "S4", "a1", "a2", "a3", "a4")
MLP_WEIGHT_NAMES = (
    "y->hy",
    "x->hx",
    "z->hz",
    "v->L1",
    "y->L1",
    "qx->L1",
    "hy->L1",
    "u->L2",
    "x->L2",
    "qy->L2",
    "hx->L2",
    "qz->L3",
    "w->L4",
    "z->L4",
    "hz->L4",
    "L1->S1",
    "L2->S2",
    "L3->S3",
    "L4->S4",
    "L1->a1",
    "S1->a1",
    "L2->a2",
    "S2->a2",
    "L3->a3",
    "S3->a3",
    "L4->a4",
    "S4->a4",
)
MLP_GENE_NAMES = tuple(f"b:{n}" for n in MLP_BIAS_NAMES) + tuple(f"w:{n}" for n in MLP_WEIGHT_NAMES)

# The competition's baseline policy: gains per (action, input) and output biases.
BASELINE_GAINS = {
    ("a1", "y"): -0.0196,
    ("a1", "v"): -0.0367,
    ("a1", "qx"): -0.7475,
    ("a2", "x"): -0.0185,
    ("a2", "u"): -0.0322,
    ("a2", "qy"): 0.7904,
    ("a3", "qz"): -0.1969,
    ("a4", "z"): 0.0513,
    ("a4", "w"): 0.1348,
}
BASELINE_BIASES = (0.02, 0.0, 0.0, 0.23)


#: Checks of a policy file's record of the run that evolved it, by name: each takes the policy's metadata and says what in
#: it contradicts itself ('' when nothing does). :func:`load_policy` applies them to every JSON policy file it reads.
#: :mod:`neurohover.policy_records` installs its ``policy_record_problem`` as it is imported: it reads the evolution's words (its
#: stop reasons and methods), which this layer may not import (T23-11).
RECORD_CHECKS: dict[str, Callable[[dict], str]] = {}


def _sigmoid(s: float) -> float:
    # Clamp the exponent so extreme genomes saturate instead of overflowing.
    return 1.0 / (1.0 + math.exp(min(700.0, -MLP_STEEPNESS * s)))


@dataclass(frozen=True, eq=False)
class Policy:
    """A generic policy: topology and genome, plus free-form metadata.

    Two policies are equal when their topologies and genomes are (metadata does not count).

    Attributes
    ----------
    topology : {"slp", "mlp"}
    genome : numpy.ndarray
        Float64 vector of ``GENOME_LENGTH[topology]`` genes in the order of docs/model.md, Policies (read-only).
    metadata : dict
        Anything worth keeping with the policy (task, MDP, score, how it was made).
    """

    topology: str
    genome: np.ndarray
    metadata: dict = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        _check_topology(self.topology)
        if not isinstance(self.metadata, dict):  # [1] was kept, and failed when the policy was saved (second trial)
            raise NeurohoverError(f"policy metadata={self.metadata!r:.60} is not allowed: give a dict")
        taken = sorted({"topology", "genome"} & set(self.metadata))  # saved, they overwrote the network itself (seventh trial)
        if taken:
            raise NeurohoverError(f"policy metadata key(s) {', '.join(taken)} are the policy's own: give the metadata other names")
        genome = check_genome(self.genome, self.topology)
        genome.setflags(write=False)
        object.__setattr__(self, "genome", genome)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Policy):
            return NotImplemented
        return self.topology == other.topology and np.array_equal(self.genome, other.genome)

    def __hash__(self) -> int:  # + 0.0: a gene -0.0 hashed apart from 0.0, which == takes as equal (T28-B15)
        return hash((self.topology, (self.genome + 0.0).tobytes()))

    def __reduce__(self):  # copies and unpickled policies are built anew: their genome was writable, NaN flown (T28-B03)
        return (Policy, (self.topology, self.genome, self.metadata))

    def act(self, observation: Sequence[float]) -> tuple[float, float, float, float]:
        """Actions for a 12-number observation, computed in plain Python (the readable definition).

        Raises NeurohoverError for an observation that is not 12 finite numbers (a NaN would give NaN actions silently),
        or one with an entry past :data:`MAX_OBSERVATION` (1e60) in magnitude: the rule that keeps every action finite for
        genes up to :data:`MAX_GENE` (1e190 gave inf and NaN actions; T31-B05). Flown states stay far below it."""
        try:  # not text, booleans or complex numbers; not a masked array, whose hidden values were flown (T16-9)
            raw = np.asarray(observation)
            obs = float64_of(raw) if raw.dtype.kind in "iuf" and not isinstance(observation, np.ma.MaskedArray) else np.zeros(0)
        except (TypeError, ValueError):
            obs = np.zeros(0)
        if obs.shape != (12,) or not np.all(np.isfinite(obs)):  # the shape: (3, 4) was flown flattened as one observation (T15-28)
            raise NeurohoverError(
                f"observation {brief(observation)} is not allowed: give 12 finite numbers of shape (12,) (u, v, w, x, y, z, p, q, r, qx, qy, qz)"
            )
        big = np.flatnonzero(np.abs(obs) > MAX_OBSERVATION)
        if big.size:  # one test per call, outside the arithmetic: the kernel's hot path is not this one
            raise NeurohoverError(
                f"observation {brief(observation)} is out of range: its {OBS_NAMES[big[0]]} {brief(float(obs[big[0]]))} is past "
                f"{MAX_OBSERVATION:g}; allowed 12 finite numbers in [-{MAX_OBSERVATION:g}, {MAX_OBSERVATION:g}] (actions stay finite)"
            )
        u, v, w, x, y, z, _p, _q, _r, qx, qy, qz = obs.tolist()
        g = self.genome.tolist()
        if self.topology == "slp":
            inputs = (u, v, w, x, y, z, qx, qy, qz)
            return tuple(sum(g[9 * i + j] * inputs[j] for j in range(9)) + g[36 + i] for i in range(4))
        b, wt = g[:15], g[15:]
        hy = _sigmoid(b[0] + wt[0] * y)
        hx = _sigmoid(b[1] + wt[1] * x)
        hz = _sigmoid(b[2] + wt[2] * z)
        l1 = b[3] + wt[3] * v + wt[4] * y + wt[5] * qx + wt[6] * hy
        l2 = b[4] + wt[7] * u + wt[8] * x + wt[9] * qy + wt[10] * hx
        l3 = b[5] + wt[11] * qz
        l4 = b[6] + wt[12] * w + wt[13] * z + wt[14] * hz
        s1, s2, s3, s4 = (_sigmoid(b[7 + k] + wt[15 + k] * lk) for k, lk in enumerate((l1, l2, l3, l4)))
        return (
            b[11] + wt[19] * l1 + wt[20] * s1,
            b[12] + wt[21] * l2 + wt[22] * s2,
            b[13] + wt[23] * l3 + wt[24] * s3,
            b[14] + wt[25] * l4 + wt[26] * s4,
        )

    def with_genome(self, genome: np.ndarray, **metadata) -> Policy:
        """A policy of the same topology with another genome, and this one's metadata (updated by ``metadata``) less the
        keys that record results of flying this genome (:data:`GENOME_RESULT_KEYS`: its champion and validation returns,
        history file, episode and evaluation counts, stop reason, seconds): they are not the new genome's (T32-B14). The
        keys that describe its run's setting (task, target, method, settings, seed, budget, n_steps ...) are kept."""
        kept = {k: v for k, v in self.metadata.items() if k not in GENOME_RESULT_KEYS}
        return Policy(self.topology, genome, {**kept, **metadata})  # uncast: float() read '0.5', dates and bools (T16-10)


#: Metadata keys that record results of flying a policy's genome (as ``neurohover evolve`` writes them):
#: :meth:`Policy.with_genome` leaves them out, as another genome's results (a saved policy claimed them; T32-B14).
GENOME_RESULT_KEYS = frozenset(
    {"champion_return", "champion_fitness_scale", "validation_return", "validation_sd", "validation_episodes", "history",
     "episodes", "evaluations", "generations", "seconds", "stop_reason", "reevaluated_from"}
)  # fmt: skip


def check_genome(genome, topology: str) -> np.ndarray:
    """Return ``genome`` as a float64 vector of the topology's length, or raise a clear error."""
    _check_topology(topology)  # a Policy's topology overwritten with 'rnn' was a KeyError here (T41-B11)
    try:  # text, booleans, complex numbers (third trial), objects, dates and masked arrays (T16-9, T16-10): as_floats
        arr = as_floats(genome, "genome", "")
    except NeurohoverError:
        raise NeurohoverError(f"a {topology} genome must be a list of finite real numbers, got {brief(genome)}{masked_note(genome)}") from None
    arr = arr.reshape(-1) if arr.ndim <= 1 else arr
    n = GENOME_LENGTH[topology]
    if arr.ndim != 1 or arr.shape[0] != n:
        raise NeurohoverError(f"a {topology} genome has {n} genes, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise NeurohoverError(f"a {topology} genome must hold finite numbers; genes {np.flatnonzero(~np.isfinite(arr)).tolist()} are not")
    big = np.flatnonzero(np.abs(arr) > MAX_GENE)
    if big.size:  # finite genes of 1e308 acted NaN and inf (T30-B01)
        raise NeurohoverError(
            f"a {topology} genome's gene {int(big[0])} {brief(float(arr[big[0]]))} is out of range: allowed numbers in [-{MAX_GENE:g}, {MAX_GENE:g}]"
        )
    return arr


def _check_topology(topology: object) -> None:
    """Refuse a topology that is not ``"slp"`` or ``"mlp"`` (an array was NumPy's "truth value is ambiguous"; T16-12)."""
    if not isinstance(topology, str) or topology not in TOPOLOGIES:
        raise NeurohoverError(f"unknown policy topology {brief(topology)}: allowed {', '.join(TOPOLOGIES)}")


def zero_genome(topology: str) -> np.ndarray:
    """The all-zero prototype of a topology."""
    _check_topology(topology)
    return np.zeros(GENOME_LENGTH[topology])


def slp_baseline_genome() -> np.ndarray:
    """SLP genome that acts exactly like the baseline policy."""
    g = np.zeros(40)
    for (action, inp), gain in BASELINE_GAINS.items():
        g[9 * (int(action[1]) - 1) + INPUT_NAMES.index(inp)] = gain
    g[36:40] = BASELINE_BIASES
    return g


def mlp_baseline_genome() -> np.ndarray:
    """MLP genome that acts exactly like the baseline policy (docs/model.md, Policies: gains on the input-to-sum
    weights, every Lk -> ak weight 1, output biases (0.02, 0, 0, 0.23), everything else 0)."""
    g = np.zeros(42)
    index = {name: 15 + i for i, name in enumerate(MLP_WEIGHT_NAMES)}
    for (action, inp), gain in BASELINE_GAINS.items():
        g[index[f"{inp}->L{action[1]}"]] = gain
    for k in range(1, 5):
        g[index[f"L{k}->a{k}"]] = 1.0
    g[11:15] = BASELINE_BIASES
    return g


def baseline_policy() -> Policy:
    """The competition's baseline policy (an SLP with the baseline gains)."""
    return Policy("slp", slp_baseline_genome(), {"name": "baseline"})


def prototype(topology: str, seed: str = "baseline") -> Policy:
    """A prototype network: ``seed`` is ``"zero"`` or ``"baseline"`` (baseline-equivalent)."""
    _check_topology(topology)  # both as text first: an array was NumPy's "truth value is ambiguous" (T16-12)
    if not isinstance(seed, str) or seed not in ("zero", "baseline"):
        raise NeurohoverError(f"unknown prototype {brief(seed)}: allowed zero, baseline")
    if seed == "zero":
        return Policy(topology, zero_genome(topology), {"prototype": "zero"})
    genome = slp_baseline_genome() if topology == "slp" else mlp_baseline_genome()
    return Policy(topology, genome, {"prototype": "baseline"})


def policy_to_dict(policy: Policy) -> dict:
    return {"topology": policy.topology, "genome": policy.genome.tolist(), **policy.metadata}


def policy_from_dict(d: dict, source: str = "policy") -> Policy:
    """Build a policy from a dict in the policy-file format."""
    if not isinstance(d, dict):
        raise NeurohoverError(f"{source}: a policy must be a JSON object with keys 'topology' and 'genome'")
    missing = [k for k in ("topology", "genome") if k not in d]
    if missing:
        raise NeurohoverError(f"{source}: missing key(s) {', '.join(missing)}; a policy file needs 'topology' (slp|mlp) and 'genome'")
    if not isinstance(d["topology"], str) or d["topology"] not in TOPOLOGIES:
        raise NeurohoverError(f"{source}: unknown topology {brief(d['topology'])}: allowed {', '.join(TOPOLOGIES)}")
    if not isinstance(d["genome"], list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in d["genome"]):
        raise NeurohoverError(f"{source}: 'genome' must be a list of numbers")
    try:
        metadata = {k: v for k, v in d.items() if k not in ("topology", "genome")}
        return Policy(d["topology"], np.array(d["genome"], dtype=float), metadata)
    except NeurohoverError as err:
        raise NeurohoverError(f"{source}: {err}") from None


def refuse_own_act(policies: Sequence[Policy], what: str = "flown") -> None:
    """Refuse a :class:`Policy` subclass with an ``act`` of its own where the policy is ``what`` (flown by the kernel, or
    saved): the kernel flies the genome, and a file holds it, never a Python ``act``, so a subclass's own act was ignored
    by evaluate, run_test and save_policy, without a word, while ``p.act`` gave other actions (T33-B11)."""
    for p in policies:
        if type(p).act is not Policy.act:
            raise NeurohoverError(
                f"policy of type {type(p).__name__!r} is not allowed: it has an act of its own, which is never {what} (the kernel flies "
                "the genome); fly your own act with neurohover.integrations.flying.evaluate_callable, or give a plain Policy"
            )


def check_padding(kinds: np.ndarray, genomes: np.ndarray, kind_numbers: dict[str, int]) -> None:
    """Refuse a kernel table's row whose genes past its kind's genome (``kind_numbers``: topology to kind) are not zero,
    as :meth:`~neurohover.evaluate.PolicyTable.from_policies` pads them: an MLP row declared an SLP (kinds [0, 0]) flew
    as one, its genes 40 and 41 unread (T33-B10)."""
    for topology, number in kind_numbers.items():  # a quick look first: evolution builds a table every generation
        rows = kinds == number
        if GENOME_LENGTH[topology] < genomes.shape[1] and genomes[rows, GENOME_LENGTH[topology] :].any():  # NaN too
            break
    else:
        return  # every padding gene zero
    lengths = np.zeros(max(kind_numbers.values()) + 1, dtype=np.int64)
    for topology, number in kind_numbers.items():
        lengths[number] = GENOME_LENGTH[topology]
    padded = np.arange(genomes.shape[1]) >= lengths[kinds][:, None]
    rows, genes = np.nonzero(padded & (genomes != 0))  # NaN too
    if rows.size:
        row, gene = int(rows[0]), int(genes[0])
        topology = next(t for t, number in kind_numbers.items() if number == kinds[row])
        raise NeurohoverError(
            f"PolicyTable row {row} is not allowed: its kind {int(kinds[row])} ({topology}) reads genes 0..{GENOME_LENGTH[topology] - 1}, but its gene "
            f"{gene} is {brief(float(genomes[row, gene]))}, not the zero that pads an {topology} genome: give the row its genome's kind (from_policies does)"
        )


def frozen(array: np.ndarray, given: object) -> np.ndarray:
    """``array`` made read-only, copied first where it shares memory with ``given`` (the caller's array, from which it
    was made) and that memory can still be written: freezing it would freeze the caller's array, or leave a way round
    the checks made (a PolicyTable row made an SLP after its padding check flew as one; T35-B01)."""
    if isinstance(given, np.ndarray) and np.may_share_memory(array, given) and (given.flags.writeable or not given.flags.owndata):
        array = array.copy()
    array.setflags(write=False)
    return array


def genome_rows(genomes: object, topology: str) -> np.ndarray:
    """``genomes`` as a float64 array (P >= 1, the topology's genome length), for
    :meth:`~neurohover.evaluate.PolicyTable.from_genomes`, or a clear error. Non-finite genes are taken (that table flies
    an optimiser's diverged sample, which crashes at once)."""
    _check_topology(topology)  # an array was NumPy's "truth value is ambiguous" (T16-12)
    n = GENOME_LENGTH[topology]
    try:
        raw = np.asarray(genomes)
    except (TypeError, ValueError, OverflowError):  # rows of unequal length were NumPy's "inhomogeneous shape" (T34-B02)
        raise NeurohoverError(f"{topology} genomes={brief(genomes)} are not allowed: give an array of real numbers (P, {n}), rows of equal length") from None
    # text was NumPy's ValueError, complex numbers lost their imaginary part (fifth trial), a mask was dropped (T16-9)
    if raw.dtype.kind not in "iuf" or isinstance(genomes, np.ma.MaskedArray):
        what = "a masked array" if isinstance(genomes, np.ma.MaskedArray) else raw.dtype
        raise NeurohoverError(f"{topology} genomes of {what} are not allowed: give an array of real numbers (P, {n})")
    g = raw.astype(float)
    if g.ndim != 2 or g.shape[1] != n or g.shape[0] == 0:
        raise NeurohoverError(f"{topology} genomes must be an array of shape (P >= 1, {n}), got {g.shape}")
    return g


def load_policy(source: str | Path) -> Policy:
    """Load a policy file (JSON, or the authors' ``.net`` format: :mod:`neurohover.netfile`), or
    the baseline policy for the text ``"baseline"``; a path (``Path("baseline")``) is always read as a file."""
    if not isinstance(source, (str, os.PathLike)):
        raise NeurohoverError(f"policy source {source!r} is not allowed: give a policy file's path or 'baseline'")
    if isinstance(source, str) and source == "baseline":  # Path('baseline') was the built-in too, not the file (T54-B09)
        return baseline_policy()
    from .paths import input_file

    path = input_file(source, "policy file", "policy file (JSON, an authors' .net file, or 'baseline')")  # the one check of a file read
    net = path.suffix.lower() == ".net"  # in any case, as the .json suffix is taken: p.NET was read as JSON (T32-B21)
    name = f"{'network' if net else 'policy'} file {str(path)!r}"
    try:
        text = utf8_text(path.read_bytes(), name, "a network file" if net else "a policy file")
    except OSError as err:
        raise NeurohoverError(f"{name} cannot be read ({err.strerror or type(err).__name__})") from None
    except NeurohoverError:
        _refuse_other_kind(path, name, net)
        raise
    if net:
        from .netfile import policy_from_net

        return policy_from_net(text, name)
    from .jsontext import parse_json

    try:
        policy = policy_from_dict(parse_json(text, name), name)
    except NeurohoverError:
        _refuse_other_kind(path, name, net)
        raise
    problem = record_problem(policy.metadata)  # its record of its run against itself: a budget of -5 or a stop reason 'zzz' was taken (T23-11)
    if problem:
        raise NeurohoverError(f"{name}: {problem}")
    return policy


def _refuse_other_kind(path: Path, name: str, net: bool) -> None:
    """Where a file load_policy cannot read is a neurohover file of another kind, say so: a results store was "must be
    UTF-8 text", a compete summary "missing key(s) topology, genome" (trial 30). Looked at only once the read failed."""
    from .filekinds import held_kind

    kind = None if net else held_kind(path)
    if kind not in (None, "a policy file"):
        allowed = "give a policy file (as evolve --out writes it), an authors' .net file or 'baseline'"
        raise NeurohoverError(f"{name} is {kind}, not a policy file: {allowed}") from None


def record_problem(metadata: dict) -> str:
    """What in a policy's ``metadata`` (its record of the run that evolved it) contradicts itself, by the first of
    :data:`RECORD_CHECKS` that finds something ('' when none does): :func:`load_policy` refuses a file of such a record,
    and :func:`save_policy` refuses to write one (T24-03)."""
    for check in RECORD_CHECKS.values():
        problem = check(metadata)
        if problem:
            return problem
    return ""


def utf8_text(data: bytes, name: str, what: str) -> str:
    """``data`` (a file's bytes) as UTF-8 text, after a byte-order mark if any, or a NeurohoverError saying that ``what``
    must be UTF-8 and where the first other byte is, in the words of the configs' (T19-15): a policy file or manifest of
    bytes ff fe was "is not valid JSON: 'utf-8' codec ..." or "Expecting value" (T20-08)."""
    body = data.removeprefix(b"\xef\xbb\xbf")  # the place counts from after a byte-order mark
    try:
        return body.decode("utf-8")
    except UnicodeDecodeError as err:
        start = err.start
        line, column = body.count(b"\n", 0, start) + 1, len(body[body.rfind(b"\n", 0, start) + 1 : start].decode()) + 1
        raise NeurohoverError(
            f"{name} cannot be read: {what} must be UTF-8 text, and byte {body[start]:#04x} at line {line}, column {column} is not (save it as UTF-8)"
        ) from None


#: A policy file's suffix (in any case: P.JSON is taken, as model files and flight data take theirs).
POLICY_SUFFIX = ".json"


def check_json_policy_name(path: object, option: str, ends: tuple[str, ...] = ()) -> None:
    """Refuse a name a policy file may not be written under, naming it as ``option``: evolve checks its ``--out`` with
    this before it evolves (refused only at the save, the run was lost), :func:`save_policy` before it writes.

    Taken: a name ending ``.json``, in any case (``p.json``, ``P.JSON``), but for the end below. Refused:

    * ``.net`` (any case): :func:`load_policy` reads it as the authors' format, so the JSON written could not be read back (third trial);
    * any other suffix, or none (``f.npz``, ``q.txt``, ``p``): flight data and other files were overwritten by a policy
      (T24-01), as learn-model --out and fly --record refuse theirs (T23-16, T21-09);
    * a name ending ``.checkpoint.json`` or ``.history.csv`` (any case): what evolve writes beside another run's
      ``--out FILE`` (``FILE.checkpoint.json``, ``FILE.history.csv``), which a policy overwrote, and that run could no longer
      be resumed (T24-01). A policy named ``x.checkpoint.json`` is refused with them: its name cannot be told from theirs.

    A name too long for the file system, it or it with the longest of ``ends`` (evolve's ``FILE.checkpoint.json``
    beside it), is refused first (:func:`neurohover.paths.checked_path`): it was a bare "File name too long", and a
    name suggested for one without a suffix was then too long for the run's history file (T29-A01).

    What is no path, ``''``, a name ending in a slash and a directory are left to :func:`neurohover.paths.output_file`
    to refuse, in its words."""
    from .paths import checked_path, path_text

    text = path_text(path)
    if not isinstance(text, str) or text == "" or text.endswith(("/", os.sep)):
        return
    if Path(checked_path(text, option, ends=ends)).is_dir():
        return
    if Path(text).suffix.lower() == ".net":
        raise NeurohoverError(
            f"{option} {text!r}: a policy is written as JSON, which load_policy would misread under the .net suffix "
            "(the authors' format); give a .json name, or write the authors' format with netfile.policy_to_net"
        )
    from .filekinds import refuse_run_file_name, refuse_suffix

    refuse_run_file_name(text, option)  # another run's checkpoint or history was overwritten by a policy (T24-01)
    # f.npz, q.txt: flight data and other files were overwritten (T24-01)
    refuse_suffix(text, option, (POLICY_SUFFIX,), "a policy file is JSON", f"policy{POLICY_SUFFIX}", ends)


def save_policy(policy: Policy, path: str | Path, **metadata) -> Path:
    """Write ``policy`` (and extra metadata: strict JSON values under keys of their own) as a JSON policy file; returns the path.

    The name is checked by :func:`check_json_policy_name` (a name ending .json, not another run's checkpoint or history;
    T24-01), the record by :data:`RECORD_CHECKS` as :func:`load_policy` checks it (T24-03): what is written loads."""
    from .jsontext import json_text, plain_json, strict_json, unwritable_key
    from .paths import output_file, writing

    if not isinstance(policy, Policy):
        raise NeurohoverError(f"policy={policy!r:.60} is not allowed: give a Policy (load_policy('baseline') for the baseline's)")
    check_json_policy_name(path, "policy file")
    refuse_own_act([policy], "saved")  # a file holds the genome: a subclass's own act was lost (T33-B11)
    check_genome(policy.genome, policy.topology)  # a genome made writable and given an inf blamed the metadata (T28-B03)
    data = policy_to_dict(policy)
    for given, what in ((policy.metadata, "policy metadata"), (metadata, "metadata")):
        taken = sorted({"topology", "genome"} & set(given))  # the policy's metadata may be updated, its network not
        if taken:  # they would overwrite the policy itself (second trial), from its own metadata edited in place too (T28-B05)
            raise NeurohoverError(f"{what} key(s) {', '.join(taken)} are the policy's own: give the metadata other names")
    data.update(metadata)
    refuse_non_text_keys(data, "policy")  # {1: 2} came back as {'1': 2} (T28-B14)
    try:  # json_text: what load_policy reads back (x=10**400 was written, then refused; T28-B14); NumPy numbers as
        text = json_text(data, indent=1, default=plain_json) + "\n"  # flight data's metadata takes them (T36-B08)
    except (TypeError, ValueError, RecursionError) as err:  # an object, or a NaN that other JSON readers refuse
        bad = unwritable_key(data)  # the entry named, as the model's stats and flight data's metadata name it (T36-B08)
        shown = f", not {key_text(bad)}={brief(data[bad])}" if isinstance(bad, str) else ""
        raise NeurohoverError(f"policy metadata must be strict JSON values (numbers finite){shown}: {err}") from None
    problem = record_problem({k: v for k, v in strict_json(text).items() if k not in ("topology", "genome")})  # as written
    if problem:  # T24-03: seed=-1 or budget=-5 was written, and load_policy then refused the file
        shown = repr(os.fspath(path)) if isinstance(path, (str, os.PathLike)) else brief(path)  # as load_policy names the file
        raise NeurohoverError(f"policy file {shown}: {problem} (load_policy would refuse the file; nothing is written)")
    path = output_file(path, "policy file", kind="a policy file")  # refuses '', a directory and a device; makes missing parents
    with writing(path, "policy file") as partial:
        partial.write_text(text, encoding="utf-8")
    return path
