"""Flight data: observations and actions of flown episodes at 10 Hz (docs/model.md, Learned models).

Saved as a NumPy ``.npz`` archive with a format tag, the episodes concatenated and their
lengths kept, so a file of any number of episodes loads back exactly; or, with
``dtype="float32"``, in about half the space, rounded to float32 (and loaded back as float64).
"""

from __future__ import annotations

import copy
import os
import zipfile
import zlib
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import NeurohoverError, brief, finite_real, float64_of, key_text, refuse_non_text_keys
from .filekinds import FLIGHT_DATA_KIND, refuse_suffix
from .flightmeta import check_meaning, check_policy_actions, flown_policy
from .jsontext import JSONError, json_text, plain_json, strict_json, unwritable_key
from .paths import path_text
from .sim.constants import ACTION_NAMES, EPISODE_STEPS, MAX_EPISODE_STEPS, OBS_NAMES

FORMAT = "neurohover-flight-data/1"
SAVE_DTYPES = ("float64", "float32")


def _check_declared_size(path: Path) -> None:
    """Refuse an archive whose arrays declare more than half the free memory, before reading them (a header declaring
    (1e11, 12) was a MemoryError of 8.73 TiB; sixth trial), or one holding a member twice (the last copy was read without a
    word, where other zip readers take the first; T30-B04). Members it cannot read are left to np.load to name."""
    from .procs import half_free_memory

    with open(path, "rb") as f:  # zipfile reads an archive with bytes in front; np.load took them for a pickle (T46-B02)
        if f.read(4) not in (b"PK\x03\x04", b"PK\x05\x06"):
            raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file: its zip archive has bytes in front of it: allowed {NPZ_WRITERS}")
    total = 0
    try:
        archive = zipfile.ZipFile(path)
    except NotImplementedError as err:  # a zip version past zipfile's: its message, not a traceback (T37-B02)
        raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file ({err}): allowed {NPZ_WRITERS}") from None
    with archive:
        names = archive.namelist()
        _check_members(path, archive)
        repeated = sorted(name for name, count in Counter(names).items() if count > 1)
        if repeated:
            raise NeurohoverError(
                f"{str(path)!r} is not a readable flight-data file: it holds member(s) {', '.join(repeated)} more than once "
                "(which copy counts is each zip reader's guess); save it again with FlightData.save"
            )
        for name in names:
            with archive.open(name) as f:
                try:
                    version = np.lib.format.read_magic(f)
                    read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                    shape, _, dtype = read(f)  # the header only, not the data
                except ValueError:
                    continue
            total += int(np.prod(shape, dtype=object)) * dtype.itemsize
    if total > half_free_memory():
        raise NeurohoverError(f"{str(path)!r} declares arrays of {total:,} bytes: more than half the memory free now; give a smaller file")


#: What a flight-data file may be, as its refusals say.
NPZ_WRITERS = "an .npz that neurohover or numpy.savez wrote"


def _member_array(z, name: str, path: Path, text: str = "") -> np.ndarray:
    """Array ``name`` of the open archive ``z``: np.load gives a NAME.npy that is no .npy as bytes (AttributeErrors; T46-B01).
    With ``text`` (what it holds), a 0-d str array as save writes it: bytes or a 1-element array were str()'s "b'...'" or
    "['...']", refused as no JSON or no flight data without naming the member (T50-B06)."""
    if not isinstance(value := z[name], np.ndarray):
        raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file: its member {name}.npy is no NumPy array: allowed {NPZ_WRITERS}")
    if text and (value.dtype.kind != "U" or value.ndim != 0):
        said, allowed = f"a {value.dtype} array of shape {value.shape}", f"a 0-d text array (NumPy dtype 'U', numpy.array(str)) holding {text}"
        raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file: its member {name}.npy holds {said}: allowed {allowed}, as save writes it")
    return value


#: The zip compression methods zipfile reads (stored, deflated, bzip2, lzma), and the flag bits it cannot read past:
#: encrypted (0), compressed patched data (5), strong encryption (6).
_ZIP_METHODS = {zipfile.ZIP_STORED: "stored", zipfile.ZIP_DEFLATED: "deflated", zipfile.ZIP_BZIP2: "bzip2", zipfile.ZIP_LZMA: "lzma"}
_ZIP_FLAGS = {0x1: "encrypted (flag bit 0)", 0x20: "compressed patched data (flag bit 5)", 0x40: "strongly encrypted (flag bit 6)"}
#: The arrays a flight-data file holds, each an .npy member.
_ARRAYS = ("format", "lengths", "observations", "actions", "metadata")


