"""``neurohover plot``: PNG plots of recorded flights and of competition results.

``neurohover plot FLIGHT.npz [--out DIR]`` draws each episode of a flight-data file (written by
``neurohover fly --record``) to ``DIR/<name>-episode<i>.png`` (a name too long for that cut at its
end): position error, velocity, attitude (roll, pitch, yaw), angular rates and actions over time, a
crash (an episode shorter than 6000 steps) marked in red. ``DIR`` defaults to the file's directory.
Figures of another flight of the same name that ``DIR`` holds are left there and named on stderr. A plot into a
``DIR`` another plot is writing is refused, naming its pid.

``neurohover plot --compete DIR [DIR ...] [--out OUTDIR]`` overlays the mean cumulative error of
several ``neurohover compete --out DIR`` results (their ``episodes.csv``; agent and task from
``summary.json``) on one figure, linear and log scale, written to ``OUTDIR/compete.png``;
``OUTDIR`` defaults to the directory holding the first DIR. A ``summary.json`` that its
``episodes.csv`` contradicts (another task's or MDP set's rows, other runs, episodes, episode
steps, crashes or returns) is refused, naming the field and both values; so is what compete never
writes: a key or column of another name, a value of another kind or range (a positive mean return, a
sigma on a task without one, a seed 'x'), a run on two MDPs or on an MDP its runs never fly, a
safeguard firing or another policy for an agent without one (neurohover.compete_files).

The files written are printed, one per line.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path

from ..errors import FloatRangeError, NeurohoverError, brief
from .options import integer

COMPETE_PNG = "compete.png"
#: Figures of another flight named in plot's note, at most (the rest counted).
_NAMED = 8


def _episodes(text: str | None, n: int) -> list[int] | None:
    """``--episodes 0,3,10-12`` as episode indices (None: every episode), each checked against ``n``."""
    if text is None:
        return None
    out: list[int] = []
    for part in text.split(","):
        lo, sep, hi = part.strip().partition("-")
        try:
            first, last = integer(lo), integer(hi) if sep else integer(lo)
        except FloatRangeError as err:  # more digits than Python reads (T53-A01)
            raise NeurohoverError(f"--episodes {err}; the flight data hold episodes 0..{n - 1}") from None
        except ValueError:
            raise NeurohoverError(f"--episodes {text!r} is not allowed: give episode numbers and ranges, e.g. 0,3,10-12") from None
        if last < 0:  # '0--1' was a reversed range, and its example -1-0 refused (T41-A04)
            raise NeurohoverError(
                f"--episodes {part.strip()!r} is not allowed: {last} is no episode number (they are 0 or more: the flight data hold "
                f"episodes 0..{n - 1}); give FIRST-LAST with 0 <= FIRST <= LAST, e.g. 0-{n - 1}"
            )
        if first > last and first < n:  # both ends may be in range: "out of range" misled (seventh trial)
            raise NeurohoverError(f"--episodes {part.strip()!r} is a reversed range: give FIRST-LAST with FIRST <= LAST, e.g. {last}-{first}")
        if not (0 <= first <= last < n):
            raise NeurohoverError(f"--episodes {part.strip()!r} is out of range: the flight data hold episodes 0..{n - 1}")
        twice = sorted(set(out) & set(range(first, last + 1)))
        if twice:  # '0,0' would draw the same file twice
            raise NeurohoverError(f"--episodes {text!r} names episode {twice[0]} more than once: give each episode once")
        out.extend(range(first, last + 1))
    return out


def _fitting_stem(stem: str, out: Path, n: int) -> str:
    """``stem`` cut at its end until ``<stem>-episode<i>.png`` fits a file name in ``out``, saying so on stderr: fly
    --record takes a name up to the limit, and plot then refused the figures' longer names."""
    from ..filekinds import fitting_name, name_limit

    end = "-episode" + "0" * len(str(max(n - 1, 0))) + ".png"
    fitted = fitting_name(stem, name_limit(out), room=len(os.fsencode(end)))
    if fitted != stem:
        print(f"neurohover plot: note: the figures are named {brief(fitted)}-episode<i>.png: the flight's whole name is too long for them", file=sys.stderr)
    return fitted


