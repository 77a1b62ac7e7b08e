"""Rendering of HoverEnv: real frames, their changes, no effect on results, checker, human mode, video."""

from __future__ import annotations

import gc
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from conftest import ROOT
from gymnasium.utils.env_checker import check_env

import neurohover
from neurohover import get_task_family
from neurohover.envs import HoverEnv
from neurohover.envs.hover import world_wind
from neurohover.envs.render import FRAME_HEIGHT, FRAME_WIDTH, HoverRenderer, view_range

BASELINE = neurohover.baseline_policy()
BOXES = HoverRenderer()  # the layout is the same in every renderer of the default size


def _crop(frame: np.ndarray, part: str) -> np.ndarray:
    r0, r1, c0, c1 = BOXES.pixel_box(part)
    return frame[r0:r1, c0:c1]


def _changed(a: np.ndarray, b: np.ndarray) -> int:
    """Number of pixels that differ between two frames (or crops)."""
    return int(np.any(a != b, axis=-1).sum())


def test_metadata_declares_both_modes() -> None:
    assert HoverEnv.metadata["render_modes"] == ["human", "rgb_array"]
    assert HoverEnv.metadata["render_fps"] == 10  # the control rate: one frame per step is real time


def test_rgb_array_frame_shape_dtype_and_content() -> None:
    env = gym.make("neurohover/GHH08-v0", mdp="test:4", render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert isinstance(frame, np.ndarray) and frame.shape == (FRAME_HEIGHT, FRAME_WIDTH, 3) and frame.dtype == np.uint8
    assert frame.shape[0] % 2 == 0 and frame.shape[1] % 2 == 0  # video encoders want even sizes
    # A real drawing, not a blank canvas: dark ink (body, text) and colours (rotor, target, wind).
    assert (frame.max(axis=-1) < 80).sum() > 500
    assert (frame.max(axis=-1).astype(int) - frame.min(axis=-1) > 80).sum() > 200
    env.close()


def test_frames_change_as_the_helicopter_moves() -> None:
    # Collective 0 drops the helicopter (about 1 m in 5 steps): the side view must show it fall.
    env = HoverEnv("ghh08", mdp="zero", render_mode="rgb_array")
    env.reset(seed=1)
    frames = [env.render()]
    altitudes = [0.0]
    for _ in range(5):
        env.step(np.zeros(4))
        frames.append(env.render())
        altitudes.append(-env._state[0, 5])
    assert altitudes[-1] < -0.5  # it really fell
    for a, b in zip(frames, frames[1:], strict=False):
        assert _changed(_crop(a, "side"), _crop(b, "side")) > 20
        assert _changed(_crop(a, "text"), _crop(b, "text")) > 0  # step and return

    # The drawn helicopter itself moved down: the lowest dark (body) pixel row in the side view.
    def lowest_ink(frame: np.ndarray) -> int:
        side = _crop(frame, "side")[5:-5, 5:-5]  # inside the axes frame
        rows = np.flatnonzero((side.max(axis=-1) < 80).any(axis=1))
        return int(rows.max())

    assert lowest_ink(frames[-1]) > lowest_ink(frames[0]) + 10


def test_frames_change_under_random_actions() -> None:
    env = gym.make("neurohover/GHH09-v0", mdp="train:2", render_mode="rgb_array")
    env.reset(seed=3)
    env.action_space.seed(3)
    previous = env.render()
    for _ in range(3):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        frame = env.render()
        assert _changed(previous[31:], frame[31:]) > 20  # below the text line
        previous = frame
        if terminated or truncated:
            break


@pytest.mark.slow
def test_windy_frame_differs_from_calm_only_in_wind_and_text() -> None:
    family = get_task_family("ghh08")
    calm = HoverEnv("ghh08", mdp=family.zero(), render_mode="rgb_array")
    windy = HoverEnv("ghh08", mdp=family.make([3.0, -2.0]), render_mode="rgb_array")
    calm.reset(seed=0)
    windy.reset(seed=0)
    a, b = calm.render(), windy.render()
    assert _changed(_crop(a, "wind"), _crop(b, "wind")) > 50  # the arrow and its speed
    # Same helicopter state at reset: everything else is identical but the text line (MDP label).
    outside = np.ones(a.shape[:2], dtype=bool)
    for part in ("wind", "text"):
        r0, r1, c0, c1 = BOXES.pixel_box(part)
        outside[r0:r1, c0:c1] = False
    assert np.array_equal(a[outside], b[outside])

    # A windier MDP draws a longer arrow: more purple-ish pixels in the compass.
    def arrow_pixels(frame: np.ndarray) -> int:
        w = _crop(frame, "wind").astype(int)
        return int(((w[..., 0] - w[..., 1] > 40) & (w[..., 2] - w[..., 1] > 40)).sum())

    stronger = HoverEnv("ghh08", mdp=family.make([5.0, -4.0]), render_mode="rgb_array")
    stronger.reset(seed=0)
    assert arrow_pixels(a) == 0 and arrow_pixels(stronger.render()) > arrow_pixels(b) > 20


def test_wind_arrow_points_where_the_air_pushes() -> None:
    # The drag acts on velocity + W: a wind parameter W = (3, 0) (north) pushes the helicopter
    # south, and the arrow shows that motion of the air.
    family = get_task_family("ghh08")
    env = HoverEnv("ghh08", mdp=family.make([3.0, 0.0]), render_mode="rgb_array", episode_steps=200)
    env.reset(seed=0)
    frame = env.render()
    x0, y0, x1, y1 = BOXES.wind.get_position().extents  # the compass axes, figure fractions
    centre_row, centre_col = (1 - (y0 + y1) / 2) * FRAME_HEIGHT, (x0 + x1) / 2 * FRAME_WIDTH
    rgb = frame.astype(int)
    purple = (rgb[..., 0] - rgb[..., 1] > 40) & (rgb[..., 2] - rgb[..., 1] > 40)
    rows, cols = np.nonzero(purple)
    assert rows.size > 20 and rows.mean() > centre_row + 5 and abs(cols.mean() - centre_col) < 3
    for _ in range(100):  # hold still against the wind with the baseline: it drifts south
        obs, _, terminated, _, _ = env.step(np.array(BASELINE.act(env._obs[0])))
        assert not terminated
    assert env._state[0, 3] < -0.5


def test_wind_arrow_follows_the_current_ghh09_wind() -> None:
    env = HoverEnv("ghh09", mdp="train:0", render_mode="rgb_array")
    env.reset(seed=0)
    first = env.render()
    wind0 = world_wind(env.mdp, 0)
    for _ in range(15):
        env.step(np.array(BASELINE.act(env._obs[0])))
    later = env.render()
    assert world_wind(env.mdp, 15) != wind0  # a sinusoidal wind changes within 1.5 s
    assert _changed(_crop(first, "wind"), _crop(later, "wind")) > 0


def test_world_wind_matches_the_mdp() -> None:
    family = get_task_family("ghh08")
    assert world_wind(family.make([2.5, -1.0]), 123) == (2.5, -1.0, 0.0)
    assert world_wind(family.zero(), 0) == (0.0, 0.0, 0.0)


def _fly(env: gym.Env, n: int, render: bool):
    obs, info = env.reset(seed=7)
    rng = np.random.default_rng(7)
    out = [(obs, 0.0, False, False, info)]
    for _ in range(n):
        action = np.array(BASELINE.act(obs)) + 0.05 * rng.standard_normal(4)
        obs, reward, terminated, truncated, info = env.step(action)
        if render:
            assert env.render() is not None
        out.append((obs, reward, terminated, truncated, info))
        if terminated or truncated:
            break
    return out


@pytest.mark.slow
@pytest.mark.parametrize("env_id", ["neurohover/GHH08-v0", "neurohover/GHH09-v0", "neurohover/FGHH-v0"])
def test_rendering_does_not_change_results(env_id: str) -> None:
    plain = _fly(gym.make(env_id), 60, render=False)
    drawn = _fly(gym.make(env_id, render_mode="rgb_array"), 60, render=True)
    assert len(plain) == len(drawn)
    for (o1, r1, te1, tr1, i1), (o2, r2, te2, tr2, i2) in zip(plain, drawn, strict=True):
        np.testing.assert_array_equal(o1, o2)
        assert r1 == r2 and te1 == te2 and tr1 == tr2 and i1 == i2


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["rgb_array", "human"])
def test_gymnasium_env_checker_passes_with_rendering(mode: str) -> None:
    gc.collect()  # an earlier test's unclosed files warn when collected: not this env's warnings
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # With a spec the checker also builds and renders the env in every declared mode.
        check_env(gym.make("neurohover/GHH08-v0", render_mode=mode).unwrapped)
    expected = ("infinity", "has no window")  # unbounded observations by design; no display here
    assert [str(w.message) for w in caught if not any(e in str(w.message) for e in expected)] == []


