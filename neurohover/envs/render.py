"""Frames of a hovering helicopter: a top view, a side view and the wind, drawn with matplotlib.

:class:`HoverRenderer` draws one RGB frame of the world state of one helicopter: where it is
relative to the hover target (the origin), its attitude (the body drawn rotated by its
quaternion), its recent track, the MDP's current world wind as an arrow on a compass, and a text
line (MDP label, step, return so far). It uses matplotlib's object-oriented API only (a
:class:`~matplotlib.figure.Figure` on a :class:`~matplotlib.backends.backend_agg.FigureCanvasAgg`),
so it never touches pyplot's global state or the process's backend. The figure is built once;
its static parts (axes, grid, labels) are drawn once and kept as a background, on which each
frame draws only the moving parts (blitting: about 10 ms a frame instead of about 80).

Frames (world frame north-east-down, metres):

- top view: east (y) to the right, north (x) up;
- side view, seen from the east: north (x) to the right, altitude (-z) up;
- wind compass: where the air moves, north up, a full radius being 5 m/s. The simulator's drag
  acts on ``body velocity + W`` for the MDP's world wind ``W`` (docs/model.md, Simulator), so
  ``W`` pushes the helicopter along ``-W``: the arrow is ``-W``, the way the helicopter drifts.

Both views show the same square window around the target: 5 m either way, zooming out to 10 m
and then to the crash box (20 m) when the helicopter leaves it.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, whole_number
from ..plots import house_style  # frames drawn in matplotlib's default style, as every figure (after T46-A04)
from ..sim.constants import MAX_POSITION
from .arguments import real_values

#: Frame size in pixels (width, height); both even, as video encoders want.
FRAME_WIDTH = 720
FRAME_HEIGHT = 340
#: The largest side of a frame (pixels): an 8K frame; Agg draws up to 65535, but a frame that size takes 17 GB.
MAX_FRAME_SIDE = 8192
PARTS = ("top", "side", "wind", "text")  # what pixel_box() locates
_DPI = 80
_TEXT_BAND = 0.09  # top share of the frame holding the text line (the axes' titles sit below it)
#: Half-widths (m) of the views; the smallest that holds the helicopter (with a margin) is used.
VIEW_RANGES: tuple[float, ...] = (5.0, 10.0, MAX_POSITION + 2.0)
_MARGIN = 1.2  # m: keep the rotor disk inside the window
WIND_FULL_SCALE = 5.0  # m/s at the compass's full radius (the GHH-08 maximum per axis)

# Body-frame outline (x forward, y right, z down; metres, roughly an XCell Tempest).
_ROTOR_RADIUS = 0.9
_MAST = 0.35
_ANGLES = np.linspace(0.0, 2.0 * np.pi, 33)
_ROTOR = np.stack([_ROTOR_RADIUS * np.cos(_ANGLES), _ROTOR_RADIUS * np.sin(_ANGLES), np.full(_ANGLES.size, -_MAST)], axis=1)
_FUSELAGE = np.array([[0.55, 0.0, 0.05], [0.0, 0.0, 0.1], [-1.1, 0.0, -0.1]])
_MAST_LINE = np.array([[0.0, 0.0, 0.1], [0.0, 0.0, -_MAST]])
_TAIL_ROTOR = np.stack([-1.1 + 0.16 * np.cos(_ANGLES), np.full(_ANGLES.size, 0.08), -0.1 + 0.16 * np.sin(_ANGLES)], axis=1)
_NOSE = np.array([[0.55, 0.0, 0.05]])


def _real_vector(values: Any, lengths: tuple[int, ...], what: str, meaning: str) -> np.ndarray:
    """``values`` as a float64 vector of one of ``lengths`` real numbers, or a NeurohoverError naming ``what`` (T14-14:
    short or text values were IndexErrors, TypeErrors and NumPy's reshape errors)."""
    message = f"{what}={' '.join(brief(values).split())} is not allowed: give {' or '.join(map(str, lengths))} real numbers ({meaning})"
    arr = real_values(values, message)
    if arr.ndim != 1 or arr.shape[0] not in lengths:
        raise NeurohoverError(message)
    return arr


def rotation_matrix(qx: float, qy: float, qz: float, qw: float) -> np.ndarray:
    """Body-to-world rotation matrix of a unit quaternion (the kernel's convention)."""
    for name, q in (("qx", qx), ("qy", qy), ("qz", qz), ("qw", qw)):
        if not (finite_real(q) or isinstance(q, (float, np.floating))):  # 'a', np.timedelta64 were TypeErrors (T14-14, T17-1); NaN kept
            raise NeurohoverError(f"rotation_matrix {name}={brief(q)} is not allowed: give a quaternion's 4 real numbers qx, qy, qz, qw")
    return np.array(
        [
            [1.0 - 2.0 * (qy * qy + qz * qz), 2.0 * (qx * qy - qw * qz), 2.0 * (qx * qz + qw * qy)],
            [2.0 * (qx * qy + qw * qz), 1.0 - 2.0 * (qx * qx + qz * qz), 2.0 * (qy * qz - qw * qx)],
            [2.0 * (qx * qz - qw * qy), 2.0 * (qy * qz + qw * qx), 1.0 - 2.0 * (qx * qx + qy * qy)],
        ]
    )


def view_range(position: Sequence[float] | np.ndarray) -> float:
    """Half-width (m) of the views for a helicopter at world ``position``."""
    position = _real_vector(position, (3,), "view_range position", "a world position x, y, z")  # [] was an IndexError (T14-14)
    reach = max(abs(float(position[0])), abs(float(position[1])), abs(float(position[2]))) + _MARGIN
    for r in VIEW_RANGES:
        if reach <= r:
            return r
    return VIEW_RANGES[-1]


class HoverRenderer:
    """Draws RGB frames of one helicopter; see the module docstring for the layout.

    Parameters
    ----------
    width, height : int
        Frame size in pixels.
    """

    @house_style
    def __init__(self, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from matplotlib.patches import Circle, FancyArrow

        for name, side in (("width", width), ("height", height)):  # 0 was a ZeroDivisionError, -5 and 'a' matplotlib's ValueErrors (T14-14)
            if not whole_number(side) or not 1 <= side <= MAX_FRAME_SIDE:
                raise NeurohoverError(f"HoverRenderer {name}={brief(side)} is not allowed: give a whole number of pixels in 1..{MAX_FRAME_SIDE}")
        self.width, self.height = int(width), int(height)
        self.figure = Figure(figsize=(self.width / _DPI, self.height / _DPI), dpi=_DPI)
        self.canvas = FigureCanvasAgg(self.figure)
        fig = self.figure
        self._text = fig.text(0.01, 0.975, "", ha="left", va="top", family="monospace", fontsize=10, animated=True)
        # Axes boxes in figure fractions: [left, bottom, width, height].
        self.top = fig.add_axes((0.065, 0.12, 0.34, 0.72))
        self.side = fig.add_axes((0.475, 0.12, 0.34, 0.72))
        self.wind = fig.add_axes((0.845, 0.30, 0.145, 0.145 * self.width / self.height))
        self.top.set_title("top view", fontsize=9)
        self.top.set_xlabel("east y (m)", fontsize=8)
        self.top.set_ylabel("north x (m)", fontsize=8)
        self.side.set_title("side view, from the east", fontsize=9)
        self.side.set_xlabel("north x (m)", fontsize=8)
        self.side.set_ylabel("altitude -z (m)", fontsize=8)
        self._views = {}
        for ax in (self.top, self.side):
            ax.set_aspect("equal", adjustable="box")
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
            ax.plot([0.0], [0.0], marker="+", color="tab:green", markersize=14, mew=2)  # the hover target
            (box,) = ax.plot([], [], ls="--", lw=0.8, color="tab:red")  # the crash box, once in view
            # Moving parts are "animated": left out of the background, drawn on it per frame.
            (trail,) = ax.plot([], [], lw=1.0, color="0.55", animated=True)
            (rotor,) = ax.plot([], [], lw=1.2, color="tab:blue", animated=True)
            (body,) = ax.plot([], [], lw=2.5, color="0.15", solid_capstyle="round", animated=True)
            (mast,) = ax.plot([], [], lw=1.5, color="0.15", animated=True)
            (tail,) = ax.plot([], [], lw=1.0, color="0.15", animated=True)
            (nose,) = ax.plot([], [], marker="o", markersize=5, color="tab:orange", ls="", animated=True)
            self._views[ax] = (box, trail, rotor, body, mast, tail, nose)
        w = self.wind
        w.set_xlim(-1.15, 1.15)
        w.set_ylim(-1.15, 1.15)
        w.set_aspect("equal")
        w.set_xticks([])
        w.set_yticks([])
        w.set_title("wind (air moves)", fontsize=9)
        w.add_patch(Circle((0.0, 0.0), 1.0, fill=False, lw=0.8, color="0.5"))
        w.text(0.0, 1.02, "N", ha="center", va="bottom", fontsize=7)
        w.text(1.02, 0.0, "E", ha="left", va="center", fontsize=7)
        self._arrow_kind = FancyArrow
        self._arrow: Any = None
        self._wind_text = w.text(0.0, -1.12, "", ha="center", va="top", fontsize=8, animated=True)
        self._range: float | None = None
        self._background = None
        self._closed = False

    def pixel_box(self, part: str) -> tuple[int, int, int, int]:
        """Pixel box (row0, row1, col0, col1) of a part of every frame: ``"top"``, ``"side"``,
        ``"wind"`` (the compass and its speed) or ``"text"`` (the band of the text line)."""
        if part not in PARTS:  # 'nope' was a KeyError (T14-14)
            raise NeurohoverError(f"pixel_box part={brief(part)} is not allowed: give one of {', '.join(PARTS)}")
        if part == "text":
            return 0, int(math.ceil(_TEXT_BAND * self.height)), 0, self.width
        ax = {"top": self.top, "side": self.side, "wind": self.wind}[part]
        x0, y0, x1, y1 = ax.get_position().extents
        if part == "wind":
            y0 -= 0.08  # the speed written below the compass
        return (
            int(math.floor((1.0 - y1) * self.height)),
            int(math.ceil((1.0 - y0) * self.height)),
            int(math.floor(x0 * self.width)),
            int(math.ceil(x1 * self.width)),
        )

    def _set_range(self, r: float) -> None:
        if r == self._range:
            return
        self._range = r
        self._background = None  # new axis limits: the static parts are drawn again
        for ax, (box, *_rest) in self._views.items():
            ax.set_xlim(-r, r)
            ax.set_ylim(-r, r)
            m = MAX_POSITION
            if r > m:
                box.set_data([-m, m, m, -m, -m], [-m, -m, m, m, -m])
            else:
                box.set_data([], [])

    # not under house_style: its artists were made in the default style by __init__ and keep it when redrawn (the same
    # frames under a user's hostile matplotlibrc), and rcdefaults() would add about 0.5 ms to each 3.5 ms frame
    def draw(self, state: Sequence[float], wind: Sequence[float], text: str, trail: np.ndarray | None = None) -> np.ndarray:
        """One frame, an (height, width, 3) uint8 array.

        Parameters
        ----------
        state : sequence of 13 floats
            World state: velocity (3), position (3), body rates (3), quaternion (qx, qy, qz, qw).
        wind : sequence of 2 or 3 floats
            The MDP's world wind ``W`` (m/s): north, east (and down, ignored); the compass shows
            the air's motion ``-W`` (see the module docstring).
        text : str
            The line drawn above the views.
        trail : (n, 3) array, optional
            Recent world positions, oldest first.
        """
        s = _real_vector(state, (13,), "draw state", "velocity, position, body rates, quaternion qx, qy, qz, qw")  # 3 numbers were an IndexError (T14-14)
        w = _real_vector(wind, (2, 3), "draw wind", "the world wind north, east and down in m/s")
        if not isinstance(text, str):
            raise NeurohoverError(f"draw text={brief(text)} is not allowed: give a string (the line above the views)")
        track = np.zeros((0, 3)) if trail is None else real_values(trail, f"draw trail={brief(trail)} is not allowed: give an (n, 3) array of positions")
        if track.size and (track.ndim != 2 or track.shape[1] != 3):  # (2, 2) was NumPy's reshape error (T14-14)
            raise NeurohoverError(f"draw trail of shape {track.shape} is not allowed: give an (n, 3) array of world positions, oldest first")
        track = track.astype(np.float64, copy=False).reshape(-1, 3)
        if self._closed:  # drawn on a new figure of the same size
            self.__init__(self.width, self.height)  # type: ignore[misc]
        pos = s[3:6]
        rot = rotation_matrix(s[9], s[10], s[11], s[12])
        self._set_range(view_range(pos))

        def world(points: np.ndarray) -> np.ndarray:
            return points @ rot.T + pos

        shapes = [world(_ROTOR), world(_FUSELAGE), world(_MAST_LINE), world(_TAIL_ROTOR), world(_NOSE)]
        for ax, (_box, trail_line, *parts) in self._views.items():
            # Top view: (east, north); side view: (north, altitude).
            project = (lambda p: (p[:, 1], p[:, 0])) if ax is self.top else (lambda p: (p[:, 0], -p[:, 2]))
            trail_line.set_data(*project(track))
            for artist, points in zip(parts, shapes, strict=True):
                artist.set_data(*project(points))

        north, east = -float(w[0]), -float(w[1])  # the air moves along -W
        speed = math.hypot(north, east)
        if self._arrow is not None:
            self._arrow.remove()
            self._arrow = None
        if speed > 1e-9:
            # Arrow along the air's motion, its length proportional to the speed (capped at the rim).
            scale = min(speed / WIND_FULL_SCALE, 1.0) / speed
            dx, dy = east * scale, north * scale
            self._arrow = self._arrow_kind(
                0.0,
                0.0,
                dx,
                dy,
                width=0.06,
                head_width=0.22,
                head_length=min(0.25, 0.6 * math.hypot(dx, dy)),
                length_includes_head=True,
                color="tab:purple",
                animated=True,
            )
            self.wind.add_patch(self._arrow)
            self._wind_text.set_text(f"{speed:.2f} m/s")
        else:
            self._wind_text.set_text("calm")
        self._text.set_text(text)
        if self._background is None:
            self.canvas.draw()
            self._background = self.canvas.copy_from_bbox(self.figure.bbox)
        else:
            self.canvas.restore_region(self._background)
        for ax, (_box, *moving) in self._views.items():
            for artist in moving:
                ax.draw_artist(artist)
        if self._arrow is not None:
            self.wind.draw_artist(self._arrow)
        self.wind.draw_artist(self._wind_text)
        self.figure.draw_artist(self._text)
        return np.asarray(self.canvas.buffer_rgba())[:, :, :3].copy()

    @house_style
    def close(self) -> None:
        """Release the figure; a later :meth:`draw` makes a new one, as an environment's render() after close() does
        (it was an AttributeError; T43-B09). Safe to call twice."""
        self.figure.clear()
        self._closed = True


def _interactive_backend(name: str) -> bool:
    """Whether matplotlib backend ``name`` opens windows."""
    try:
        from matplotlib.backends import BackendFilter, backend_registry

        return name.lower() in backend_registry.list_builtin(BackendFilter.INTERACTIVE)
    except ImportError:  # matplotlib < 3.9
        from matplotlib import rcsetup

        return name.lower() in [b.lower() for b in getattr(rcsetup, "interactive_bk", [])]


class HumanWindow:
    """A matplotlib window showing frames, created on the first :meth:`show` (pyplot only here).

    Without a display (an Agg backend) the frames go nowhere and nothing fails, so a headless
    run in ``human`` mode behaves like a run without rendering.
    """

    def __init__(self, fps: float) -> None:
        if not finite_real(fps) or not fps > 0:  # 0 and NaN were taken (and 0 divided by at the first frame; T14-14)
            raise NeurohoverError(f"HumanWindow fps={brief(fps)} is not allowed: give a finite number of frames per second > 0")
        self.fps = float(fps)
        self._figure: Any = None
        self._image: Any = None
        self._warned = False

    @house_style
    def show(self, frame: np.ndarray) -> None:
        """Show ``frame``, an (height, width, 3) uint8 RGB image (or RGBA) as :meth:`HoverRenderer.draw` gives."""
        if not isinstance(frame, np.ndarray) or frame.dtype != np.uint8 or frame.ndim != 3 or frame.shape[2] not in (3, 4) or not frame.size:
            shown = f"an array of shape {frame.shape} and dtype {frame.dtype}" if isinstance(frame, np.ndarray) else brief(frame)
            raise NeurohoverError(f"HumanWindow frame {shown} is not allowed: give an (height, width, 3) uint8 RGB image (HoverRenderer.draw)")  # T14-14
        import matplotlib
        import matplotlib.pyplot as plt  # a window needs pyplot's figure manager

        if self._figure is None:
            h, w = frame.shape[:2]
            self._figure = plt.figure("neurohover", figsize=(w / _DPI, h / _DPI), dpi=_DPI)
            ax = self._figure.add_axes((0.0, 0.0, 1.0, 1.0))
            ax.set_axis_off()
            self._image = ax.imshow(frame)
        else:
            self._image.set_data(frame)
        if _interactive_backend(matplotlib.get_backend()):
            plt.pause(1.0 / self.fps)  # draws the window and paces the frames at the control rate
        elif not self._warned:
            self._warned = True
            warnings.warn(
                f"render_mode='human': matplotlib's backend {matplotlib.get_backend()!r} has no window (no display?); frames are drawn but not shown",
                stacklevel=3,
            )

    @house_style
    def close(self) -> None:
        if self._figure is not None:
            import matplotlib.pyplot as plt

            plt.close(self._figure)
            self._figure = None
            self._image = None


__all__ = ["FRAME_HEIGHT", "FRAME_WIDTH", "HoverRenderer", "HumanWindow", "rotation_matrix", "view_range"]
