"""neurohover.settingsdoc and `neurohover settings`: each setting described once, in its class's docstring.

Every settings class a run or an agent takes has one docstring entry per field and no entry without a
field, so the table `neurohover settings NAME` prints (and the API docs) cannot drift from the code.
"""

from __future__ import annotations

import dataclasses

import pytest

from neurohover.cli.settings import settings_classes
from neurohover.settingsdoc import documented, format_settings, plain, settings_rows


@dataclasses.dataclass(frozen=True)
class _Example:
    """An example.

    Attributes
    ----------
    a, b : int
        Two counts,
        over two lines.
    c : {"x", "y"}
        A choice.

    Prose after the entries is no entry.
    """

    a: int = 1
    b: int = 2
    c: str = "x"


@dataclasses.dataclass(frozen=True)
class _Child(_Example):
    """A child.

    Parameters
    ----------
    d : float or None
        Its own.
    """

    d: float | None = None


def test_entries_are_read_from_the_numpy_docstring_and_its_bases() -> None:
    assert documented(_Example) == {"a": ("int", "Two counts, over two lines."), "b": ("int", "Two counts, over two lines."), "c": ('{"x", "y"}', "A choice.")}
    rows = settings_rows(_Child)
    assert [(r.name, r.default, r.help) for r in rows] == [
        ("a", "1", "Two counts, over two lines."),
        ("b", "2", "Two counts, over two lines."),
        ("c", "'x'", "A choice."),
        ("d", "None", "Its own."),
    ]
    assert plain("``x`` and :class:`~a.b.Thing`") == "x and Thing"


@pytest.mark.parametrize("name", sorted(settings_classes()))
def test_every_setting_of_every_settings_class_is_documented_once(name: str) -> None:
    cls = settings_classes()[name]
    fields = {f.name for f in dataclasses.fields(cls) if f.init}
    docs = documented(cls)
    assert sorted(fields - set(docs)) == [], f"{cls.__name__}: fields without a docstring entry"
    assert sorted(set(docs) - fields) == [], f"{cls.__name__}: docstring entries naming no field"
    assert all(row.help for row in settings_rows(cls))


def test_the_settings_command_prints_the_defaults_the_classes_hold(cli) -> None:
    from neurohover.evolution.generational import GenerationalSettings

    rc, out, _ = cli("settings", "generational")
    defaults = GenerationalSettings()
    for f in dataclasses.fields(GenerationalSettings):
        assert f"{f.name} = {getattr(defaults, f.name)!r}" in out
    assert rc == 0 and out.strip() == format_settings(GenerationalSettings, "generational").strip()
    rc, listed, _ = cli("settings")
    assert rc == 0 and [line.split()[0] for line in listed.splitlines()] == list(settings_classes())
    rc, _, err = cli("settings", "bogus")
    assert rc == 2 and "no settings named 'bogus': allowed steady-state, generational" in err and "Traceback" not in err


def test_an_agents_name_shows_its_settings_class_and_one_without_settings_is_told_so(cli) -> None:
    from neurohover.agents.hybrid import HybridSettings

    rc, out, _ = cli("settings", "hybrid-baseline")
    assert rc == 0 and out.strip() == format_settings(HybridSettings, "hybrid").strip()
    rc, _, err = cli("settings", "model-free")
    assert rc == 2 and "agent 'model-free' takes no settings of its own" in err
