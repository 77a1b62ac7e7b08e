"""The sensor model of an MDP: what the policy sees when the sensors are noisy or late (docs/benchmarks.md).

The simulator's transition dynamics are noisy but its observations are exact; the paper (Section
7) names noisy sensors as the harder benchmark it leaves out. A :class:`Sensor` makes the 12
observation entries that the policy, the safeguard and the recorded flight data see

    reading_k = o_k + e_k,   e_0 = std z_0,   e_k = rho e_(k-1) + sqrt(1 - rho^2) std z_k

(z_k: 12 standard normals from the episode's own sensor stream, so noise never shifts the gusts;
std: one per group of three entries), delivered ``delay`` control steps late (the reset's reading
until the first one arrives), and each reading after the reset's lost with probability ``dropout``
(a 13th normal of the stream decides; the policy keeps the reading delivered last, as a controller
holds its last motion-capture frame through an occlusion). Reward and crash test stay on the true
state, as in the simulator.
``rho = 0`` is white noise; ``rho`` near 1 drifts as motion-capture errors do. The exact sensor
(all zero) leaves every result bit-identical to a simulator without one.

=============  =======  ==========================================================
setting        unit     meaning
=============  =======  ==========================================================
velocity       m/s      std of the noise on u, v, w (body frame), 0..100
position       m        std of the noise on x, y, z (body frame), 0..100
rates          rad/s    std of the noise on p, q, r, 0..100
attitude       1        std of the noise on the quaternion's qx, qy, qz, 0..100
correlation    1        AR(1) coefficient rho of the noise, 0 <= rho < 1
delay          steps    control steps (0.1 s each) the readings arrive late, 0..10
dropout        1        probability that a reading is lost (the last one held), 0 or 2**-52 <= p < 1
=============  =======  ==========================================================

A noise *level* L is the profile ``L * (0.1 m/s, 0.1 m, 0.1 rad/s, 0.01)``: at level 1 each
entry's noise is about the size of the baseline policy's typical hovering error on it. A std above 0 but
below 2**-52 (``MIN_STD``, drift's smallest walk) changes no reading and is refused, as is a level whose
attitude std falls below it (``MIN_LEVEL``) and a dropout above 0 but below 2**-52 (``MIN_DROPOUT``).
"""

from __future__ import annotations

import decimal
import math
import operator
import re
from dataclasses import asdict, dataclass, fields, replace

from ..errors import (
    FloatRangeError,
    NeurohoverError,
    brief,
    comma_separated,
    finite_real,
    float_of,
    lowest_allowed,
    real_number,
    setting_float,
    whole_in,
    whole_number,
)
from ..sim.constants import MAX_SENSOR_DELAY, MIN_NOISE, SENSOR_GROUPS

#: The std of each group at noise level 1 (velocity m/s, position m, rates rad/s, attitude).
LEVEL_PROFILE = (0.1, 0.1, 0.1, 0.01)
#: The largest std of a group: 100 m/s, m or rad/s is twenty times the crash box's 5 m/s (and 20 m), so readings
#: carry nothing of the state; a larger value is a typo (e.g. 1e300 would overflow a policy's hidden layer).
MAX_STD = 100.0
#: The largest noise level: the one whose profile reaches MAX_STD.
MAX_LEVEL = MAX_STD / max(LEVEL_PROFILE)
#: The smallest std of a group but 0 (exact), float64's epsilon 2**-52 as drift's smallest walk: below it a reading
#: is the true value (1e-320 flew exact sensors, recorded as noisy; T44-A04). The smallest level is the one whose profile reaches it.
MIN_STD = MIN_NOISE
MIN_LEVEL = MIN_STD / min(LEVEL_PROFILE)
_TOO_SMALL = "too small to change a reading (below 2**-52)"
#: The smallest dropout but 0 (none), 2**-52 as the stds': a reading is lost where Phi(z') < p, z' a 13th normal drawn each step
#: for any p > 0, so below it under 2e-4 of a reading is lost in the 10**12 steps a call may fly, yet z' shifts all later noise (T59-B01).
MIN_DROPOUT = MIN_NOISE


def _is_number(text: str) -> bool:
    """Whether ``text`` reads as a number (a bare noise level), for naming what is wrong with a setting."""
    try:
        float_of(text)  # '1_0' is no number here either
    except ValueError:
        return False
    return True


