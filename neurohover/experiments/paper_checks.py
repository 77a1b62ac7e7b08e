"""The checks of a config's ``[paper]`` table (what the report compares against) and of its one-line texts
(:mod:`.config`: :func:`~.config.make_config` and :func:`~.config.load_config` call them)."""

from __future__ import annotations

import unicodedata

from ..errors import NeurohoverError, brief, finite_real, unknown_keys

#: The most characters of each one-line text of a config (the report writes each into one line or heading of Markdown;
#: a 20,000-character title was taken, T28-A07): the shipped configs' longest are a third of these.
TEXT_LIMITS = {"title": 200, "paper_ref": 200, "label": 100, "p": 200, "notes": 1000, "claims": 1000}


def control_character(text: str) -> str | None:
    """The first control character of ``text`` (a newline, a tab, NUL, a line or paragraph separator) as its escape,
    or None: a newline in a title or a --set VALUE was taken, and put headings into the report or dropped what followed
    (T28-A06, A07)."""
    for ch in text:
        if unicodedata.category(ch) in ("Cc", "Zl", "Zp"):
            return repr(ch)[1:-1]
    return None


def check_line(key: str, text, where: str, limit_key: str | None = None) -> None:
    """Refuse a one-line text of a config (``key``: how the message names it) that is no text, holds a control character,
    or is longer than :data:`TEXT_LIMITS` ``[limit_key or key]``."""
    if not isinstance(text, str):  # title = 5 was stored, then refused as a damaged store's (sixth trial)
        raise NeurohoverError(f"{where}: {key} = {brief(text)} is not allowed: give text")
    bad = control_character(text)
    if bad is not None:
        raise NeurohoverError(f"{where}: {key} = {brief(text)} is not allowed: it holds the control character {bad}; give one line of text")
    limit = TEXT_LIMITS[limit_key or key]
    if len(text) > limit:
        raise NeurohoverError(f"{where}: {key} = {brief(text)} is not allowed: give at most {limit} characters")


def check_texts(title, paper_ref, settings: dict, where: str) -> None:
    """The one-line texts of a config that the report shows: its title and paper_ref, and its variants', fits' and
    conditions' labels (the groups' labels are unit-key words, :mod:`.schema`)."""
    check_line("title", title, where)
    check_line("paper_ref", paper_ref, where)
    for kind in ("variants", "fits", "conditions"):
        for item in settings.get(kind, []):
            if isinstance(item, dict) and item.get("label") is not None:
                check_line(f"{kind[:-1]} label", item["label"], where, "label")


#: What a config's [paper] table may hold (what the report reads from it).
PAPER_KEYS = ("notes", "claims", "ttests", "groups", "table", "table3")
#: The [paper] keys each kind's report section reads (:mod:`.report`: ``table`` Table 4's model-learning section,
#: ``groups`` the test runs', ``table3`` the evolution section's robustness table; every section the rest).
KIND_PAPER_KEYS = {
    "evolution": ("notes", "claims", "ttests", "table3"),
    "model_learning": ("notes", "claims", "ttests", "table"),
    "test_runs": ("notes", "claims", "ttests", "groups"),
}
_SHOWN_BY = {"table3": "evolution", "table": "model_learning", "groups": "test_runs"}


def _paper_p(p) -> bool:
    """Whether ``p`` reads as a paper's p-value: a number in 0..1 (after '<' or '<='; words may follow it), 'not
    significant', or 'none' (a test the paper did not make, with why)."""
    if not isinstance(p, str):
        return False
    if p.strip().lower().startswith(("not significant", "none")):
        return True
    try:
        return 0 <= float(p.strip().lower().lstrip("<= ").split()[0]) <= 1
    except (ValueError, IndexError):
        return False


#: The numbers each entry of a [paper] table may give (what the report reads), the required ones first.
_PAPER_NUMBERS = {
    "table": (("r_m", "r_a"), ("t", "sd")),  # Table 4's: method -> t, r_m, r_a, sd
    "groups": ((), ("crash_rate", "return_per_episode_no_crash")),  # test runs': group -> ...
    "table3": ((), ("r", "sd", "r_G", "sd_G", "crashes_G")),  # Table 3's: variant -> ...
}


