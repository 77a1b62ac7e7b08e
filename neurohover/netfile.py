"""The authors' network files (``.net``, their ``eonn`` package's format) as neurohover policies.

The paper's authors published their policies as text files with one gene per line:
``n ID POSITION FUNCTION BIAS`` for a node (position 0 input, 1 output, 2 hidden; function 0 sum,
1 sigmoid) and ``s SOURCE DEST WEIGHT`` for a link, optionally after ``#`` comment lines. Two
topologies occur: the paper's MLP (Figure 1; their GHH-08/09 policies) and the SLP of their FGHH
generics. The nodes are numbered as below; the mapping to our genome orders (docs/model.md,
Policies) is fixed by the node and link names, so ``load_policy("mdp0.net")`` flies one of their
policies exactly as their simulator did (the returns in a file's ``# reward`` comment are met
within the noise).

==========  =====================================================  ===========================
node ids    MLP                                                    SLP
==========  =====================================================  ===========================
1..12       inputs u, v, w, x, y, z, p, q, r, qx, qy, qz           the same inputs
            (p, q, r are unused)
13..16      position sigmoids hy, hx, hz; linear sum L1            outputs a1..a4 (sums),
                                                                   each linked from the 9 used
                                                                   inputs
17..27      sums L2..L4, sigmoids S1..S4, outputs a1..a4           (none)
==========  =====================================================  ===========================
"""

from __future__ import annotations

import re

import numpy as np

from .errors import NeurohoverError, brief
from .policies import INPUT_NAMES, MLP_BIAS_NAMES, MLP_WEIGHT_NAMES, Policy

_INPUTS = {1: "u", 2: "v", 3: "w", 4: "x", 5: "y", 6: "z", 7: "p", 8: "q", 9: "r", 10: "qx", 11: "qy", 12: "qz"}
_ACTIONS = ("a1", "a2", "a3", "a4")
#: Node id -> name, per topology.
NODE_NAMES = {
    "mlp": {**_INPUTS, **{13 + i: name for i, name in enumerate(MLP_BIAS_NAMES)}},
    "slp": {**_INPUTS, **{13 + i: name for i, name in enumerate(_ACTIONS)}},
}
NODE_IDS = {topology: {name: i for i, name in names.items()} for topology, names in NODE_NAMES.items()}
SLP_LINK_NAMES = tuple(f"{i}->{a}" for a in _ACTIONS for i in INPUT_NAMES)  # row by row, as the SLP genome
_LINKS = {"mlp": MLP_WEIGHT_NAMES, "slp": SLP_LINK_NAMES}
_BIASES = {"mlp": MLP_BIAS_NAMES, "slp": _ACTIONS}
_DESCRIPTION = {"mlp": "the paper's MLP (ids 1-27)", "slp": "an SLP (ids 1-16)"}


def _role(topology: str, name: str) -> tuple[int, int]:
    """(eonn position, eonn function) of a non-input node: outputs 1, hidden 2; sigmoids 1, sums 0."""
    position = 1 if name.startswith("a") else 2
    function = 1 if topology == "mlp" and name[0] in "hS" else 0
    return position, function


#: A number as the authors' files write one: ASCII digits, a sign, a point and an exponent; 'nan' and 'inf' match so that they are
#: named as not finite. float() and int() also read '1_0' as 10 and other scripts' digits (thirteenth trial F2; fourteenth T14-20).
_NUMBER = re.compile(r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf|infinity|nan)", re.IGNORECASE)
_INTEGER = re.compile(r"[+-]?[0-9]+")


def _integer(text: str, what: str) -> int:
    """A node id, position or function: an integer in plain ASCII digits."""
    if not _INTEGER.fullmatch(text):
        raise ValueError(f"{what} {text!r} is not allowed: give an integer in ASCII digits (no '_')")
    if len(text.lstrip("+-")) > 18:  # past 4,300 digits int() said "use sys.set_int_max_str_digits()" (T36-A05)
        raise ValueError(f"{what} {brief(text)} is not allowed: give an integer of at most 18 digits (node ids, positions and functions are small)")
    return int(text)


def _finite(text: str, what: str) -> float:
    """A bias or weight: a finite number (a NaN was refused later by Policy, without the file and line)."""
    if not _NUMBER.fullmatch(text):
        raise ValueError(f"{what} {text!r} is not allowed: give a decimal number in ASCII digits (like +0.0367 or -1.5e-3; no '_')")
    value = float(text)
    if not np.isfinite(value):
        raise ValueError(f"{what} {text} is not a finite number")
    return value


def _parse_lines(text: str, source: str):
    """Node and link lines with their line numbers, and the comment lines."""
    nodes: dict[int, tuple[int, int, float, int, str]] = {}
    links: dict[tuple[int, int], tuple[float, int, str]] = {}
    comments = []
    for number, line in enumerate(text.splitlines(), 1):
        fields = line.split()
        if not fields:
            continue
        if fields[0].startswith("#"):
            comments.append(line.lstrip("# ").strip())
            continue
        try:
            if not line.isascii():  # int() and float() read other scripts' digits: '٣' was weight 3 (thirteenth trial, F2)
                raise ValueError("characters other than ASCII are not allowed: give numbers in ASCII digits")
            if fields[0] == "n" and len(fields) == 5:
                node = _integer(fields[1], "node id")
                if node in nodes:  # a second definition would silently replace the first
                    raise ValueError(f"node {node} is defined again (first on line {nodes[node][3]})")
                nodes[node] = (_integer(fields[2], "position"), _integer(fields[3], "function"), _finite(fields[4], "bias"), number, line.strip())
            elif fields[0] == "s" and len(fields) == 4:
                link = (_integer(fields[1], "source node"), _integer(fields[2], "destination node"))
                if link in links:
                    raise ValueError(f"link {link[0]} -> {link[1]} is given again (first on line {links[link][1]})")
                links[link] = (_finite(fields[3], "weight"), number, line.strip())
            else:
                raise ValueError("expected 'n ID POSITION FUNCTION BIAS' or 's SOURCE DEST WEIGHT'")
        except ValueError as err:
            raise NeurohoverError(f"{source}, line {number}: {err}: {line.strip()!r}") from None
    return nodes, links, comments


