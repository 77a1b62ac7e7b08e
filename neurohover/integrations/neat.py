"""Topology evolution with NEAT (neat-python): networks whose structure evolves with their weights.

The paper (Section 3.1) reports that NEAT and AEONN "did not discover topologies that outperformed
the manually designed topology", without numbers. This module runs that claim: neat-python's
``Population`` (species, crossover, structural mutation) evolves feed-forward networks of the nine
state features the paper's networks see -> 4 actions, and every generation's genomes fly their episodes together in the
native vector environment (:func:`neurohover.integrations.flying.evaluate_callable`, the same
physics and the same (seed, episode) gust streams as the kernel), each network evaluated by a
compiled forward pass that is neat-python's ``FeedForwardNetwork.activate`` for a whole batch.

A generation's genomes each fly ``episodes`` fresh episodes (episode numbers continue across
generations, so no two generations meet the same gusts), their fitness is the mean return. The
run's champion is the genome of best fitness ever (neat-python's ``best_genome``); the budget counts
episodes, as every evolution run here does. neat-python draws from Python's global ``random``: the
run seeds it from ``seed`` and restores the caller's state afterwards, so a run is reproducible.

Example::

    from neurohover import get_task_family
    from neurohover.integrations.neat import evolve_topology

    result = evolve_topology(get_task_family("ghh08").mdp("train:0"), budget=20_000, seed=1)
    print(result.champion_fitness, result.nodes, result.connections)
"""

from __future__ import annotations

import copy
import functools
import graphlib
import math
import operator
import random
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from dataclasses import fields as dataclass_fields
from typing import Any

import numba as nb
import numpy as np

from ..errors import NeurohoverError, brief, finite_real, float64_of, whole_number
from ..evolution.config import check_budget
from ..evolution.fitness import FITNESS_SCALES, episode_fitness
from ..evolution.seeding import check_seed
from ..flightmeta import compared_by_value
from ..paths import temp_text_file
from ..sim.constants import ACTION_DIM, EPISODE_STEPS, OBS_NAMES
from ..tasks import MDP, TaskFamily

__all__ = [
    "ACTIVATIONS",
    "NEAT_TOPOLOGY",
    "NeatSettings",
    "TopologyResult",
    "evolve_topology",
    "forward",
    "genome_record",
    "network_of_record",
    "pack_networks",
]

#: An evolution variant's topology that evolves with NEAT (the experiments' name; its champion is stored so).
NEAT_TOPOLOGY = "neat"
MAX_POP, MAX_EPISODES_PER_GENOME = 100_000, 10_000  # sizes beyond any budget this machine flies
MAX_SPREAD = 100.0  # of a weight's or bias's mutation or start (neat-python clamps them to +-30)
#: neat-python's activation functions this forward pass computes, by id (its ``activations`` module, exactly).
ACTIVATIONS = ("identity", "tanh", "sigmoid", "clamped", "relu")
#: What a network sees: the nine state features of the paper's networks (Section 3.1), as the SLP and MLP do.
INPUTS = ("u", "v", "w", "x", "y", "z", "qx", "qy", "qz")
INPUT_INDEX = np.array([OBS_NAMES.index(name) for name in INPUTS])
N_INPUTS = len(INPUTS)