def test_human_mode_opens_its_window_lazily_and_closes() -> None:
    env = HoverEnv("ghh08", mdp="zero", render_mode="human")
    assert env._window is None and env._renderer is None  # nothing drawn or opened at construction
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "no window" on this headless machine
        env.reset(seed=0)
        assert env._window is not None
        _, _, _, _, _ = env.step(np.array(BASELINE.act(np.zeros(12))))
        assert env.render() is None  # human mode shows, it returns nothing
    env.close()
    env.close()  # closing twice is allowed
    assert env._window is None and env._renderer is None


def test_render_without_a_mode_warns_and_returns_none() -> None:
    env = gym.make("neurohover/GHH08-v0").unwrapped
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="without specifying any render mode"):
        assert env.render() is None


def test_render_before_reset_draws_the_start() -> None:
    env = HoverEnv("fghh", render_mode="rgb_array")
    frame = env.render()
    assert frame.shape == (FRAME_HEIGHT, FRAME_WIDTH, 3)


def test_views_zoom_out_when_the_helicopter_leaves_them() -> None:
    assert view_range((0.0, 0.0, 0.0)) == 5.0
    assert view_range((0.0, -6.0, 0.0)) == 10.0
    assert view_range((19.5, 0.0, 0.0)) == 22.0  # the crash box (20 m) and a margin


def test_record_video_writes_a_video(tmp_path: Path) -> None:
    pytest.importorskip("moviepy")
    from gymnasium.wrappers import RecordVideo

    env = gym.make("neurohover/GHH08-v0", mdp="train:1", render_mode="rgb_array", episode_steps=15, max_episode_steps=15)
    env = RecordVideo(env, str(tmp_path / "videos"), episode_trigger=lambda e: True, disable_logger=True)
    obs, _ = env.reset(seed=0)
    done = False
    while not done:
        obs, _, terminated, truncated, _ = env.step(np.array(BASELINE.act(obs)))
        done = terminated or truncated
    env.close()
    videos = list((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 1000


@pytest.mark.parametrize("name", ["render.png", "flight.png"])
def test_readme_images_exist(name: str) -> None:
    path = ROOT / "docs" / "images" / name
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"docs/images/{name}" in (ROOT / "README.md").read_text()