def _topology(nodes: dict, source: str) -> str:
    """``slp`` when node 13 is an output (an SLP's a1), else ``mlp`` (node 13 is the MLP's hidden hy)."""
    topology = "slp" if 13 in nodes and nodes[13][0] == 1 else "mlp"
    for node, (_, _, _, number, line) in sorted(nodes.items()):
        if node not in NODE_NAMES[topology]:
            raise NeurohoverError(
                f"{source}, line {number}: node {node} is not a node of {_DESCRIPTION[topology]}; "
                f"known topologies: {_DESCRIPTION['mlp']}, {_DESCRIPTION['slp']}: {line!r}"
            )
    return topology


def policy_from_net(text: str, source: str = "network file") -> Policy:
    """Parse an authors' ``.net`` network (MLP or SLP) into a :class:`Policy` (comments become metadata)."""
    if not isinstance(text, str):  # None, 5 or bytes were AttributeError and TypeError (sixth trial)
        raise NeurohoverError(f"{source}: {type(text).__name__} {text!r:.40} is not allowed: give the file's text (str)")
    nodes, links, comments = _parse_lines(text, source)
    topology = _topology(nodes, source)
    names = NODE_NAMES[topology]
    absent = [i for i in _INPUTS if i not in nodes]  # the authors' files list all twelve (fifth trial: none was accepted)
    if absent:
        raise NeurohoverError(f"{source}: not {_DESCRIPTION[topology]}: input node(s) {', '.join(map(str, absent))} missing ('n ID 0 0 +0.0000')")
    biases: dict[str, float] = {}
    for node, (pos, func, bias, number, line) in nodes.items():
        if node in _INPUTS:
            if (pos, func, bias) != (0, 0, 0.0):  # position 7, function 9 or a bias of 5 were read as a plain input, the bias dropped
                raise NeurohoverError(
                    f"{source}, line {number}: input node {node} ({names[node]}) must have position 0, function 0 and bias 0 "
                    f"(an input passes its reading on), not {pos}, {func} and {bias:g}: {line!r}"
                )
            continue
        if (pos, func) != _role(topology, names[node]):
            want = _role(topology, names[node])
            raise NeurohoverError(
                f"{source}, line {number}: node {node} ({names[node]}) of {_DESCRIPTION[topology]} must have position {want[0]} "
                f"and function {want[1]}, not {pos} and {func}: {line!r}"
            )
        biases[names[node]] = bias
    weights: dict[str, float] = {}
    for (src, dst), (weight, number, line) in links.items():
        name = f"{names.get(src, src)}->{names.get(dst, dst)}"
        if name not in _LINKS[topology]:
            raise NeurohoverError(f"{source}, line {number}: link {src} -> {dst} ({name}) is not a link of {_DESCRIPTION[topology]}: {line!r}")
        weights[name] = weight
    missing = [f"bias of {n}" for n in _BIASES[topology] if n not in biases] + [f"link {n}" for n in _LINKS[topology] if n not in weights]
    if missing:
        raise NeurohoverError(f"{source}: not {_DESCRIPTION[topology]}: missing {', '.join(missing[:4])}{' ...' if len(missing) > 4 else ''}")
    if topology == "mlp":
        genome = [biases[n] for n in MLP_BIAS_NAMES] + [weights[n] for n in MLP_WEIGHT_NAMES]
    else:
        genome = [weights[n] for n in SLP_LINK_NAMES] + [biases[a] for a in _ACTIONS]
    metadata: dict[str, object] = {"source": "authors' network file"}
    if comments:
        metadata["comments"] = comments
    return Policy(topology, np.array(genome), metadata)


def policy_to_net(policy: Policy) -> str:
    """Write an MLP or SLP policy in the authors' ``.net`` format (the inverse of :func:`policy_from_net`)."""
    if not isinstance(policy, Policy):  # None, 'baseline' or 5 were AttributeError (sixth trial)
        raise NeurohoverError(f"policy {policy!r:.60} is not a Policy: load one with neurohover.load_policy (e.g. load_policy('baseline'))")
    topology = policy.topology
    if topology not in NODE_NAMES:
        raise NeurohoverError(f"no .net form for topology {topology!r}: allowed {', '.join(NODE_NAMES)}")
    ids = NODE_IDS[topology]
    n_weights = len(_LINKS[topology])
    bias_values = policy.genome[n_weights:] if topology == "slp" else policy.genome[: len(MLP_BIAS_NAMES)]
    weight_values = policy.genome[:n_weights] if topology == "slp" else policy.genome[len(MLP_BIAS_NAMES) :]
    lines = [f"n {i} 0 0 +0.0000" for i in _INPUTS]
    for name, bias in sorted(zip(_BIASES[topology], bias_values), key=lambda nb: ids[nb[0]]):
        position, function = _role(topology, name)
        lines.append(f"n {ids[name]} {position} {function} {bias:+.17g}")
    links = []
    for name, weight in zip(_LINKS[topology], weight_values):
        src, dst = name.split("->")
        links.append((ids[src], ids[dst], weight))
    lines += [f"s {s} {d} {w:+.17g}" for s, d, w in sorted(links)]
    return "\n".join(lines) + "\n"
