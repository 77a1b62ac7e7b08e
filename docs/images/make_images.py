"""Make the README's images: ``render.png`` (one HoverEnv frame) and ``flight.png`` (a flight plot).

Run from anywhere: ``python3 docs/images/make_images.py``; the images are written beside this
script. Both come from the same flight: the competition's baseline policy on GHH-09 training MDP
1 (sinusoidal winds), gust-noise seed 0, so rerunning the script redraws the same pictures.
"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import matplotlib.image as mpimg
import numpy as np

import neurohover
from neurohover.flightdata import FlightData
from neurohover.plots import flight_figure, save_figure

HERE = Path(__file__).resolve().parent
TASK, MDP, SEED = "ghh09", "train:1", 0
FRAME_STEP = 150  # 15 s in: the wind has pushed the helicopter off the target and tilted it


def render_frame(path: Path) -> Path:
    """A frame of the baseline hovering in the wind, ``FRAME_STEP`` steps into the episode."""
    policy = neurohover.baseline_policy()
    env = gym.make(f"neurohover/{TASK.upper()}-v0", mdp=MDP, render_mode="rgb_array")
    obs, _ = env.reset(seed=SEED)
    for _ in range(FRAME_STEP):
        obs, *_ = env.step(np.array(policy.act(obs)))
    mpimg.imsave(path, env.render())
    env.close()
    return path


def flight_plot(path: Path) -> Path:
    """The plot ``neurohover plot`` draws for one recorded 6000-step episode of the same policy and MDP."""
    family = neurohover.get_task_family(TASK)
    mdp = family.mdp(MDP)
    ev = neurohover.evaluate(neurohover.baseline_policy(), mdp, episodes=1, seed=SEED, record=True)
    data: FlightData = ev.flight_data
    title = f"flight: episode 0, {mdp.label}, return {float(ev.returns.ravel()[0]):.6g}, policy baseline"
    return save_figure(flight_figure(data.observations[0], data.actions[0], title=title), path)


if __name__ == "__main__":
    import argparse

    argparse.ArgumentParser(description=str(__doc__).splitlines()[0]).parse_args()  # --help describes, it draws nothing
    for made in (render_frame(HERE / "render.png"), flight_plot(HERE / "flight.png")):
        print(made)