@dataclass(frozen=True)
class Sensor:
    """Noisy, correlated, late sensors; ``Sensor()`` is exact (see the module docstring's table)."""

    velocity: float = 0.0
    position: float = 0.0
    rates: float = 0.0
    attitude: float = 0.0
    correlation: float = 0.0
    delay: int = 0
    dropout: float = 0.0

    def __post_init__(self) -> None:
        for name in (*SENSOR_GROUPS, "correlation"):
            value = getattr(self, name)
            # correlation's range, not "a finite number >= 0", for -0.5 or '2' as for 1.5 (T48-B08)
            allowed = "0 <= correlation < 1" if name == "correlation" else "a finite number >= 0"
            if not real_number(value):  # NumPy's numbers are numbers too; not a bool, nor a NumPy time (T17-1)
                raise NeurohoverError(f"sensor {name}={brief(value)} is not a number: allowed {allowed}")
            if not finite_real(value) or value < 0:  # np.timedelta64 was float()'s TypeError (T17-1), 10**400 an OverflowError
                raise NeurohoverError(f"sensor {name}={brief(value)} is out of range: allowed {allowed}")
            number = setting_float(value)  # np.float32(0.1) as 0.1 (T56-B03), -0.0 as 0.0: one competition (T56-B04)
            if name != "correlation" and number > MAX_STD:
                raise NeurohoverError(f"sensor {name}={value!r} is out of range: allowed a std in 0..{MAX_STD:g}")
            if name != "correlation" and 0 < number < MIN_STD:
                allowed = f"allowed 0 (exact) or a std in {lowest_allowed(MIN_STD)}..{MAX_STD:g}"
                raise NeurohoverError(f"sensor {name}={brief(value)} is out of range, {_TOO_SMALL}: {allowed}")
            object.__setattr__(self, name, number)
        if self.correlation >= 1.0:
            raise NeurohoverError(f"sensor correlation={self.correlation!r} is out of range: allowed 0 <= correlation < 1")
        if self.correlation > 0 and not any(getattr(self, name) for name in SENSOR_GROUPS):  # it did nothing (fifth trial)
            raise NeurohoverError(f"sensor correlation={self.correlation!r} applies to noise: give a level or the stds beside it")
        p = self.dropout
        if not real_number(p):  # np.array(0.1) was called out of range, a value refused for its type (T33-B16)
            raise NeurohoverError(f"sensor dropout={brief(p)} is not a number: allowed a probability 0 <= dropout < 1")
        if not finite_real(p) or not 0 <= p < 1:  # NaN fails the comparison too; np.timedelta64 is no number (T17-1)
            raise NeurohoverError(f"sensor dropout={brief(p)} is out of range: allowed a probability 0 <= dropout < 1")
        p = setting_float(p)  # np.float32 as the decimal it prints as, compared and kept (T56-B03)
        if 0 < p < MIN_DROPOUT:  # every path (from_dict, parse, from_row_values, MDP rows) builds a Sensor here (T59-B01)
            allowed = f"allowed 0 (none) or a probability {lowest_allowed(MIN_DROPOUT)} <= dropout < 1"
            raise NeurohoverError(f"sensor dropout={brief(self.dropout)} is out of range, too small to lose a reading in practice (below 2**-52): {allowed}")
        object.__setattr__(self, "dropout", p)
        # T24-11: whole_in, so 1.5 or True "is not allowed" (a type) and -1 "is out of range"; both said out of range
        delay = whole_in(self.delay, "sensor delay", 0, MAX_SENSOR_DELAY, f"{MAX_SENSOR_DELAY} (control steps)")
        object.__setattr__(self, "delay", delay)  # a NumPy integer as the int it is

    @property
    def exact(self) -> bool:
        """Whether the sensors report the true observation at once (no noise, no delay)."""
        return self == EXACT

    @property
    def stds(self) -> tuple[float, float, float, float]:
        """The noise std of each group of three observation entries (velocity, position, rates, attitude)."""
        return (self.velocity, self.position, self.rates, self.attitude)

    def row_values(self) -> tuple[float, ...]:
        """The seven numbers of an MDP row's sensor slots (``sim.constants.ROW_SENSOR``)."""
        return (*self.stds, self.correlation, float(self.delay), self.dropout)

    @classmethod
    def from_row_values(cls, values) -> Sensor:
        """The sensor of an MDP row's seven sensor slots (refused clearly when they are not a valid sensor)."""
        try:  # 3 values were an IndexError, None a TypeError, 9 values a sensor of the first seven (thirteenth trial, F10)
            items = list(values)
            # Numbers only: text such as '1' was read as 1.0 and then refused as "correlation=1.0" (T14-21).
            v = [float(x) for x in items] if all(real_number(x) for x in items) else []
        except (TypeError, OverflowError):
            v = []
        if len(v) != 7:
            raise NeurohoverError(
                f"sensor row values {brief(values)} are not allowed: give the 7 numbers of an MDP row's sensor slots "
                "(velocity, position, rates, attitude, correlation, delay, dropout)"
            )
        if not float(v[5]).is_integer():
            raise NeurohoverError(f"sensor delay={v[5]!r} in an MDP row is not a whole number of control steps")
        return cls(v[0], v[1], v[2], v[3], correlation=v[4], delay=int(v[5]), dropout=v[6])

    @classmethod
    def at_level(cls, level: float, correlation: float = 0.0, delay: int = 0) -> Sensor:
        """The sensor of noise level ``level``: :data:`LEVEL_PROFILE` scaled by it."""
        if not real_number(level):  # '1' and None were called out of range (T26-B17)
            raise NeurohoverError(f"sensor noise level={brief(level)} is not allowed: give a number in 0..{MAX_LEVEL:g}")
        if not finite_real(level) or not 0 <= level <= MAX_LEVEL:  # np.float32(0.5), Fraction(1, 2) in range too (thirteenth trial, F8)
            raise NeurohoverError(f"sensor noise level={brief(level)} is out of range: allowed a number in 0..{MAX_LEVEL:g}")
        if 0 < level < MIN_LEVEL:
            allowed = f"allowed 0 (exact) or a number in {lowest_allowed(MIN_LEVEL)}..{MAX_LEVEL:g}"
            raise NeurohoverError(f"sensor noise level={brief(level)} is out of range, too small to change a reading (an attitude std below 2**-52): {allowed}")
        v, p, r, a = (setting_float(level) * s for s in LEVEL_PROFILE)  # np.float32(0.1) as 0.1 (T56-B03)
        return cls(v, p, r, a, correlation=correlation, delay=delay)

    @classmethod
    def parse(cls, text: str, delay: int = 0) -> Sensor:
        """A sensor from the command line: a level (``"0.5"``) or ``key=value`` pairs (``"position=0.2,correlation=0.9"``).

        Keys are the settings of the module's table plus ``level`` (the profile scaled, before
        any group std given beside it); ``delay`` applies unless the text sets one.
        """
        text = str(text).strip()
        allowed = ("level", *(f.name for f in fields(cls)))
        if not text.isascii():  # float() reads other scripts' digits
            raise NeurohoverError(f"sensor {text!r} is not understood: give numbers in ASCII digits")
        try:
            return cls.at_level(float_of(text), delay=delay)
        except ValueError as exc:
            if isinstance(exc, NeurohoverError):
                raise
            if isinstance(exc, FloatRangeError):
                raise NeurohoverError(f"sensor level {exc}: allowed a noise level in 0..{MAX_LEVEL:g}") from None
        settings: dict[str, float] = {}
        expected = f"allowed a noise level (e.g. 0.5) or key=value pairs with keys {', '.join(allowed)}"
        parts = [p.strip() for p in text.split(",")]
        if "" in parts:  # '0.5,' was called 'not understood' for its level (T40-A01)
            raise NeurohoverError(f"sensor {text!r} has an empty setting between commas: {expected}")
        for part in parts:
            key, eq, value = part.partition("=")
            key = key.strip()
            if not eq and len(parts) > 1 and _is_number(part):  # '0.5,velocity=0.1' refused 0.5 while naming it allowed (T40-A01)
                raise NeurohoverError(
                    f"sensor {text!r:.80} gives the bare level {part!r:.40} beside another setting: a bare level is allowed "
                    f"only alone; among key=value pairs write level={part:.40} (one level), with keys {', '.join(allowed)}"
                )
            if not eq or key not in allowed:
                raise NeurohoverError(f"sensor setting {part!r} is not understood: {expected}")
            if key in settings:
                raise NeurohoverError(f"sensor setting {key!r} is given twice in {text!r}: give each key once")
            try:
                settings[key] = float_of(value)
            except ValueError as err:
                if isinstance(err, FloatRangeError) or not value.strip():
                    why = f": {err}" if isinstance(err, FloatRangeError) else ""
                    raise NeurohoverError(f"sensor setting {part[:40]!r} needs a number after '='{why}") from None
                commas = comma_separated(part)  # 'velocity=0.05 position=0.05': one value, said to need a number (T49-A03)
                said = f"{key}: its value {brief(value.strip())} is not a number: separate settings with commas ({commas:.80})" if commas else (
                    f"{part[:40]!r} needs a number after '=': its value {brief(value.strip())} is not one; give KEY=NUMBER pairs separated by commas"
                )  # fmt: skip
                raise NeurohoverError(f"sensor setting {said}, with keys {', '.join(allowed)}") from None
            if key == "delay" and math.isfinite(settings[key]):  # the text's own value: 9.0000000000000001 is 9.0 as a float (T53-A05)
                exact = decimal.Decimal(value.strip())
                if exact != exact.to_integral_value():
                    raise NeurohoverError(f"sensor delay={value.strip()[:40]!r} is not a whole number of control steps")
                settings[key] = int(exact)  # 99999999999999999999 named as itself, not as the float 1e20 (T53-A06)
        if not settings:
            raise NeurohoverError(f"sensor {text!r} is empty: {expected}")
        if not whole_number(delay):  # 2.0 as Sensor(delay=) refuses it (whole_in; it was taken beside key=value text, T37-B12)
            raise NeurohoverError(f"sensor delay={brief(delay)} is not allowed: give a whole number of control steps in 0..{MAX_SENSOR_DELAY}")
        values: dict[str, float | int] = {"delay": delay} | settings
        if not real_number(values["delay"]):  # "x" was a ValueError (fifth trial), np.timedelta64(2) delay 2
            raise NeurohoverError(f"sensor delay={values['delay']!r:.40} is not allowed: give a whole number of control steps")
        if not float(values["delay"]).is_integer():
            raise NeurohoverError(f"sensor delay={values['delay']!r} is not a whole number of control steps")
        values["delay"] = int(values["delay"])
        return cls.from_dict(values)  # the level, then the stds given beside it

    @classmethod
    def of(cls, obs_noise=None, obs_delay=None) -> Sensor:
        """The sensor of the ``obs_noise`` / ``obs_delay`` options (of the CLI, the configs and the environments).

        ``obs_noise``: None (no noise), a level (a number), a :class:`Sensor`, a dict of its
        settings, or the command line's text (:meth:`parse`); ``obs_delay``: None or the control
        steps the readings arrive late (given once: a Sensor or dict that sets another refuses it).
        """
        if obs_delay is None:
            delay = None
        elif not whole_number(obs_delay):  # np.int64(2) as Sensor(delay=) takes it (F8); 2.0 as it refuses it (whole_in, T37-B12)
            raise NeurohoverError(f"obs_delay={brief(obs_delay)} is not allowed: give a whole number of control steps in 0..{MAX_SENSOR_DELAY}")
        else:
            delay = operator.index(obs_delay)
        if obs_noise is None:
            return cls(delay=delay or 0)
        if isinstance(obs_noise, Sensor):
            sensor = obs_noise
        elif isinstance(obs_noise, dict):
            sensor = cls.from_dict(obs_noise)
        elif isinstance(obs_noise, str):
            sensor = cls.parse(obs_noise)
        else:
            sensor = cls.at_level(obs_noise)
        if delay is None:
            return sensor
        named = isinstance(obs_noise, dict) and "delay" in obs_noise
        named = named or (isinstance(obs_noise, str) and re.search(r"(^|,)\s*delay\s*=", obs_noise) is not None)
        if sensor.delay != delay and (sensor.delay != 0 or named):  # an explicit delay=0 lost to obs_delay=2 without a word (sixth trial)
            raise NeurohoverError(  # the options as the command line spells them too (eleventh trial, U8)
                f"obs_delay={delay} conflicts with the delay={sensor.delay} that obs_noise sets: give the delay once "
                "(on the command line: --obs-delay, or delay= in --obs-noise)"
            )
        return replace(sensor, delay=delay)

    def to_dict(self) -> dict:
        """The settings as a dict (``dropout`` only when set: a sensor's dict reads as it did before it existed)."""
        d = asdict(self)
        if not self.dropout:
            del d["dropout"]
        return d

    @classmethod
    def from_dict(cls, d: dict) -> Sensor:
        """A sensor from a dict of the settings (unknown keys refused by name)."""
        if not isinstance(d, dict):
            raise NeurohoverError(f"a sensor must be a table of settings, got {d!r}")
        allowed = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - allowed - {"level"})
        if unknown:
            raise NeurohoverError(f"unknown sensor setting(s) {', '.join(map(repr, unknown))}: allowed level, {', '.join(sorted(allowed))}")
        d = dict(d)
        base = cls.at_level(d.pop("level", 0.0))
        return cls(**(asdict(base) | d))


EXACT = Sensor()