@dataclass(frozen=True)
class NeatSettings:
    """The NEAT run's settings (neat-python's config keys of the same meaning; the rest are its usual defaults).

    Attributes
    ----------
    pop_size : int
        Genomes per generation (>= 4).
    episodes : int
        Episodes each genome flies a generation.
    initial : {"full_direct", "unconnected"}
        The starting topology: every input to every output (an SLP), or none.
    activations : tuple of str
        Those a new node may take (the first is the default), of :data:`ACTIVATIONS`.
    node_add_prob, conn_add_prob, node_delete_prob, conn_delete_prob : float
        The chances of the structural mutations, per genome and generation.
    weight_mutate_power : float
        The spread of a weight's perturbation.
    bias_mutate_power : float
        The spread of a bias's perturbation.
    weight_mutate_rate : float
        The chance that each weight is perturbed in a mutation.
    activation_mutate_rate : float
        The chance that a node's activation is redrawn.
    replace_rate : float
        The chance that a weight or bias is drawn afresh from its initial spread instead of perturbed.
    compatibility_threshold : float
        The genome distance that separates species.
    weight_init_stdev, bias_init_stdev : float
        The initial spread of weights and biases (0: every genome starts as the zero network, as NE's zero prototype).
    start : {"random", "baseline"}
        neat-python's initial genomes, or every initial genome the baseline policy (the SLP's gains and
        biases on the direct connections, identity outputs), as the paper seeds its SLP and MLP; it needs
        ``initial = "full_direct"`` and ``"identity"`` among the activations.
    fitness : {"return", "inv-log-error"}
        A genome's fitness: its mean return, or its episodes' mean 1/ln(error) (FGHH's scale).
    """

    pop_size: int = 150
    episodes: int = 1
    initial: str = "full_direct"
    activations: tuple[str, ...] = ("tanh", "sigmoid", "identity")
    node_add_prob: float = 0.2
    conn_add_prob: float = 0.3
    node_delete_prob: float = 0.1
    conn_delete_prob: float = 0.2
    weight_mutate_power: float = 0.5
    weight_mutate_rate: float = 0.8
    bias_mutate_power: float = 0.2
    activation_mutate_rate: float = 0.1
    replace_rate: float = 0.1
    compatibility_threshold: float = 3.0
    weight_init_stdev: float = 0.5
    bias_init_stdev: float = 0.5
    start: str = "random"
    fitness: str = "return"

    @classmethod
    def of(cls, table: Mapping[str, Any]) -> NeatSettings:
        """Settings from a config's table (TOML lists as tuples); an unknown key refused by name (NeurohoverError)."""
        if not isinstance(table, Mapping):
            raise NeurohoverError(f"NEAT settings must be a table of NeatSettings' fields, got {type(table).__name__}")
        known = {f.name for f in dataclass_fields(cls)}
        unknown = sorted(set(table) - known)
        if unknown:
            raise NeurohoverError(f"unknown NEAT setting(s) {', '.join(map(repr, unknown))}: allowed {', '.join(sorted(known))}")
        values: dict[str, Any] = {k: tuple(v) if isinstance(v, list) else v for k, v in table.items()}
        return cls(**values)

    def __post_init__(self) -> None:  # a NeurohoverError (a ValueError) naming the value and what is allowed
        for name, low, high in (("pop_size", 4, MAX_POP), ("episodes", 1, MAX_EPISODES_PER_GENOME)):
            v = getattr(self, name)
            if not whole_number(v) or not low <= v <= high:  # NumPy's integers too: np.int64(4) "must be an integer" (T34-B12)
                raise NeurohoverError(f"{name}={brief(v)} must be an integer in {low}..{high}")
            object.__setattr__(self, name, operator.index(v))
        # text first: an array's `in` was NumPy's "truth value ... is ambiguous" (sixteenth trial)
        if not isinstance(self.initial, str) or self.initial not in ("full_direct", "unconnected"):
            raise NeurohoverError(f"initial={brief(self.initial)}: allowed full_direct or unconnected")
        if not isinstance(self.fitness, str) or self.fitness not in FITNESS_SCALES:
            raise NeurohoverError(f"fitness={brief(self.fitness)}: allowed {', '.join(FITNESS_SCALES)}")
        if not isinstance(self.start, str) or self.start not in ("random", "baseline"):
            raise NeurohoverError(f"start={brief(self.start)}: allowed random or baseline")
        acts = self.activations  # checked before any use: activations=5 was "'int' object is not iterable" (eleventh trial)
        names = isinstance(acts, (tuple, list)) and all(isinstance(a, str) for a in acts)
        if not names or not acts or any(a not in ACTIVATIONS for a in acts) or len(set(acts)) != len(acts):
            raise NeurohoverError(f"activations={brief(acts)}: allowed a non-empty tuple of distinct names from {', '.join(ACTIVATIONS)}")
        object.__setattr__(self, "activations", tuple(acts))
        if self.start == "baseline" and (self.initial != "full_direct" or "identity" not in self.activations):
            raise NeurohoverError("start='baseline' needs initial='full_direct' and 'identity' among the activations (the baseline is linear)")
        probs = ("node_add_prob", "conn_add_prob", "node_delete_prob", "conn_delete_prob", "activation_mutate_rate", "replace_rate", "weight_mutate_rate")
        for group, least, most, allowed in (  # (neat-python clamps weights and biases to +-30: a larger spread only saturates them)
            (probs, 0.0, 1.0, "a probability in [0, 1]"),
            (("weight_mutate_power", "bias_mutate_power", "compatibility_threshold"), None, MAX_SPREAD, f"a number in (0, {MAX_SPREAD:g}]"),
            (("weight_init_stdev", "bias_init_stdev"), 0.0, MAX_SPREAD, f"a number in [0, {MAX_SPREAD:g}]"),
        ):
            for name in group:  # NumPy's numbers too (np.float32(0.25) was "must be a probability"; T34-B12), stored as floats
                v = getattr(self, name)
                if not (finite_real(v) and (0.0 < v if least is None else least <= v) and v <= most):
                    raise NeurohoverError(f"{name}={brief(v)} must be {allowed}")
                object.__setattr__(self, name, float(v) + 0.0)  # -0.0 as 0.0


