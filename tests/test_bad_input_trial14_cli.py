"""The fourteenth bad-input trial's command-line findings (and the items earlier trials left): each gives one clear
message (exit 2) naming the value and what is allowed, before any work is done."""

from __future__ import annotations

from pathlib import Path


def test_evolve_refuses_a_net_out_before_evolving(tmp_path: Path, cli) -> None:
    """evolve --out p.net was refused only when the evolved policy was saved (JSON under .net, which load_policy reads
    as the authors' format), so the whole run was lost; it is refused up front, leaving no history or checkpoint."""
    out = tmp_path / "p.net"
    rc, _, err = cli("evolve", "--task", "ghh08", "--out", str(out), "--budget", "10")
    assert rc == 2
    assert f"--out {str(out)!r}: a policy is written as JSON" in err and "give a .json name" in err
    assert list(tmp_path.iterdir()) == []