def _note_left(out: Path, stem: str, n: int) -> None:
    """Say (stderr) which ``<stem>-episode<i>.png`` in ``out`` no plot of this flight writes: another flight of
    the same name's figures, left in the folder beside this one's, as ``report`` says of its own (T42-A03). Never removed:
    they are a person's files as much as neurohover's."""
    width = len(str(max(n - 1, 0)))
    own = {f"{stem}-episode{i:0{width}d}.png" for i in range(n)}
    pattern = re.compile(re.escape(stem) + r"-episode[0-9]+\.png")
    try:
        stale = [p.name for p in out.iterdir() if pattern.fullmatch(p.name) and p.name not in own and p.is_file()]
    except OSError:  # the folder unreadable after writing: nothing to say
        return
    if stale:
        from ..paths import printable

        stale.sort(key=lambda name: (len(name), name))  # episode2 before episode10
        named = ", ".join(stale[:_NAMED]) + (f" and {len(stale) - _NAMED} more" if len(stale) > _NAMED else "")
        print(
            f"neurohover plot: note: {printable(out)!r} holds figures of another flight named {stem!r} (this one has {n} "
            f"episode(s)), left in the folder (remove them if unwanted): {named}",
            file=sys.stderr,
        )


def cmd_plot(args: argparse.Namespace) -> int:
    """Plot a recorded flight (one PNG per episode) or overlay competition results (one PNG)."""
    from ..paths import input_file, output_dir, printable, refuse_pseudo_fs

    if args.flight is not None and args.compete:
        raise NeurohoverError("give either a flight-data file or --compete DIR ..., not both")
    if args.compete and args.episodes is not None:
        raise NeurohoverError("--episodes picks episodes of a flight-data file; it does not apply to --compete")
    if args.flight is None and not args.compete:
        raise NeurohoverError("nothing to plot: give a flight-data file (neurohover fly --record) or --compete DIR ...")
    if args.flight is not None:
        from ..flightdata import FlightData

        path = input_file(args.flight, "FLIGHT", "flight-data file")
        data = FlightData.load(path)  # refuses anything but flight data, with the reason
        if args.out is None:  # plot /dev/stdin wrote its figures into /dev (T46-A05)
            refuse_pseudo_fs(path.parent, "plot's default --out (FLIGHT's folder)", path.parent, into=True, instead="give --out DIR")
        out = output_dir(args.out if args.out is not None else path.parent, "--out")
        from ..plots import plot_flight_data, sole_plot

        stem = _fitting_stem(path.stem, out, data.n_episodes)
        with sole_plot(out, "--out"):  # two at once mixed two flights' episodes without a note (T47-A03)
            written = plot_flight_data(data, out, stem=stem, episodes=_episodes(args.episodes, data.n_episodes))
            _note_left(out, stem, data.n_episodes)
    else:
        from ..compete import check_against_store
        from ..compete_files import read_compete_dirs
        from ..plots import compete_figure, save_figure, sole_plot

        results = read_compete_dirs(args.compete)  # every directory checked and read before anything is written
        for folder in args.compete:  # and against the stores they name (T38-B06)
            check_against_store(folder)
        out = output_dir(args.out if args.out is not None else results[0].path.resolve().parent, "--out")
        with sole_plot(out, "--out"):
            written = [save_figure(compete_figure(results), out / COMPETE_PNG)]
    for p in written:
        print(printable(p))  # a newline or U+202E in --out split or reversed the line (fourteenth trial, T14-24)
    return 0


def register(sub) -> None:
    p = sub.add_parser(
        "plot",
        help="plot recorded flights (fly --record) or overlay competition results (compete --out)",
        description=(cmd_plot.__doc__ or "") + "\n\n" + __doc__.split("\n\n", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("flight", nargs="?", metavar="FLIGHT.npz", help="flight data written by neurohover fly --record")
    p.add_argument("--compete", nargs="+", metavar="DIR", help="directories written by neurohover compete --out, overlaid on one figure")
    p.add_argument("--out", metavar="DIR", help="directory for the PNG files (default: beside the input)")
    p.add_argument("--episodes", metavar="LIST", help="flight data: only these episodes (0-based), e.g. 0,3,10-12 (default: every episode, about 1 s each)")
    p.set_defaults(func=cmd_plot)


__all__ = ["cmd_plot", "register"]