_CONFIG = """
[NEAT]
fitness_criterion     = max
fitness_threshold     = 1e30
no_fitness_termination = True
pop_size              = {pop_size}
reset_on_extinction   = True

[DefaultGenome]
activation_default      = {activation_default}
activation_mutate_rate  = {activation_mutate_rate}
activation_options      = {activations}
aggregation_default     = sum
aggregation_mutate_rate = 0.0
aggregation_options     = sum
bias_init_mean          = 0.0
bias_init_stdev         = {bias_init_stdev}
bias_max_value          = 30.0
bias_min_value          = -30.0
bias_mutate_power       = {bias_mutate_power}
bias_mutate_rate        = 0.7
bias_replace_rate       = {replace_rate}
compatibility_disjoint_coefficient = 1.0
compatibility_weight_coefficient   = 0.5
conn_add_prob           = {conn_add_prob}
conn_delete_prob        = {conn_delete_prob}
enabled_default         = True
enabled_mutate_rate     = 0.01
feed_forward            = True
initial_connection      = {initial}
node_add_prob           = {node_add_prob}
node_delete_prob        = {node_delete_prob}
num_hidden              = 0
num_inputs              = {n_inputs}
num_outputs             = {n_outputs}
response_init_mean      = 1.0
response_init_stdev     = 0.0
response_max_value      = 30.0
response_min_value      = -30.0
response_mutate_power   = 0.0
response_mutate_rate    = 0.0
response_replace_rate   = 0.0
weight_init_mean        = 0.0
weight_init_stdev       = {weight_init_stdev}
weight_max_value        = 30
weight_min_value        = -30
weight_mutate_power     = {weight_mutate_power}
weight_mutate_rate      = {weight_mutate_rate}
weight_replace_rate     = {replace_rate}

[DefaultSpeciesSet]
compatibility_threshold = {compatibility_threshold}

[DefaultStagnation]
species_fitness_func = max
max_stagnation       = 20
species_elitism      = 2

[DefaultReproduction]
elitism            = 2
survival_threshold = 0.2
"""


def neat_config(settings: NeatSettings):
    """neat-python's ``Config`` for ``settings`` (written to a temporary file, as neat-python reads one)."""
    import neat

    fields = {**asdict(settings), "activations": " ".join(settings.activations), "activation_default": settings.activations[0]}
    text = _CONFIG.format(**fields, n_inputs=N_INPUTS, n_outputs=ACTION_DIM)  # the template names the settings' fields
    with temp_text_file(text, "neat-python's config file") as path:  # neat-python's Config reads a file, by name only
        return neat.Config(neat.DefaultGenome, neat.DefaultReproduction, neat.DefaultSpeciesSet, neat.DefaultStagnation, path)