def _check_members(path: Path, archive: zipfile.ZipFile) -> None:
    """Refuse a member zipfile cannot read (encrypted, patched, or compressed by a method it lacks: Deflate64, zstd,
    AES), which was zipfile's RuntimeError or NotImplementedError (T37-B02), and one of the arrays stored without its
    .npy name, which NumPy hands back as bytes, preferred to the .npy member of that name (an AttributeError; T37-B03)."""
    for info in archive.infolist():
        flags = [said for bit, said in _ZIP_FLAGS.items() if info.flag_bits & bit]
        if flags or info.compress_type not in _ZIP_METHODS:
            said = flags[0] if flags else f"compressed by method {info.compress_type}, which zipfile does not read"
            methods = ", ".join(list(_ZIP_METHODS.values())[:-1]) + " or " + list(_ZIP_METHODS.values())[-1]
            raise NeurohoverError(
                f"{str(path)!r} is not a readable flight-data file: its member {brief(info.filename)} is {said}: "
                f"allowed {NPZ_WRITERS} (members {methods}; not encrypted)"
            )
        if info.filename in _ARRAYS:
            raise NeurohoverError(
                f"{str(path)!r} is not a readable flight-data file: its member {brief(info.filename)} is not allowed: "
                f"arrays are .npy members ({info.filename}.npy), as in {NPZ_WRITERS}"
            )


def _float64(values: np.ndarray, name: str, path: Path) -> np.ndarray:
    """A flight-data file's observations or actions as native float64, whatever their stored float dtype and byte order
    (a '>f8' file skipped the policy_flown check, T37-B04); a value past float64's range (np.longdouble's 1e400) is
    refused as no finite float64 number, without NumPy's overflow warning (T37-B10)."""
    native = float64_of(values)
    if values.dtype.itemsize > 8:  # wider than float64: its finite values may not be finite float64 numbers
        past = np.isinf(native) & np.isfinite(values)
        if past.any():
            k, i = (int(x) for x in np.argwhere(past)[0])
            raise NeurohoverError(
                f"flight-data file {str(path)!r}: its {name} row {k} column {i} = {brief(values[k, i])} is not allowed: "
                "it is no finite float64 number (past float64's range); give flight data as flown"
            )
    return native


