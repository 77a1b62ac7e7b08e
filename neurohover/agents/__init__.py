"""On-line agents and the test-run protocol (docs/model.md, On-line agents)."""

from .model_free import ModelFreeAgent
from .protocol import Agent, Choice, EpisodeOutcome, RunResult, run_test

__all__ = ["Agent", "Choice", "EpisodeOutcome", "ModelFreeAgent", "RunResult", "run_test"]