@compared_by_value  # == by value: arrays whole (T46-B08)
@dataclass(frozen=True, eq=False)
class PackedNetworks:
    """Feed-forward networks as flat arrays for :func:`forward`: per network its node evaluations in
    neat-python's order (``node_start``), per node its value slot, activation id, bias, response and
    incoming links (``link_start``), per link its source slot and weight. Slots 0..8 of a network
    are its inputs (:data:`INPUTS`); ``out_slot`` gives each network's 4 output slots."""

    node_start: np.ndarray
    node_slot: np.ndarray
    node_act: np.ndarray
    node_bias: np.ndarray
    node_resp: np.ndarray
    link_start: np.ndarray
    link_src: np.ndarray
    link_w: np.ndarray
    out_slot: np.ndarray
    n_slots: int


def pack_networks(genomes: Sequence, config) -> PackedNetworks:
    """Pack neat-python genomes into :class:`PackedNetworks` (via ``neat.nn.FeedForwardNetwork.create``). Internal:
    called with the genomes and config of a NEAT run (README, Python API, What is public)."""
    import neat

    node_start, node_slot, node_act, node_bias, node_resp = [0], [], [], [], []
    link_start, link_src, link_w, out_slot = [0], [], [], []
    width = N_INPUTS + 1
    nets = [neat.nn.FeedForwardNetwork.create(g, config) for g in genomes]
    for net in nets:
        width = max(width, N_INPUTS + len(net.node_evals) + ACTION_DIM)
    for net in nets:
        slots = {k: i for i, k in enumerate(net.input_nodes)}
        for node, act, _agg, bias, response, links in net.node_evals:
            slots[node] = len(slots)
            name = act.__name__.replace("_activation", "")
            if name not in ACTIVATIONS:
                raise NeurohoverError(f"activation {name!r} is not computed here: allowed {', '.join(ACTIVATIONS)}")
            node_slot.append(slots[node])
            node_act.append(ACTIVATIONS.index(name))
            node_bias.append(bias)
            node_resp.append(response)
            for src, w in links:
                link_src.append(slots[src])
                link_w.append(w)
            link_start.append(len(link_src))
        node_start.append(len(node_slot))
        # an output no node evaluation reaches reads as 0 (neat-python's values dict default is 0.0 too)
        out_slot.append([slots.get(k, width - 1) for k in net.output_nodes])
    i64 = np.int64
    return PackedNetworks(
        np.asarray(node_start, i64),
        np.asarray(node_slot, i64),
        np.asarray(node_act, i64),
        np.asarray(node_bias, float),
        np.asarray(node_resp, float),
        np.asarray(link_start, i64),
        np.asarray(link_src, i64),
        np.asarray(link_w, float),
        np.asarray(out_slot, i64).reshape(-1, ACTION_DIM),
        width,
    )


@nb.njit(cache=True)
def _forward(node_start, node_slot, node_act, node_bias, node_resp, link_start, link_src, link_w, out_slot, width, net_of_row, obs, out):
    values = np.zeros(width)
    for r in range(obs.shape[0]):
        n = net_of_row[r]
        values[:] = 0.0
        for i in range(obs.shape[1]):
            values[i] = obs[r, i]
        for j in range(node_start[n], node_start[n + 1]):
            s = 0.0
            for k in range(link_start[j], link_start[j + 1]):
                s += values[link_src[k]] * link_w[k]
            z = node_bias[j] + node_resp[j] * s
            a = node_act[j]
            if a == 1:  # tanh, as neat-python: tanh(2.5 z) clamped to +-60 first
                z = math.tanh(max(-60.0, min(60.0, 2.5 * z)))
            elif a == 2:  # sigmoid: 1 / (1 + exp(-5 z)), 5 z clamped to +-60
                z = 1.0 / (1.0 + math.exp(-max(-60.0, min(60.0, 5.0 * z))))
            elif a == 3:
                z = max(-1.0, min(1.0, z))
            elif a == 4:
                z = z if z > 0.0 else 0.0
            values[node_slot[j]] = z
        for m in range(out.shape[1]):
            out[r, m] = values[out_slot[n, m]]


