"""Object instances: a table may hold several objects with one label (three cups), and each object has
an id of its own that plans, checks and outputs name.

An id is given in the scene file (`"id": "red cup"`) or assigned in scene order: the first object of a
label is the label itself ("cup"), the next ones the label with their number among that label's
objects ("cup#2", "cup#3"), skipping an id that some object was given. A scene whose objects all have
different labels thus has ids equal to its labels, as before ids existed.
"""

from __future__ import annotations

SEPARATOR = "#"
MAX_ID_CHARS = 60


class DuplicateIdError(ValueError):
    """Two objects were given the same id; `first` and `second` are their positions."""

    def __init__(self, ident: str, first: int, second: int):
        super().__init__(f"object {second}: id {ident!r} is already object {first}'s")
        self.ident, self.first, self.second = ident, first, second


def assign_ids(labels: list[str], given: list[str | None] | None = None) -> list[str]:
    """The id of every object, in order: `given[k]` where it is set, else the next free one of its label
    (see the module docstring). Raises DuplicateIdError when two given ids are the same."""
    given = list(given) if given is not None else [None] * len(labels)
    owner: dict[str, int] = {}
    for k, ident in enumerate(given):
        if ident is not None:
            if ident in owner:
                raise DuplicateIdError(ident, owner[ident], k)
            owner[ident] = k
    counts: dict[str, int] = {}
    ids = []
    for label, ident in zip(labels, given):
        if ident is None:
            n = counts.get(label, 0)
            while True:
                n += 1
                ident = label if n == 1 else f"{label}{SEPARATOR}{n}"
                if ident not in owner:
                    break
            counts[label] = n
            owner[ident] = len(ids)
        ids.append(ident)
    return ids


def id_problem(ident: object) -> str | None:
    """Why a given id cannot be used (None when it can): a non-empty string of printable characters
    without spaces at either end, at most MAX_ID_CHARS long."""
    if not isinstance(ident, str) or not ident or ident != ident.strip() or not ident.isprintable():
        return f"id must be a non-empty string without surrounding spaces, not {ident!r:.60}"
    if len(ident) > MAX_ID_CHARS:
        return f"id is longer than {MAX_ID_CHARS} characters"
    return None


def ids_by_label(labels: list[str], ids: list[str]) -> dict[str, list[str]]:
    """label -> the ids of its objects, in order."""
    out: dict[str, list[str]] = {}
    for label, ident in zip(labels, ids):
        out.setdefault(label, []).append(ident)
    return out
