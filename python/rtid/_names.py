"""The names the module's arguments take, and the closest one to a misspelt name.

The condition keys, each kind's columns and the options' values are the library's own
(``Conditions::KEYS`` and ``Kind::columns`` in src/io/experiment_file/, the loop modes,
the search's methods, the objectives, the sweep's outputs, the tuning's objectives),
read from the extension once: a misspelling is caught before any work, with the
closest name.
"""

from __future__ import annotations

import difflib
import math
import numbers

from . import _rtid
from ._rtid import RtidError

#: A manifest's ``conditions`` keys (docs/experiment-files.md).
CONDITIONS = tuple(_rtid.condition_keys())

#: The columns each kind's reader and evaluators read (docs/experiment-files.md's
#: table), every position under each of its unit suffixes.
COLUMNS = {kind: list(columns) for kind, columns in _rtid.kind_columns()}

#: The options' values as the library spells them: ``loop``, ``method`` (the search's),
#: ``objectives`` (the identification's), ``outputs`` (the sweep's), ``objective``
#: (the tuning's), ``response``.
OPTIONS = {name: tuple(values) for name, values in _rtid.option_names()}

#: How close (difflib's ratio, case ignored) an unknown column must be to a known one
#: to be taken for a misspelling of it rather than an extra column.
COLUMN_CUTOFF = 0.8


def closest(name: str, known, cutoff: float = 0.6) -> str | None:
    """The known name closest to `name` (case ignored), if any is close."""
    by_lower = {}
    for k in known:
        by_lower.setdefault(k.lower(), k)
    found = difflib.get_close_matches(name.lower(), list(by_lower), n=1, cutoff=cutoff)
    return by_lower[found[0]] if found else None


def unknown(argument: str, what: str, name: str, known) -> RtidError:
    """A ValueError: `name` is no `what` of `known`, with the closest known name."""
    hint = closest(name, known)
    tail = f"did you mean `{hint}`?" if hint else f"expected one of {', '.join(known)}"
    return RtidError(f"{argument}: unknown {what} `{name}`; {tail}")


def check_conditions(conditions) -> None:
    """Refuses a condition key rtid does not know (a misspelling), naming the closest."""
    for key in conditions:
        if not isinstance(key, str):
            raise TypeError(f"conditions: key {key!r} is not a string")
        if key not in CONDITIONS:
            raise unknown("conditions", "condition", key, CONDITIONS)


def check_columns(kind: str, columns) -> None:
    """Refuses a column that is not one `kind` reads but nearly is (a misspelling),
    naming the one it nearly is; other columns are the file's extra columns."""
    known = COLUMNS.get(kind)
    if not known:
        return
    for name in columns:
        if name in known:
            continue
        hint = closest(name, known, COLUMN_CUTOFF)
        if hint is not None:
            raise RtidError(f"{name}: not a column of a {kind} experiment; did you mean `{hint}`?"
                            " (a column a kind does not read is kept as an extra column: give"
                            " it a name of its own)")


def finite_number(value, argument: str) -> float:
    """`value` as a float: a TypeError naming `argument` if it is not a number, an
    RtidError (a ValueError) if it is not finite."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{argument}: {value!r} is not a number, but {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v):
        raise RtidError(f"{argument}: {v} is not a finite number")
    return v