def observation_batch(obs: object) -> np.ndarray:
    """``obs`` as a (B, 12) float array, or a NeurohoverError: a (12,) or (2, 5) array was an IndexError and NaN
    flew silently, where Policy.act refuses both (thirteenth trial, F19)."""
    try:
        raw = np.asarray(obs)
        batch = float64_of(raw) if raw.dtype.kind in "iuf" else None  # not text, booleans or complex; longdouble 1e400: inf (T37-B10)
    except (TypeError, ValueError):
        batch = None
    if batch is None or batch.ndim != 2 or batch.shape[1] != 12 or not np.all(np.isfinite(batch)):
        if batch is None:
            shown = brief(obs)
        else:  # an array's repr runs over lines: its shape, and whether it holds NaN or inf, say what is wrong
            shown = f"of shape {batch.shape}" + (" holding NaN or inf" if batch.size and not np.all(np.isfinite(batch)) else "")
        raise NeurohoverError(
            f"observations {shown} are not allowed: give a (B, 12) array of finite numbers, one row (u, v, w, x, y, z, p, q, r, qx, qy, qz) per helicopter"
        )
    return batch


def forward(packed: PackedNetworks, net_of_row: np.ndarray, obs: np.ndarray) -> np.ndarray:
    """The actions of network ``net_of_row[r]`` for observation row ``r`` (B, 12): shape (B, 4)."""
    if not isinstance(packed, PackedNetworks):  # None was an AttributeError (thirteenth trial, F19)
        raise NeurohoverError(f"packed={brief(packed)} is not allowed: give PackedNetworks (pack_networks, network_of_record)")
    p = packed
    obs = observation_batch(obs)
    rows = np.asarray(net_of_row)
    n_nets = len(p.node_start) - 1
    if rows.shape != (obs.shape[0],) or rows.dtype.kind not in "iu" or (rows.size and not (0 <= rows.min() and rows.max() < n_nets)):
        raise NeurohoverError(f"net_of_row={brief(net_of_row)} is not allowed: give one network index 0..{n_nets - 1} per observation row ({obs.shape[0]})")
    obs = obs[:, INPUT_INDEX]
    out = np.empty((obs.shape[0], ACTION_DIM))
    _forward(
        p.node_start, p.node_slot, p.node_act, p.node_bias, p.node_resp, p.link_start, p.link_src, p.link_w, p.out_slot, p.n_slots,
        np.ascontiguousarray(net_of_row, dtype=np.int64), np.ascontiguousarray(obs, dtype=np.float64), out,
    )  # fmt: skip
    return out


@dataclass
class TopologyResult:
    """A NEAT run: its champion (a neat-python genome) and its size, the config, and one row per generation."""

    champion: object
    champion_fitness: float
    nodes: int  # hidden and output nodes of the champion, enabled or not reached
    connections: int  # its enabled connections
    episodes: int
    generations: int
    config: object
    history: list[dict] = field(default_factory=list)

    @functools.cached_property
    def packed(self) -> PackedNetworks:
        """The champion packed for :func:`forward` once (``act`` runs every control step of a flight)."""
        return pack_networks([self.champion], self.config)

    def act(self, obs: np.ndarray) -> np.ndarray:
        """The champion's actions for a batch of observations (B, 12) -> (B, 4)."""
        batch = observation_batch(obs)
        return forward(self.packed, np.zeros(len(batch), dtype=np.int64), batch)


def genome_record(genome) -> tuple[float, ...]:
    """A genome as a flat tuple of floats (what a stored result holds): the node count, then per node its key,
    bias, response and activation id (:data:`ACTIVATIONS`), then per enabled connection its input, output and weight.
    :func:`network_of_record` flies it again, to the same bits."""
    if not isinstance(getattr(genome, "nodes", None), Mapping) or not isinstance(getattr(genome, "connections", None), Mapping):
        raise NeurohoverError(f"genome={brief(genome)} is not allowed: give a neat-python genome (a TopologyResult's champion)")  # thirteenth trial, F19
    out: list[float] = [float(len(genome.nodes))]
    for key, node in genome.nodes.items():  # in the genome's order, so that a node's inputs sum in the same order
        out += [float(key), float(node.bias), float(node.response), float(ACTIVATIONS.index(node.activation))]
    for (i, o), conn in genome.connections.items():
        if conn.enabled:
            out += [float(i), float(o), float(conn.weight)]
    return tuple(out)


