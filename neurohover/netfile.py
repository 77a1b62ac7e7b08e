"""The authors' network files (``.net``, their ``eonn`` package's format) as neurohover MLP policies.

The paper's authors published their policies as text files with one gene per line:
``n ID POSITION FUNCTION BIAS`` for a node and ``s SOURCE DEST WEIGHT`` for a link, optionally
after ``#`` comment lines. Their MLP (the paper's Figure 1) numbers its nodes as below; the
mapping to our genome order (docs/model.md, Policies) is fixed by the node and link names, so
``load_policy("mdp0.net")`` flies one of their policies exactly as their simulator did (the
returns in a file's ``# reward`` comment are met within the noise).

==========  ====================================================================
node ids    meaning
==========  ====================================================================
1..12       inputs: u, v, w, x, y, z, p, q, r, qx, qy, qz (p, q, r are unused)
13, 14, 15  position sigmoids hy, hx, hz
16..19      linear sums L1..L4
20..23      sigmoids S1..S4
24..27      outputs a1..a4
==========  ====================================================================
"""

from __future__ import annotations

import numpy as np

from .errors import NeurohoverError
from .policies import MLP_BIAS_NAMES, MLP_WEIGHT_NAMES, Policy

NODE_NAMES = {1: "u", 2: "v", 3: "w", 4: "x", 5: "y", 6: "z", 7: "p", 8: "q", 9: "r", 10: "qx", 11: "qy", 12: "qz"}
NODE_NAMES.update({13 + i: name for i, name in enumerate(MLP_BIAS_NAMES)})
NODE_IDS = {name: i for i, name in NODE_NAMES.items()}
_INPUT_IDS = range(1, 13)


def policy_from_net(text: str, source: str = "network file") -> Policy:
    """Parse an authors' ``.net`` MLP into a :class:`Policy` (comment lines become metadata)."""
    biases: dict[str, float] = {}
    weights: dict[str, float] = {}
    comments = []
    for number, line in enumerate(text.splitlines(), 1):
        fields = line.split()
        if not fields:
            continue
        if fields[0].startswith("#"):
            comments.append(line.lstrip("# ").strip())
            continue
        try:
            if fields[0] == "n" and len(fields) == 5:
                node, value = int(fields[1]), float(fields[4])
                if node not in NODE_NAMES:
                    raise ValueError(f"node {node} is not a node of the paper's MLP (ids 1-27)")
                if node not in _INPUT_IDS:
                    biases[NODE_NAMES[node]] = value
            elif fields[0] == "s" and len(fields) == 4:
                src, dst = int(fields[1]), int(fields[2])
                name = f"{NODE_NAMES.get(src, src)}->{NODE_NAMES.get(dst, dst)}"
                if name not in MLP_WEIGHT_NAMES:
                    raise ValueError(f"link {src} -> {dst} ({name}) is not a link of the paper's MLP")
                weights[name] = float(fields[3])
            else:
                raise ValueError("expected 'n ID POSITION FUNCTION BIAS' or 's SOURCE DEST WEIGHT'")
        except ValueError as err:
            raise NeurohoverError(f"{source}, line {number}: {err}: {line.strip()!r}") from None
    missing = [f"bias of {n}" for n in MLP_BIAS_NAMES if n not in biases] + [f"link {n}" for n in MLP_WEIGHT_NAMES if n not in weights]
    if missing:
        raise NeurohoverError(f"{source}: not the paper's MLP: missing {', '.join(missing[:4])}{' ...' if len(missing) > 4 else ''}")
    genome = np.array([biases[n] for n in MLP_BIAS_NAMES] + [weights[n] for n in MLP_WEIGHT_NAMES])
    metadata: dict[str, object] = {"source": "authors' network file"}
    if comments:
        metadata["comments"] = comments
    return Policy("mlp", genome, metadata)


def policy_to_net(policy: Policy) -> str:
    """Write an MLP policy in the authors' ``.net`` format (the inverse of :func:`policy_from_net`)."""
    if policy.topology != "mlp":
        raise NeurohoverError(f"only MLP policies have a .net form, not {policy.topology!r}")
    lines = [f"n {i} 0 0 +0.0000" for i in _INPUT_IDS]
    for k, name in enumerate(MLP_BIAS_NAMES):
        node = NODE_IDS[name]
        position = 1 if name.startswith("a") else 2  # eonn: 1 output, 2 hidden
        function = 1 if name[0] in "hS" else 0  # eonn: 1 sigmoid, 0 sum
        lines.append(f"n {node} {position} {function} {policy.genome[k]:+.17g}")
    links = []
    for k, name in enumerate(MLP_WEIGHT_NAMES):
        src, dst = name.split("->")
        links.append((NODE_IDS[src], NODE_IDS[dst], policy.genome[len(MLP_BIAS_NAMES) + k]))
    lines += [f"s {s} {d} {w:+.17g}" for s, d, w in sorted(links)]
    return "\n".join(lines) + "\n"
