"""Command-line options generated from the settings dataclasses (issue 34): one source for type, choices, help and default."""

from __future__ import annotations

import argparse
from dataclasses import dataclass

import pytest

from neurohover import NeurohoverError
from neurohover.cli.options import add_setting_options, check_given, given_settings


@dataclass(frozen=True)
class _Toy:
    """A settings class as the package writes them.

    Parameters
    ----------
    mode : {"fast", "slow"}
        How it runs: about 30% faster when fast.
    size : int
        How many (>= 1).
    on : bool
        Whether it is on.
    """

    mode: str = "fast"
    size: int = 3
    on: bool = False

    def __post_init__(self) -> None:
        if self.mode not in ("fast", "slow"):
            raise NeurohoverError(f"mode={self.mode!r} is not allowed: fast or slow")


def _parser() -> tuple[argparse.ArgumentParser, tuple]:
    p = argparse.ArgumentParser(prog="toy")
    return p, add_setting_options(p, _Toy, ("mode", "size", "on"), prefix="toy-", flags={"on": "switch"}, who="toys")


def test_an_option_says_what_its_field_says() -> None:
    p, options = _parser()
    assert [o.flag for o in options] == ["--toy-mode", "--toy-size", "--switch"]
    text = p.format_help()  # a '%' in a docstring must not break argparse's formatting
    assert "--toy-mode {fast,slow}" in text and "toys: how it runs: about 30% faster when fast (default fast)" in " ".join(text.split())
    assert "(default 3)" in text and "(default false)" in text


def test_given_options_become_the_fields_and_absent_ones_stay_the_class_default() -> None:
    p, options = _parser()
    args = p.parse_args(["--toy-size", "5", "--switch", "true"])
    assert given_settings(args, options) == {"size": 5, "on": True}
    assert given_settings(p.parse_args([]), options) == {}
    with pytest.raises(SystemExit):
        p.parse_args(["--switch", "yes"])  # a bool reads true/false only, as TOML writes it


def test_a_bad_value_is_refused_by_the_class_and_named_by_its_option() -> None:
    p, options = _parser()
    args = p.parse_args(["--toy-mode", "medium"])
    with pytest.raises(NeurohoverError, match="--toy-mode medium: mode='medium' is not allowed: fast or slow"):
        check_given(_Toy, given_settings(args, options), options)


def test_the_commands_options_follow_their_classes() -> None:
    """compete's hybrid and model options and learn-model's LR options are those of HybridSettings, DangerousState and ModelEvolution."""
    from neurohover.agents.model_based import ModelEvolution
    from neurohover.cli import build_parser
    from neurohover.evaluate import DangerousState

    commands = build_parser()._subparsers._group_actions[0].choices
    compete = " ".join(commands["compete"].format_help().split())
    assert (
        f"--safeguard-box SAFEGUARD_BOX Bound on |u|, |v|, |w|, |x|, |y|, |z|, |p|, |q|, |r| (> 0; 0.5 in the paper) (default {DangerousState().box})"
        in compete
    )
    assert "--hybrid-replacement {rerank,evolve}" in compete and "--model-substeps {10,1}" in compete
    learn = " ".join(commands["learn-model"].format_help().split())
    assert "--noise-estimate {rms,innovations} lr: the model's gust noise" in learn and f"(default {ModelEvolution().noise})" in learn