#: The most a NEAT record's bias, response or weight may be: neat-python's clamp of all three (_CONFIG), so a record
#: it evolved always holds them; 1e308 flew NaN, and a node key of 0.5 was cut to 0 (T32-B16).
MAX_NEAT_VALUE, MAX_NODE_KEY = 30.0, 2**53


def _check_record_network(record: Sequence[float], n_nodes: int) -> None:
    """A record's nodes and connections as neat-python builds them, checked: whole, unrepeated node keys 0..2**53 with
    the 4 outputs 0..3 among them, values within +-30, and each connection once, from an input (-9..-1) or a node, to
    a node, and no cycle among them. A record without nodes was neat-python's KeyError 0, a connection from node 55 its
    KeyError 55 (T32-B15); a repeated node or connection kept the last (T32-B16); a cycle's nodes were dropped (T34-B09)."""
    name = "a NEAT record's {} {} is not allowed: {}"
    keys = [record[1 + 4 * j] for j in range(n_nodes)]
    for key in keys:
        if not (float(key).is_integer() and 0 <= key <= MAX_NODE_KEY):
            raise NeurohoverError(name.format("node key", brief(key), f"allowed a whole number in 0..2**53 (outputs 0..{ACTION_DIM - 1})"))
    if len(set(keys)) < len(keys) or not set(range(ACTION_DIM)) <= set(keys):
        raise NeurohoverError(name.format("node keys", brief(keys), f"give each node once, the outputs 0..{ACTION_DIM - 1} among them"))
    values = [(what, record[1 + 4 * j + k]) for j in range(n_nodes) for k, what in ((1, "bias"), (2, "response"))]
    values += [("weight", record[j + 2]) for j in range(1 + 4 * n_nodes, len(record), 3)]
    for what, v in values:
        if abs(v) > MAX_NEAT_VALUE:
            raise NeurohoverError(name.format(what, brief(v), f"allowed numbers in [-{MAX_NEAT_VALUE:g}, {MAX_NEAT_VALUE:g}] (neat-python's clamp)"))
    seen: set[tuple[float, float]] = set()
    for j in range(1 + 4 * n_nodes, len(record), 3):
        i, o = record[j], record[j + 1]
        if (i, o) in seen or not (i in keys or (float(i).is_integer() and -N_INPUTS <= i <= -1)) or o not in keys:
            why = "it is listed twice" if (i, o) in seen else f"give it once, from an input -{N_INPUTS}..-1 or a node of the record to a node"
            raise NeurohoverError(name.format("connection", f"{brief(i)} -> {brief(o)}", why))
        seen.add((i, o))
    cycle = _cycle_of(seen)
    if cycle:  # neat-python's FeedForwardNetwork dropped every node on it, and the record flew without them (T34-B09)
        path = " -> ".join(brief(int(k)) for k in cycle)
        raise NeurohoverError(name.format("connection cycle", path, "give a feed-forward network, as NEAT evolves here (a cycle's nodes flew as absent)"))


def _cycle_of(links: set[tuple[float, float]]) -> list[float]:
    """A cycle of the directed graph ``links`` (its nodes from the smallest, the first repeated last: ``[0, 0]`` for a
    self-loop), or []: the standard library's topological sort finds it."""
    order: graphlib.TopologicalSorter = graphlib.TopologicalSorter()
    for i, o in sorted(links):
        order.add(o, i)  # o is computed after i
    try:
        order.prepare()
    except graphlib.CycleError as err:
        cycle = err.args[1][:-1]  # in the links' direction
        first = cycle.index(min(cycle))
        return cycle[first:] + cycle[: first + 1]
    return []