def _json_value(value, path: str, where: str) -> None:
    """Refuse a value under [paper] that the store's JSON cannot hold (inf, nan, 10**400, an object), by its key path:
    it was a json error once the store file was made (twelfth trial, T3)."""
    if isinstance(value, dict):
        for k, v in value.items():
            if not isinstance(k, str):
                raise NeurohoverError(f"{where}: [paper] {path} has key {brief(k)}: give text keys")
            _json_value(v, f"{path}.{k}", where)
    elif isinstance(value, list | tuple):
        for i, v in enumerate(value):
            _json_value(v, f"{path}[{i}]", where)
    elif isinstance(value, float | int) and not isinstance(value, bool) and not finite_real(value):
        raise NeurohoverError(f"{where}: [paper] {path} = {brief(value)} is not allowed: give a finite number")
    elif not isinstance(value, str | bool | int | float):
        raise NeurohoverError(f"{where}: [paper] {path} = {brief(value)} is not allowed: give text, a Python int or float, a list or a table (what JSON holds)")


def check_paper_table(paper, where: str, kind: str | None = None) -> None:
    """Refuse a [paper] table the report cannot read: unknown keys, values the store's JSON cannot hold, and entries of the
    wrong shape (a text where the report formats a number was a traceback in `report`, after reproduce had run; twelfth
    trial, T1-T3). Shared by config files and :func:`make_config`, which gives the experiment's ``kind``: a key its
    report section never shows (:data:`KIND_PAPER_KEYS`) is refused too (T28-A09)."""
    if not isinstance(paper, dict):
        raise NeurohoverError(f"{where}: [paper] = {brief(paper)} is not allowed: give a table (a dict) of {', '.join(PAPER_KEYS)}")
    named = unknown_keys(paper, PAPER_KEYS)  # each as its repr: the key '' was named as nothing
    if named:
        raise NeurohoverError(f"{where}: unknown [paper] key(s) {named}; allowed: {', '.join(PAPER_KEYS)}")
    for key in ("notes", "claims"):  # lists of sentences (a string here was reported letter by letter)
        value = paper.get(key, [])
        if not isinstance(value, list) or not all(isinstance(x, str) for x in value):
            raise NeurohoverError(f"{where}: [paper] {key} = {brief(value)} is not allowed: give a list of strings")
        for x in value:  # each is one bullet of the report (T28-A07)
            check_line(f"[paper] {key} entry", x, where, key)
    ttests = paper.get("ttests", [])
    if not isinstance(ttests, list):  # 5 was a TypeError, 'x' read letter by letter (twelfth trial, T2)
        raise NeurohoverError(f"{where}: [paper] ttests = {brief(ttests)} is not allowed: give a list of tables with a, b and p")
    for t in ttests:
        if not isinstance(t, dict) or not {"a", "b", "p"} <= set(t):
            raise NeurohoverError(f"{where}: each [paper] ttests entry needs a, b and p, got {brief(t)}")
        named = unknown_keys(t, {"a", "b", "p"})  # a misspelt extra key was dropped without a word (T27-A05)
        if named:
            raise NeurohoverError(f"{where}: unknown [paper] ttests key(s) {named} in {brief(t)}; allowed: a, b, p")
        if not _paper_p(t["p"]):
            raise NeurohoverError(
                f"{where}: [paper] ttests p = {brief(t['p'])} is not allowed: give the paper's p-value as text, "
                "e.g. '5.8e-12', '< 0.0026', 'not significant' or 'none (why)'"
            )
        check_line("[paper] ttests p", t["p"], where, "p")
        for side in ("a", "b"):  # a list was a TypeError where the names are looked up
            if not isinstance(t[side], str):
                raise NeurohoverError(f"{where}: [paper] ttests {side} = {brief(t[side])} is not allowed: give a group, variant, method or fit by name")
    for key, (required, optional) in _PAPER_NUMBERS.items():
        _check_paper_numbers(paper.get(key, {}), key, required, optional, where)
    for key, value in paper.items():  # what the shapes leave open (a t test's other keys)
        _json_value(value, key, where)
    shown = KIND_PAPER_KEYS.get(kind or "", PAPER_KEYS)
    unshown = [k for k in PAPER_KEYS if k in paper and k not in shown]
    if unshown:
        raise NeurohoverError(
            f"{where}: [paper] {unshown[0]} is not allowed in a {kind} experiment: its report never shows it "
            f"({unshown[0]} belongs to the {_SHOWN_BY[unshown[0]]} report); allowed: {', '.join(shown)}"
        )