def same_values(a: object, b: object) -> bool:
    """Value equality through dicts, lists and tuples, arrays compared whole: the same shape, dtype and values, NaN
    equal to NaN (the ``==`` of FlightData, Evaluation and PolicyTable, whose generated one was NumPy's ValueError)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):  # an array equals an array only, as a list a list
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)):
            return False
        return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc")
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_values(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(same_values(x, y) for x, y in zip(a, b, strict=True))
    try:
        return bool(a == b)
    except (ValueError, TypeError):  # a NumPy scalar against a list compares elementwise: not the same value
        return False


@dataclass(frozen=True, eq=False)  # eq=False: the generated == compared arrays as tuples, NumPy's ValueError (tenth trial)
class FlightData:
    """Flown episodes: ``observations[i]`` is (steps_i + 1, 12), ``actions[i]`` is (steps_i, 4).

    ``observations[i][k]`` is what the policy saw before choosing ``actions[i][k]`` (the clipped
    action the simulator applied); the last observation follows the last action. The arrays are read-only: copies of
    writeable ones given, so an edit cannot get past the checks made (T45-B07).

    ``==`` compares recordings: the same episodes (each array's shape, dtype and values, NaN equal to NaN) and
    equal metadata. Flight data are unhashable (they hold arrays), as a list is.

    ``metadata`` is free-form JSON: the keys ``fly --record`` writes (task, mdps, seed, returns, crashed,
    episode_steps, policy, policy_flown, safeguard_step, ...) are checked against the episodes and each other wherever present; any
    other key is the user's own note, kept as given (a documented choice: a misspelt key is kept, not refused).
    """

    observations: tuple[np.ndarray, ...]
    actions: tuple[np.ndarray, ...]
    metadata: dict = field(default_factory=dict)

    __hash__ = None  # type: ignore[assignment]  # mutable arrays: the generated hash was a TypeError on ndarray (tenth trial)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, FlightData):
            return NotImplemented
        return same_values((self.observations, self.actions, self.metadata), (other.observations, other.actions, other.metadata))

    def __post_init__(self) -> None:
        for name in ("observations", "actions"):  # a string was an AttributeError (fourth trial)
            arrays = getattr(self, name)
            if isinstance(arrays, (str, bytes, np.ndarray)) or not isinstance(arrays, (tuple, list)):
                raise NeurohoverError(f"flight data {name}={brief(arrays)} is not allowed: give a sequence of arrays, one per episode")
            _check_arrays(arrays, name, "flight data")
            # read-only: an edit after the checks below (an inf reading) was taken by observed_return and save (T45-B07)
            object.__setattr__(self, name, tuple(_frozen(a) for a in arrays))
        _metadata_text(self.metadata, "flight data")  # None, [1], {1: 2}, a NaN were taken, and refused or changed by save() (T15-29, T21-08)
        _check_episodes(self.observations, self.actions, "flight data")
        # metadata load() refuses (episode_steps -5, crashed 'x') was taken here and written by save() (T18-4)
        check_metadata(self.metadata, np.array([a.shape[0] for a in self.actions], dtype=np.int64), "flight data", (self.observations, self.actions))

    def check_again(self, where: str = "flight data") -> None:
        """The checks ``FlightData(...)`` runs, run again by each reader (the learners, Transitions, observed_return,
        ``+``, save): metadata may be edited after making (an edited safeguard_step ['a', None] was a TypeError in EC-MER,
        T43-B06), and the arrays replaced (``object.__setattr__``: 10 readings for 100 actions were NumPy's broadcast
        error in learn_lr, a wrong return in observed_return, taken by Transitions; T45-B06). The arrays themselves are
        read-only (T45-B07)."""
        for name in ("observations", "actions"):
            arrays = getattr(self, name)
            if not isinstance(arrays, tuple):
                raise NeurohoverError(f"{where}: its {name} {brief(arrays)} are not allowed: give a tuple of arrays, one per episode")
            _check_arrays(arrays, name, where)
        _check_episodes(self.observations, self.actions, where)
        _metadata_text(self.metadata, where)
        check_metadata(self.metadata, np.array([a.shape[0] for a in self.actions], dtype=np.int64), where, (self.observations, self.actions))

    @property
    def n_episodes(self) -> int:
        return len(self.actions)

    @property
    def n_transitions(self) -> int:
        return int(sum(a.shape[0] for a in self.actions))

    def __add__(self, other: FlightData) -> FlightData:
        if not isinstance(other, FlightData):
            return NotImplemented  # Python's TypeError ("unsupported operand"), as for any sum it cannot make
        self.check_again("flight data (the first of +)")  # an edited crashed of the wrong length was dropped without a word (T43-B06)
        other.check_again("flight data (the second of +)")
        if not self.actions or not other.actions:  # no episodes: they add none and contradict no entry (sum(..., empty) lost 'crashed')
            kept = other if not self.actions else self
            return FlightData(kept.observations, kept.actions, copy.deepcopy(kept.metadata))
        meta = {**self.metadata, **other.metadata}
        for name in set(meta) - {*_PER_EPISODE, "episode_steps", "policy_flown"}:  # one entry for the whole recording
            if name not in self.metadata or name not in other.metadata or not same_values(self.metadata[name], other.metadata[name]):
                del meta[name]  # the second's seed and policy were kept for every episode (T24-04), as its task was (ninth trial)
        for name in _PER_EPISODE:  # one entry per episode: both halves, or none (load() refuses a list of the wrong length)
            a, b = self.metadata.get(name), other.metadata.get(name)
            if name == "safeguard_step" and (a is None) != (b is None):  # a recording without: no fallback flew it (fly --record's)
                a, b = [-1] * self.n_episodes if a is None else a, [-1] * other.n_episodes if b is None else b
            if isinstance(a, list) and isinstance(b, list) and len(a) == self.n_episodes and len(b) == other.n_episodes:
                meta[name] = a + b
            else:
                meta.pop(name, None)
        a, b = self.metadata.get("episode_steps"), other.metadata.get("episode_steps")
        if type(a) is int and type(b) is int:  # every episode within the budget load() checks (ninth trial)
            meta["episode_steps"] = max(a, b)
            flags, lengths = meta.get("crashed"), [n.shape[0] for n in self.actions + other.actions]
            budgets = [a] * self.n_episodes + [b] * other.n_episodes  # a crash is charged for its own budget's steps left
            if isinstance(flags, list) and any((budget if c else n) < max(a, b) for c, n, budget in zip(flags, lengths, budgets)):
                del meta["episode_steps"]  # a shorter budget's full episodes or crashes: no one budget holds for all (T22-01)
        flown = self.metadata.get("policy_flown"), other.metadata.get("policy_flown")
        if any(f is not None for f in flown) and flown[0] != flown[1]:  # two policies flew them: EC-MER must not take one for both
            meta["policy_flown"] = None
        elif flown == (None, None) and "policy" not in meta and ("policy" in self.metadata or "policy" in other.metadata):
            meta["policy_flown"] = None  # older files of two policy names: EC-MER took the baseline for both once one was dropped (T24-04)
        return FlightData(self.observations + other.observations, self.actions + other.actions, meta)

    def recorded_policy(self, name: str = "flight data"):
        """The policy that flew these episodes as ``fly --record`` keeps it (metadata ``policy_flown``), for EC-MER; None
        where none is recorded. A file's name alone was looked up from another directory (ninth trial).

        Raises
        ------
        NeurohoverError
            If joined recordings of two policies record none (``policy_flown`` None), or the record is damaged.
        """
        if "policy_flown" in self.metadata and self.metadata["policy_flown"] is None:
            raise NeurohoverError(f"{name} were flown by more than one policy (joined recordings): EC-MER learns one closed loop; give --policy FILE")
        return flown_policy(self.metadata, name)  # one that is no policy: named as load() names it (T24-06)

    def save(self, path: str | Path, dtype: str = "float64") -> Path:
        """Write the flight data to ``path`` (a name ending ``.npz``, as ``fly --record`` takes), as float64 (exact) or
        float32 (half the space; a finite value past float32's range is refused, not written as inf)."""
        if not isinstance(dtype, str) or dtype not in SAVE_DTYPES:  # an array was NumPy's "truth value is ambiguous" (T16-12)
            raise NeurohoverError(f"flight-data dtype {brief(dtype)} is not allowed: use {' or '.join(SAVE_DTYPES)}")
        from .paths import output_file, writing

        meta_text = _metadata_text(self.metadata, "flight data")  # checked again: metadata may be changed after making
        if not self.actions or self.n_transitions == 0:
            raise NeurohoverError("flight data to save needs at least one step flown (load() refuses any other file)")
        text = path_text(path)  # an os.PathLike's text, not its repr (T33-B13)
        if isinstance(text, str) and text not in ("", "-") and not text.endswith("/") and not os.path.exists(text):
            check_npz_name(text)  # before output_file makes its directory; '', '-', 'dir/' and what exists it names as such
        # refuses '', a directory and a device (/dev/null was a struct.error), and another kind of neurohover file, through a link too (T34-B03)
        path = output_file(path, "flight-data file", kind=FLIGHT_DATA_KIND)
        check_npz_name(path)
        lengths = np.array([a.shape[0] for a in self.actions], dtype=np.int64)
        self.check_again()  # metadata changed after making (episode_steps -5) was written, then refused by load(); arrays replaced (T45-B06)
        for i, crashed in enumerate(crash_flags(self)):  # NaN readings were written, then refused by load() (T22-02's check)
            check_flown(self.observations[i], self.actions[i], crashed, f"flight data to save, episode {i}")
        if dtype == "float64":  # what load() checks of a float64 file: a policy_flown that does not give the actions (T24-06)
            check_policy_actions(self.metadata, self.observations, self.actions, "flight data")
        largest = float(np.finfo(dtype).max)
        for name in ("observations", "actions"):  # 1e300 was written as float32's inf, without a word (fifteenth trial, T15-29)
            big = max((float(np.abs(a[np.isfinite(a)]).max(initial=0.0)) for a in getattr(self, name)), default=0.0)
            if big > largest:
                raise NeurohoverError(f"flight data {name} hold {big:.3g}, past {dtype}'s largest value {largest:.4g}: save them as float64, or scale them")
        with writing(path, "flight-data file") as partial, open(partial, "wb") as f:  # a file object keeps numpy from appending ".npz"
            np.savez_compressed(
                f,
                format=np.array(FORMAT),
                lengths=lengths,
                observations=(np.concatenate(self.observations) if self.observations else np.zeros((0, 12))).astype(dtype),
                actions=(np.concatenate(self.actions) if self.actions else np.zeros((0, 4))).astype(dtype),
                metadata=np.array(meta_text),
            )
        return path

    @classmethod
    def load(cls, path: str | Path) -> FlightData:
        """Read flight data written by :meth:`save`; other files are refused with a clear message, as are metadata that
        contradict themselves or the episodes (:func:`check_metadata`). A float64 file's ``policy_flown`` (in either byte
        order, or wider: read as native float64 first, T37-B04) must give the first episode's first 200 recorded actions
        (T24-06: some milliseconds, whatever the file's size; a float32 file's rounded readings are left to EC-MER's check:
        :func:`neurohover.flightmeta.check_policy_actions`; float16 is refused)."""
        from .paths import input_file

        if not isinstance(path, (str, os.PathLike)):  # None was a TypeError (second trial); an os.PathLike is a path (T33-B13)
            raise NeurohoverError(f"flight-data file {path!r} is not allowed: give a path")
        path = input_file(path, "flight-data file")  # an empty path, a directory: named as such, not as missing
        if not zipfile.is_zipfile(path):  # np.load would try (and refuse) to unpickle anything else
            raise NeurohoverError(
                f"{str(path)!r} is not a neurohover flight-data file: flight data are .npz archives (written by neurohover fly --record or FlightData.save)"
            )
        try:
            _check_declared_size(path)
            with np.load(path, allow_pickle=False) as z:
                if "format" not in z.files or str(_member_array(z, "format", path, repr(FORMAT))) != FORMAT:
                    raise NeurohoverError(f"{str(path)!r} is not a neurohover flight-data file (expected format {FORMAT})")
                lengths, obs, act = (_member_array(z, name, path) for name in ("lengths", "observations", "actions"))
                metadata = strict_json(str(_member_array(z, "metadata", path, "a JSON object")))  # 100,000 deep was a RecursionError (ninth trial)
        except (OSError, ValueError, zipfile.BadZipFile, EOFError, KeyError, zlib.error) as err:  # zlib: damaged bytes (sixth trial)
            if isinstance(err, NeurohoverError):
                raise
            where = " in its member metadata.npy: allowed a JSON object, as save writes it" if isinstance(err, JSONError) else ""  # T50-B06
            raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file ({type(err).__name__}: {err}){where}") from None
        if lengths.ndim != 1 or lengths.dtype.kind not in "iu" or (lengths < 0).any():  # float or text lengths were NumPy errors
            raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file: its episode lengths are not one count (an integer >= 0) per episode")
        if lengths.size == 0:  # first: its metadata's lists, one entry per episode, were refused for not being empty (T21-12)
            raise NeurohoverError(f"flight-data file {str(path)!r} holds no transitions")
        if not isinstance(metadata, dict):  # a list was an AttributeError in learn-model (fifth trial)
            raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file: its metadata is a {type(metadata).__name__}, not a JSON object")
        if obs.dtype.kind != "f" or act.dtype.kind != "f":
            kinds = f"{obs.dtype} and {act.dtype}"
            raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file: its observations and actions are {kinds}, not real numbers")
        if obs.dtype.itemsize < 4 or act.dtype.itemsize < 4:  # float16: rounded past what the policy_flown check reads (T37-B04)
            kinds = f"{obs.dtype.name} and {act.dtype.name}"
            raise NeurohoverError(
                f"{str(path)!r} is not a readable flight-data file: its observations and actions are {kinds}: allowed float32 or wider "
                "(FlightData.save writes float64 or float32)"
            )
        if lengths.size and int(lengths.max()) > MAX_EPISODE_STEPS:  # 2**62 twice summed to a negative count (seventh trial)
            longest = int(lengths.max())
            raise NeurohoverError(f"{str(path)!r} is not a readable flight-data file: an episode of {longest:,} steps (at most {MAX_EPISODE_STEPS:,})")
        if (lengths == 0).any():  # a flown episode has at least one step, even one that crashes at once (ninth trial)
            raise NeurohoverError(
                f"{str(path)!r} is not a readable flight-data file: episode {int(np.argmin(lengths))} has 0 steps (a flown one has at least 1)"
            )
        check_metadata(metadata, lengths, f"flight-data file {str(path)!r}")  # what the lengths contradict, before the arrays
        if obs.shape != (int(lengths.sum() + lengths.size), 12) or act.shape != (int(lengths.sum()), 4):
            raise NeurohoverError(
                f"flight-data file {str(path)!r} is truncated or inconsistent: {lengths.size} episodes of {lengths.sum()} steps "
                f"but arrays {obs.shape} and {act.shape}"
            )
        # the readings the policy saw, not rounded (T24-06), in either byte order ('>f8' skipped the check: T37-B04)
        exact = obs.dtype.itemsize >= 8 and act.dtype.itemsize >= 8
        obs, act = _float64(obs, "observations", path), _float64(act, "actions", path)  # float32 loads as float64, as all here
        obs.setflags(write=False)  # their episodes' views are then not copied (_frozen)
        act.setflags(write=False)
        obs_split = np.split(obs, np.cumsum(lengths + 1)[:-1])
        act_split = np.split(act, np.cumsum(lengths)[:-1])
        check_metadata(metadata, lengths, f"flight-data file {str(path)!r}", (tuple(obs_split), tuple(act_split)))  # and the readings (T23-03, T23-19)
        bad = unwritable_key(metadata)  # a NaN no check above names (T32-B18)
        if bad is not None:  # it was refused as metadata that "cannot be saved", the file not named
            raise NeurohoverError(
                f"flight-data file {str(path)!r}: its metadata {key_text(bad)}={brief(metadata[bad])} is not allowed: "
                "give strict JSON values, numbers finite (NaN and Infinity are no JSON: FlightData.save refuses them)"
            )
        deep = _too_deep(metadata)
        if deep:
            raise NeurohoverError(f"flight-data file {str(path)!r}: its metadata {deep}")
        data = cls(tuple(obs_split), tuple(act_split), metadata)
        for i, crashed in enumerate(crash_flags(data)):  # a NaN was named by plot, not by learn-model, and neither named the file (T22-02)
            check_flown(data.observations[i], data.actions[i], crashed, f"flight-data file {str(path)!r}, episode {i}")
        if exact:  # after check_flown: the readings the policy is flown on are finite
            check_policy_actions(metadata, data.observations, data.actions, f"flight-data file {str(path)!r}")
        return data


def _check_arrays(arrays: tuple | list, name: str, where: str) -> None:
    """Refuse ``arrays`` (a FlightData's ``name``) unless each is a plain array of real numbers: a masked array was stored
    as it was, its hidden values learned from (T16-9); an np.matrix, and save() was a TypeError (T28-B06)."""
    if not all(type(a) is np.ndarray and a.dtype.kind in "fi" for a in arrays):
        other = next((type(a).__name__ for a in arrays if isinstance(a, np.ndarray) and type(a) is not np.ndarray), None)
        note = f" (not {other}: give np.asarray of it)" if other and other != "MaskedArray" else ""
        raise NeurohoverError(f"{where} {name} must be arrays of real numbers (plain, not masked), one per episode{note}")


def _check_episodes(observations: tuple, actions: tuple, where: str) -> None:
    """Refuse episodes whose observations and actions do not pair up as flown: (T+1, 12) readings for (T, 4) actions, T >= 1."""
    if len(observations) != len(actions):
        raise NeurohoverError(f"{where} needs one action array per observation array, got {len(observations)} and {len(actions)}")
    for i, (obs, act) in enumerate(zip(observations, actions)):
        if obs.ndim != 2 or obs.shape[1] != 12 or act.ndim != 2 or act.shape[1] != 4 or obs.shape[0] != act.shape[0] + 1:
            raise NeurohoverError(f"{where}, episode {i}: observations must be (T+1, 12) and actions (T, 4), got {obs.shape} and {act.shape}")
        if act.shape[0] == 0:  # written by save(), then refused by load() (T22-19)
            raise NeurohoverError(f"{where}: episode {i} has 0 steps (a flown one has at least 1)")


def _frozen(array: np.ndarray) -> np.ndarray:
    """``array`` read-only, copied first unless no one can write its memory (a read-only array, or a read-only view of one,
    as :meth:`FlightData.load` and ``+`` give): the caller's array stays theirs, writeable (T45-B07)."""
    owner = array if array.flags.owndata else array.base
    if array.flags.writeable or not isinstance(owner, np.ndarray) or owner.flags.writeable:
        array = array.copy()
    array.setflags(write=False)
    return array


def crash_flags(data: FlightData) -> list[bool]:
    """Whether each episode of ``data`` crashed: its flag as flown (the ``crashed`` metadata every recording holds), or,
    in files recorded before 2026-12-04, whether it is shorter than the metadata's ``episode_steps`` (default 6000)."""
    return _flags(data.metadata, [a.shape[0] for a in data.actions])


def _flags(metadata: object, lengths) -> list[bool]:
    """:func:`crash_flags` of metadata and episode lengths (check_metadata's, before the flight data are made)."""
    meta = metadata if isinstance(metadata, dict) else {}
    flags = meta.get("crashed")
    if isinstance(flags, list) and len(flags) == len(lengths):
        return [bool(c) for c in flags]
    steps = meta.get("episode_steps")
    steps = steps if type(steps) is int else EPISODE_STEPS  # checked where the metadata are (check_metadata)
    return [int(n) < steps for n in lengths]


def check_flown(observations: np.ndarray, actions: np.ndarray, crashed: bool, where: str) -> None:
    """Refuse an episode's readings that no flight gives, naming ``where`` (the file and episode), the step, the variable
    and its value: a NaN or infinite observation (the simulator's are finite, a crash's last one too, out of bounds as it
    may be), or a non-finite action but the last of a ``crashed`` episode (a policy's NaN action is recorded as given,
    and crashes the episode there). The one check of flight data as flown: :meth:`FlightData.load`, plots and learned
    models' transitions (a file of NaN observations drew empty panels, T21-04; learn-model named no file, episode or
    step, T22-02)."""
    for kind, values, names, last in (("observation", observations, OBS_NAMES, 0), ("action", actions, ACTION_NAMES, int(crashed))):
        bad = np.argwhere(~np.isfinite(values[: values.shape[0] - last]))
        if bad.size:
            k, i = (int(x) for x in bad[0])
            count = f" ({len(bad) - 1:,} more of the episode's {kind} readings are NaN or infinite)" if len(bad) > 1 else ""
            but = "but as a crashed episode's last" if kind == "action" else "a crash's last one included"
            raise NeurohoverError(
                f"{where}: step {k} reads {names[i]} = {values[k, i]}{count}: no flight records a NaN or infinite {kind}, {but}; give flight data as flown"
            )


def check_npz_name(path: str | Path, what: str = "flight-data file") -> None:
    """Refuse a flight-data file whose name does not end .npz, naming it as ``what`` (``fly --record`` passes its
    option): 'x.txt' was written as a NumPy archive under that name (T21-09), rx.csv held one (twelfth trial, S2)."""
    refuse_suffix(str(path), what, (".npz",), "flight data are a NumPy archive", "flight.npz")


#: The metadata lists of one entry per episode: name -> (what an entry must be, what it is called).
_PER_EPISODE = {
    "returns": (finite_real, "one number"),
    "mdps": (lambda m: isinstance(m, dict), "one MDP (a table)"),
    "crashed": (lambda c: type(c) is bool, "one true or false"),
    # evaluate(record=True, safeguard=...) writes it: the step its fallback took over at, and flew on from; -1: never (T42-B03)
    "safeguard_step": (lambda s: type(s) is int and s >= -1, "one control step (-1: no fallback flew it; k: one flew from step k on)"),
}


def _check_dict(metadata: object, where: str) -> dict:
    """``metadata`` if it is a dict, as flight data and their files hold; else one error naming it."""
    if not isinstance(metadata, dict):
        raise NeurohoverError(f"{where}: its metadata {brief(metadata)} is not allowed: give a dict (a JSON object)")
    return metadata


def _metadata_text(metadata: object, where: str) -> str:
    """The JSON text :meth:`FlightData.save` writes of ``metadata``, or one error naming what load() would not read back
    as given: metadata that is no dict (5 was written, then refused), a value that is no strict JSON (an object() was a
    TypeError mid-write, a NaN written and read back; T16-24) and a key that is not text (JSON writes {1: 2} as {'1': 2},
    other metadata; T21-08). The one check of metadata, when flight data are made and when they are saved."""
    metadata = _check_dict(metadata, where)
    refuse_non_text_keys(metadata, where)
    try:
        text = json_text(metadata, default=plain_json)
    except (TypeError, ValueError, RecursionError) as err:
        bad = unwritable_key(metadata)  # the entry to name, where one alone fails
        shown = f", not {key_text(bad)}={brief(metadata[bad])}" if isinstance(bad, str) else ""
        raise NeurohoverError(f"{where} metadata cannot be saved as JSON: give strict JSON values (numbers finite){shown} ({err})") from None
    deep = _too_deep(metadata)
    if deep:
        raise NeurohoverError(f"{where} metadata {deep}")
    return text


def _too_deep(metadata: dict) -> str:
    """Which metadata value nests more lists or tables than :data:`~neurohover.jsontext.MAX_NOTE_DEPTH`, in words ('' when
    none does): a note 600 deep loaded, and the flight data could then not be deep-copied or pickled (T33-B03)."""
    from .jsontext import MAX_NOTE_DEPTH, nesting_depth

    bad = next((k for k, v in metadata.items() if nesting_depth(v) > MAX_NOTE_DEPTH), None)
    if bad is None:
        return ""
    return f"{key_text(bad)}={brief(metadata[bad])} is not allowed: it is nested more than {MAX_NOTE_DEPTH} lists or tables deep"


def check_metadata(metadata: object, lengths: np.ndarray, where: str, episodes: tuple[tuple, tuple] | None = None) -> None:
    """Refuse the metadata fields plots and crash marks read when they are of the wrong kind, by name (an episode_steps
    "a" was a ValueError in plot; seventh trial), and metadata the episodes contradict (ninth trial): an episode longer
    than ``episode_steps``, or one shorter whose ``crashed`` flag is false (T22-01; a crash may come on the last step, so
    a crashed episode of ``episode_steps`` steps is one). Files without either entry (recorded before ``crashed`` was)
    are checked as far as they go.

    Parameters
    ----------
    metadata : dict
        The flight data's metadata (anything else is refused).
    lengths : (episodes,) int array
        The steps of each episode.
    where : str
        What the messages name: ``"flight-data file 'f.npz'"`` (:meth:`FlightData.load`) or ``"flight data"`` (flight data
        built in Python, checked before a plot: fourteenth trial).
    episodes : (observations, actions), optional
        Each episode's arrays, where they are known: the metadata are also checked against them (returns, crash flags).
        The metadata against themselves and the episodes: :func:`neurohover.flightmeta.check_meaning` (T23-02..T23-19).
    """
    metadata = _check_dict(metadata, where)
    n_episodes = lengths.size
    steps = metadata.get("episode_steps")
    if steps is not None and (type(steps) is not int or not 1 <= steps <= MAX_EPISODE_STEPS):
        allowed = f"an integer in 1..{MAX_EPISODE_STEPS:,}"
        raise NeurohoverError(f"{where}: its metadata episode_steps={brief(steps)} is not allowed: {allowed}")
    if steps is not None and n_episodes and int(lengths.max()) > steps:  # an episode of 12,000 steps spanned a reset (ninth trial)
        longest = int(np.argmax(lengths))
        raise NeurohoverError(
            f"{where}: episode {longest} has {int(lengths[longest]):,} steps, more than its metadata's "
            f"episode_steps={steps:,} (every episode ends at that budget): its lengths and metadata contradict"
        )
    for name in ("task", "policy"):  # shown in titles and notes (a task 5 or a policy 123 was taken; eighth trial)
        if metadata.get(name) is not None and not isinstance(metadata[name], str):
            raise NeurohoverError(f"{where}: its metadata {name}={brief(metadata[name])} is not allowed: give text")
    flown_policy(metadata, where)  # a policy_flown 'x' was taken by load, plot and LR, refused by EC-MER alone (T24-06)
    for name, (fits, each) in _PER_EPISODE.items():  # lists of one entry per episode (returns "x" was taken; eighth trial)
        value = metadata.get(name)  # present as null: refused by name, not taken as absent (mdps null, T21-05)
        if name in metadata and (not isinstance(value, list) or len(value) != n_episodes or not all(fits(v) for v in value)):
            raise NeurohoverError(f"{where}: its metadata {name}={brief(value)} is not allowed: {each} per episode ({n_episodes}), or no {name} entry")
    handed = metadata.get("safeguard_step") or []
    late = next((i for i, k in enumerate(handed) if k >= lengths[i]), None)
    if late is not None:  # the fallback takes over at a step it flies: one of 0..steps-1
        raise NeurohoverError(
            f"{where}: its metadata safeguard_step={brief(handed)} is not allowed: episode {late} has {int(lengths[late]):,} steps, yet "
            f"its fallback took over at step {handed[late]:,}: allowed -1 (never) or 0..{int(lengths[late]) - 1:,}"
        )
    flags = metadata.get("crashed")
    uncrashed = [i for i, c in enumerate(flags) if not c and lengths[i] < steps] if steps is not None and flags is not None else []
    if uncrashed:  # 3000 steps of a 6000-step budget, crashed false, were drawn as "3000 steps, no crash" and learned from (T22-01)
        i = uncrashed[0]
        raise NeurohoverError(
            f"{where}: episode {i} has {int(lengths[i]):,} steps, fewer than its metadata's episode_steps={steps:,}, yet its crashed "
            "flag is false (an episode that does not crash flies the whole budget): its lengths and metadata contradict"
        )
    task, mdps = metadata.get("task"), _checked_mdps(metadata.get("mdps") or [], where)
    for i, mdp in enumerate(mdps):  # a task 'ghh09' over ghh08's MDPs was plotted under the wrong name (ninth trial)
        if task is not None and mdp is not None and mdp.family != task:
            raise NeurohoverError(f"{where}: its metadata task {brief(task)} is not its MDPs' family: episode {i} flew a {brief(mdp.family)} MDP")
    checked = None if episodes is None else (*episodes, _flags(metadata, lengths.tolist()))
    check_meaning(metadata, mdps, checked, where)  # what the fields say, against each other and the readings (T23-02..T23-19)


def _checked_mdps(tables: list, where: str) -> list:
    """The MDP of each table of a metadata ``mdps`` list (None for ``{}``, an MDP not recorded), its values checked as
    the MDP's own (:meth:`MDP.from_dict`): a dt 0 or a NaN parameter was plotted and learned from without a word (T21-05)."""
    from .tasks import MDP

    mdps: list = []
    known: dict[str, object] = {}  # the same table once: fly --record writes one per episode, most of them alike
    for i, table in enumerate(tables):
        try:
            text = json_text(table, default=plain_json, sort_keys=True)
        except (TypeError, ValueError, RecursionError):  # no JSON (changed after making): checked here, named by save()
            text = ""
        if not text or text not in known:
            try:
                known[text] = MDP.from_dict(table) if table else None
            except NeurohoverError as err:
                raise NeurohoverError(f"{where}: its metadata mdps entry {i} is not allowed: {err}") from None
        mdps.append(known[text])
    return mdps