def network_of_record(record: Sequence[float]) -> PackedNetworks:
    """The network of a :func:`genome_record`, packed for :func:`forward` (neat-python's evaluation order)."""
    import neat

    # [] was an IndexError, None a TypeError (thirteenth trial, F19)
    # np.array(3) has no len() (sixteenth trial): an array must be 1-D
    listed = (isinstance(record, Sequence) and not isinstance(record, (str, bytes))) or (isinstance(record, np.ndarray) and record.ndim == 1)
    if not listed or len(record) == 0 or not all(finite_real(v) for v in record):
        raise NeurohoverError(f"record={brief(record)} is not allowed: give a genome_record (a non-empty list of finite numbers)")
    n_nodes = int(record[0])
    if n_nodes < 0 or not float(record[0]).is_integer():
        raise NeurohoverError(f"a NEAT record's node count {brief(record[0])} is not allowed: give a whole number >= 0")
    if len(record) < 1 + 4 * n_nodes or (len(record) - 1 - 4 * n_nodes) % 3:  # before the ids: 99 blamed them (T47-B16)
        fits = [n for n in range(ACTION_DIM, (len(record) - 1) // 4 + 1) if (len(record) - 1 - 4 * n) % 3 == 0]  # of the outputs at least
        holds = f"holds {', '.join(map(str, fits[:5]))}{', ...' if len(fits) > 5 else ''} nodes" if fits else f"holds no {ACTION_DIM} nodes or more"
        raise NeurohoverError(
            f"a NEAT record's node count {brief(record[0])} is not allowed: a record of {len(record)} numbers (the count, then 4 per node and 3 per "
            f"connection) does not hold {brief(record[0])} nodes and whole connections; it {holds}"
        )
    if not all(float(record[j]).is_integer() and 0 <= record[j] < len(ACTIVATIONS) for j in range(4, 1 + 4 * n_nodes, 4)):
        raise NeurohoverError(f"record={brief(record)} is not allowed: its activation ids must be whole numbers 0..{len(ACTIVATIONS) - 1}")
    config = neat_config(NeatSettings(activations=ACTIVATIONS))
    _check_record_network(record, n_nodes)
    genome = neat.DefaultGenome(0)
    gc = config.genome_config
    for j in range(n_nodes):
        key, bias, response, act = record[1 + 4 * j : 5 + 4 * j]
        node = gc.node_gene_type(int(key))
        node.bias, node.response, node.activation, node.aggregation = float(bias), float(response), ACTIVATIONS[int(act)], "sum"
        genome.nodes[int(key)] = node
    for innovation, j in enumerate(range(1 + 4 * n_nodes, len(record), 3)):
        i, o, w = record[j : j + 3]
        conn = gc.connection_gene_type((int(i), int(o)), innovation=innovation)  # (a number neat-python 2 requires; unused in flight)
        conn.weight, conn.enabled = float(w), True
        genome.connections[(int(i), int(o))] = conn
    return pack_networks([genome], config)


def seed_baseline(genome, config) -> None:
    """Make ``genome`` (fully connected inputs -> outputs) the baseline policy: gains on its direct
    connections, the biases on its outputs, identity outputs, every other weight 0."""
    from ..policies import BASELINE_BIASES, BASELINE_GAINS

    gains = {(-1 - INPUTS.index(inp), int(action[1]) - 1): g for (action, inp), g in BASELINE_GAINS.items()}
    for key, conn in genome.connections.items():
        conn.weight = float(gains.get(key, 0.0))
        conn.enabled = True
    for k in config.genome_config.output_keys:
        node = genome.nodes[k]
        node.bias, node.response, node.activation, node.aggregation = float(BASELINE_BIASES[k]), 1.0, "identity", "sum"


def evolve_topology(
    mdps: MDP | Sequence[MDP] | TaskFamily,
    *,
    budget: int,
    seed: int = 0,
    settings: NeatSettings | Mapping[str, Any] | None = None,
    n_steps: int = EPISODE_STEPS,
) -> TopologyResult:
    """Evolve a network's topology and weights with NEAT on ``mdps`` for ``budget`` episodes.

    Each genome of a generation flies ``settings.episodes`` episodes (on the MDPs in turn when there are
    several, as a run over training MDPs; each on a fresh MDP from G when ``mdps`` is a task family, drawn
    from ``seed``); fitness is its mean return, or on ``settings.fitness = "inv-log-error"`` the mean of its
    episodes' 1/ln(error) (:mod:`neurohover.evolution.fitness`, FGHH's scale). ``budget`` is an integer in 1..10**10
    episodes (:data:`~neurohover.evolution.config.MAX_BUDGET`, as for ``evolve``) and at least one generation's.
    """
    import neat

    from .flying import evaluate_callable

    s = NeatSettings.of(settings) if isinstance(settings, Mapping) else settings if settings is not None else NeatSettings()
    if not isinstance(s, NeatSettings):
        raise NeurohoverError(f"settings must be a NeatSettings or a dict of its fields, got {type(settings).__name__}")
    seed = check_seed(seed)
    family = mdps if isinstance(mdps, TaskFamily) else None
    mdp_rng = np.random.default_rng([int(seed), 0x4E4]) if family is not None else None  # the MDPs from G, apart from the gusts
    mdp_list: list = [mdps] if isinstance(mdps, MDP) else []
    if isinstance(mdps, Sequence) and not isinstance(mdps, (str, bytes)):  # None, 3, np.array(3): list() raised TypeError (sixteenth trial)
        mdp_list = list(mdps)
    if family is None and (not mdp_list or not all(isinstance(m, MDP) for m in mdp_list)):
        raise NeurohoverError(f"mdps={brief(mdps)} is not allowed: mdps must be one MDP or a non-empty sequence of MDPs of one task family, or a TaskFamily")
    check_budget(budget)  # evolve's range first: 10**13 ran on without a cap (sixteenth trial)
    if budget < s.pop_size * s.episodes:
        raise NeurohoverError(f"budget={budget!r} is out of range: allowed an integer >= one generation ({s.pop_size * s.episodes} episodes)")
    config = neat_config(s)
    history: list[dict] = []
    flown = 0
    best: list = [None, -math.inf]  # the genome of the best estimate ever, copied when told (an elite is evaluated again)

    def fitness(genomes, cfg) -> None:
        nonlocal flown
        packed = pack_networks([g for _, g in genomes], cfg)
        n = len(genomes) * s.episodes
        # episode j of the generation: genome j // episodes, MDP j % len(mdps) (or a fresh one from G), gust stream (seed, flown + j)
        rows = [family.sample(mdp_rng) for _ in range(n)] if family is not None else [mdp_list[j % len(mdp_list)] for j in range(n)]
        ev = evaluate_callable(
            lambda obs, idx: forward(packed, idx // s.episodes, obs), rows, seed=seed, first_episode=flown, n_steps=n_steps, obs_dtype="float64", indexed=True
        )
        returns = np.asarray(ev.returns).reshape(len(genomes), s.episodes)
        scores = episode_fitness(returns, s.fitness)
        for (_, g), r in zip(genomes, scores, strict=True):
            g.fitness = float(r.mean())
            if g.fitness > best[1]:
                best[:] = [copy.deepcopy(g), g.fitness]
        flown += n
        history.append({"generation": len(history), "episodes": flown, "best": float(scores.mean(axis=1).max()), "crashed": int(np.sum(ev.crashed))})

    state = random.getstate()
    random.seed(seed)
    try:
        population = neat.Population(config)
        if s.start == "baseline":
            for genome in population.population.values():
                seed_baseline(genome, config)
        generations = max(1, int(budget) // (s.pop_size * s.episodes))
        try:
            population.run(fitness, generations)
        except RuntimeError as err:  # neat-python's own refusals mid-run (e.g. more species than the population holds)
            raise NeurohoverError(f"neat-python stopped the run: {err} (a larger pop_size or compatibility_threshold avoids it)") from None
    finally:
        random.setstate(state)
    champion, champion_fitness = best
    enabled = sum(1 for c in champion.connections.values() if c.enabled)
    return TopologyResult(champion, float(champion_fitness), len(champion.nodes), enabled, flown, len(history), config, history)