def _check_paper_numbers(table, key: str, required: tuple[str, ...], optional: tuple[str, ...], where: str) -> None:
    """A [paper] ``table`` / ``groups`` / ``table3``: names, each a table of the numbers ``required`` and ``optional``."""
    allowed = ", ".join((*required, *optional)) + (f" ({' and '.join(required)} required)" if required else "")
    shape = f"give a table of names, each a table of numbers {allowed}"
    if not isinstance(table, dict):
        raise NeurohoverError(f"{where}: [paper] {key} = {brief(table)} is not allowed: {shape}")
    for name, entry in table.items():
        if not isinstance(entry, dict):
            raise NeurohoverError(f"{where}: [paper] {key}.{name} = {brief(entry)} is not allowed: {shape}")
        unknown = unknown_keys(entry, {*required, *optional})
        missing = [k for k in required if k not in entry]
        if unknown or missing:
            what = f"unknown number(s) {unknown}" if unknown else f"no {' or '.join(missing)}"
            raise NeurohoverError(f"{where}: [paper] {key}.{name} has {what}: allowed {allowed}")
        for k, v in entry.items():
            if not finite_real(v) or (k == "crash_rate" and not 0 <= v <= 1) or (k == "crashes_G" and not (isinstance(v, int) and v >= 0)):
                want = "a rate in 0..1" if k == "crash_rate" else "an integer >= 0" if k == "crashes_G" else "a finite number"
                raise NeurohoverError(f"{where}: [paper] {key}.{name}.{k} = {brief(v)} is not allowed: give {want}")


def check_paper(paper, raw: dict, where: str) -> None:
    """Refuse a paper t test or number table entry that names no group, variant, method or fit at any scale (its shape was checked by
    :func:`make_config`, :func:`check_paper_table`)."""
    tables = [raw.get("settings", {}), *raw.get("scales", {}).values()]
    entries = [e for tab in tables for kind in ("groups", "variants", "fits") for e in tab.get(kind, []) if isinstance(e, dict)]
    names = {e.get(k) for e in entries for k in ("key", "label", "agent")} | {m for tab in tables for m in tab.get("methods", [])}
    pairs: set[frozenset] = set()
    for t in paper.get("ttests", []):
        for side in ("a", "b"):
            if t[side] not in names:
                raise NeurohoverError(f"{where}: [paper] ttests names {t[side]!r} ({side}), which is no group, variant, method or fit of the config")
        if t["a"] == t["b"]:  # a group against itself: p = 1, and a verdict of "reversed" for equal means (T26-A05)
            raise NeurohoverError(f"{where}: [paper] ttests compares {brief(t['a'])} with itself (a = b): give two different groups, variants, methods or fits")
        if frozenset((t["a"], t["b"])) in pairs:  # both orders: the paper found each better than the other (T27-A04)
            raise NeurohoverError(
                f"{where}: [paper] ttests compares {brief(t['a'])} with {brief(t['b'])} twice (in either order): "
                "give each pair once, with a the one the paper found better"
            )
        pairs.add(frozenset((t["a"], t["b"])))
    for key in _PAPER_NUMBERS:  # an entry of no name the report looks up was never shown, without a word
        allowed = names | ({"mlp-baseline"} if key == "table3" else set())  # table3's row for a policy set's specialised MLPs
        for name in paper.get(key, {}):
            if name not in allowed:
                raise NeurohoverError(f"{where}: [paper] {key} names {brief(name)}, which is no group, variant, method or fit of the config")
