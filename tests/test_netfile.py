"""The authors' .net network files: parsing, writing, and flying them like any policy file."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from neurohover import NeurohoverError, evaluate, get_task_family
from neurohover.netfile import policy_from_net, policy_to_net
from neurohover.policies import Policy, baseline_policy, load_policy, mlp_baseline_genome, prototype

# The authors' baseline.net as their eonn package wrote it (node and link lines, 4 decimals).
BASELINE_NET = """n 1 0 0 +0.0000
n 2 0 0 +0.0000
n 3 0 0 +0.0000
n 4 0 0 +0.0000
n 5 0 0 +0.0000
n 6 0 0 +0.0000
n 7 0 0 +0.0000
n 8 0 0 +0.0000
n 9 0 0 +0.0000
n 10 0 0 +0.0000
n 11 0 0 +0.0000
n 12 0 0 +0.0000
n 13 2 1 +0.0000
n 14 2 1 +0.0000
n 15 2 1 +0.0000
n 16 2 0 +0.0000
n 17 2 0 +0.0000
n 18 2 0 +0.0000
n 19 2 0 +0.0000
n 20 2 1 +0.0000
n 21 2 1 +0.0000
n 22 2 1 +0.0000
n 23 2 1 +0.0000
n 24 1 0 +0.0200
n 25 1 0 +0.0000
n 26 1 0 +0.0000
n 27 1 0 +0.2300
s 1 17 -0.0322
s 2 16 -0.0367
s 3 19 +0.1348
s 4 14 +0.0000
s 4 17 -0.0185
s 5 13 +0.0000
s 5 16 -0.0196
s 6 15 +0.0000
s 6 19 +0.0513
s 10 16 -0.7475
s 11 17 +0.7904
s 12 18 -0.1969
s 13 16 +0.0000
s 14 17 +0.0000
s 15 19 +0.0000
s 16 20 +0.0000
s 16 24 +1.0000
s 17 21 +0.0000
s 17 25 +1.0000
s 18 22 +0.0000
s 18 26 +1.0000
s 19 23 +0.0000
s 19 27 +1.0000
s 20 24 +0.0000
s 21 25 +0.0000
s 22 26 +0.0000
s 23 27 +0.0000
"""


def test_the_authors_baseline_file_is_our_baseline_seed_and_flies_like_the_baseline(tmp_path: Path) -> None:
    path = tmp_path / "baseline.net"
    path.write_text("# wind: [+0.000, +0.000]\n" + BASELINE_NET)
    policy = load_policy(path)
    assert policy.topology == "mlp"
    np.testing.assert_array_equal(policy.genome, mlp_baseline_genome())
    assert policy.metadata["comments"] == ["wind: [+0.000, +0.000]"]
    mdps = get_task_family("ghh08").training_mdps()[:2]
    a = evaluate(policy, mdps, episodes=1, seed=3, n_steps=300).returns
    b = evaluate(baseline_policy(), mdps, episodes=1, seed=3, n_steps=300).returns
    np.testing.assert_allclose(a, b, rtol=1e-12)


def test_writing_and_reading_a_net_file_keeps_every_gene_and_its_place() -> None:
    genome = np.random.default_rng(0).normal(size=42)
    policy = Policy("mlp", genome)
    back = policy_from_net(policy_to_net(policy))
    np.testing.assert_array_equal(back.genome, genome)
    # Shuffled lines are read by node and link ids, not by position.
    lines = policy_to_net(policy).splitlines()
    np.testing.assert_array_equal(policy_from_net("\n".join(reversed(lines))).genome, genome)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (BASELINE_NET.replace("s 23 27 +0.0000\n", ""), "missing link S4->a4"),
        (BASELINE_NET + "s 1 24 +0.5\n", "link 1 -> 24 (u->a1) is not a link of the paper's MLP"),
        (BASELINE_NET + "n 28 2 0 +0.0\n", "node 28 is not a node of the paper's MLP"),
        (BASELINE_NET.replace("s 2 16 -0.0367", "s 2 16 heavy"), "line 29"),
        (BASELINE_NET + "s 23 27 +0.5\n", "link 23 -> 27 is given again (first on line"),  # issue 37: kept the later value
        (BASELINE_NET + "n 27 2 0 +0.9\n", "node 27 is defined again (first on line"),
        (BASELINE_NET.replace("s 2 16 -0.0367", "s 2 16 nan"), "x.net, line 29: weight nan is not a finite number"),  # no file or line before
        (BASELINE_NET.replace("n 20 2 1 +0.0000", "n 20 2 1 inf"), "x.net, line 20: bias inf is not a finite number"),
        # Fifth trial: an input line of another role or with a bias was read as a plain input (the bias dropped); none at all too.
        (BASELINE_NET.replace("n 1 0 0 +0.0000", "n 1 7 9 +0.0000"), "x.net, line 1: input node 1 (u) must have position 0, function 0 and bias 0"),
        (BASELINE_NET.replace("n 1 0 0 +0.0000", "n 1 0 0 +5.0000"), "not 0, 0 and 5"),
        ("".join(line + "\n" for line in BASELINE_NET.splitlines() if not line.startswith(("n 1 ", "n 2 "))), "input node(s) 1, 2 missing"),
    ],
    ids=[
        *("missing-link", "extra-link", "extra-node", "bad-number", "repeated-link", "repeated-node", "nan-weight", "inf-bias"),
        *("input-role", "input-bias", "no-input"),
    ],
)
def test_a_file_that_is_not_the_papers_mlp_is_refused_with_the_line(text: str, message: str) -> None:
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        policy_from_net(text, "x.net")


# The baseline as an SLP in the authors' format (their FGHH generics' layout: outputs 13-16, every
# used input linked to every output, zero weights written too), 4 decimals as eonn writes them.
_SLP_GAINS = {(5, 13): -0.0196, (2, 13): -0.0367, (10, 13): -0.7475, (4, 14): -0.0185, (1, 14): -0.0322, (11, 14): 0.7904, (12, 15): -0.1969}
_SLP_GAINS.update({(6, 16): 0.0513, (3, 16): 0.1348})
BASELINE_SLP_NET = (
    "".join(f"n {i} 0 0 +0.0000\n" for i in range(1, 13))
    + "n 13 1 0 +0.0200\nn 14 1 0 +0.0000\nn 15 1 0 +0.0000\nn 16 1 0 +0.2300\n"
    + "".join(f"s {src} {dst} {_SLP_GAINS.get((src, dst), 0.0):+.4f}\n" for src in (1, 2, 3, 4, 5, 6, 10, 11, 12) for dst in (13, 14, 15, 16))
)


def test_an_slp_file_in_the_authors_layout_is_the_baseline_slp_and_flies_like_the_baseline(tmp_path: Path) -> None:
    path = tmp_path / "policy_01.net"
    path.write_text("# score: 0.2\n" + BASELINE_SLP_NET)
    policy = load_policy(path)
    assert policy.topology == "slp"
    np.testing.assert_array_equal(policy.genome, prototype("slp", "baseline").genome)
    mdps = get_task_family("fghh", 0.3).test_mdps()[:2]
    a = evaluate(policy, mdps, episodes=1, seed=3, n_steps=300).returns
    b = evaluate(baseline_policy(), mdps, episodes=1, seed=3, n_steps=300).returns
    np.testing.assert_allclose(a, b, rtol=1e-12)


def test_writing_and_reading_an_slp_net_file_keeps_every_gene_and_its_place() -> None:
    genome = np.random.default_rng(1).normal(size=40)
    text = policy_to_net(Policy("slp", genome))
    np.testing.assert_array_equal(policy_from_net(text).genome, genome)
    np.testing.assert_array_equal(policy_from_net("\n".join(reversed(text.splitlines()))).genome, genome)
    assert "n 13 1 0" in text and "s 12 16" in text  # output nodes 13-16, links from the inputs' ids


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (BASELINE_SLP_NET.replace("s 12 16 +0.0000\n", ""), "not an SLP (ids 1-16): missing link qz->a4"),
        (BASELINE_SLP_NET + "s 7 13 +0.5\n", "line 53: link 7 -> 13 (p->a1) is not a link of an SLP"),
        (BASELINE_SLP_NET + "n 17 1 0 +0.0\n", "line 53: node 17 is not a node of an SLP (ids 1-16); known topologies"),
        (BASELINE_SLP_NET.replace("n 14 1 0", "n 14 1 1"), "line 14: node 14 (a2) of an SLP (ids 1-16) must have position 1 and function 0, not 1 and 1"),
        (BASELINE_SLP_NET.replace("n 16 1 0 +0.2300", "n 16 1 0 lots"), "line 16"),
    ],
    ids=["missing-link", "rate-input", "unknown-node", "sigmoid-output", "bad-number"],
)
def test_a_malformed_or_unknown_slp_file_is_refused_with_the_line(text: str, message: str) -> None:
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        policy_from_net(text, "x.net")
