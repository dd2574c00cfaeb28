"""Role preferences learned from the frame corpus, for the lone object of an alternating verb.

"rub the steak" and "rub the salt in" have the same syntax; what differs is that the corpus shows
steak as what gets rubbed (Destination) and salt as what is rubbed on (Theme). Counting, over frames
whose roles were fixed by syntax (a with-phrase or a destination phrase), how often each noun fills
each role of each verb — pooled over the alternating verbs as a back-off — resolves the lone object.
No preference is written by hand: an unseen noun keeps the syntactic default (the object role).
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path

from lmcr.files import atomic_path, read_resource
from lmcr.srl.mentions import FrameMention

SMOOTHING = 1.0


@dataclass
class RolePriors:
    """Counts of (verb, value, role) and (value, role) from unambiguous frames of alternating verbs."""

    by_verb: Counter = field(default_factory=Counter)
    pooled: Counter = field(default_factory=Counter)

    def observe(self, frames: Iterable[FrameMention], alternating: set[str]) -> None:
        """Count role fillers of unambiguous, fully specified alternating-verb frames."""
        for frame in frames:
            if frame.predicate not in alternating or frame.ambiguous_object or None in frame.roles.values():
                continue
            for role, value in frame.roles.items():
                self.by_verb[(frame.predicate, value, role)] += 1
                self.pooled[(value, role)] += 1

    def probability(self, verb: str, value: str, role: str, other: str) -> float | None:
        """Smoothed P(role | verb, value) backing off to P(role | value); None when never seen."""
        for counts, key in ((self.by_verb, (verb,)), (self.pooled, ())):
            hit, miss = counts[(*key, value, role)], counts[(*key, value, other)]
            if hit + miss:
                return (hit + SMOOTHING) / (hit + miss + 2 * SMOOTHING)
        return None

    def resolve(self, frame: FrameMention) -> FrameMention:
        """Swap a default-assigned lone object into the other role when the corpus prefers that role; read a
        learned verb's phrase as a phrasal verb's object when the corpus prefers its noun as a Theme ("stir
        in the sugar": the sugar is what is stirred in, not where)."""
        if frame.particle_reading is not None:
            return self._particle(frame)
        role = frame.ambiguous_object
        if role is None:
            return frame
        other = next(r for r in frame.roles if r != role)
        value = frame.roles[role]
        p = self.probability(frame.predicate, value, role, other)
        if p is None or p >= 0.5:
            return frame
        roles = {role: None, other: value} if list(frame.roles)[0] == role else {other: value, role: None}
        roles = {r: roles[r] for r in frame.roles}
        spans = {other: frame.spans[role]} if role in frame.spans else {}
        return replace(frame, roles=roles, spans=spans, ambiguous_object=other)

    def _particle(self, frame: FrameMention) -> FrameMention:
        """The phrasal reading of `frame` when its object is likelier a Theme than what the phrase made it
        in the other reading (the phrasal verb is no alternating verb of the eleven: the pooled counts
        decide); else the frame."""
        reading = frame.particle_reading
        theme = reading.roles.get("Theme")
        phrase_role = next((r for r, v in frame.roles.items() if v == theme and r != "Theme"), None)
        if theme is None or phrase_role is None:
            return replace(frame, particle_reading=None)
        p = self.probability(reading.predicate, theme, "Theme", phrase_role)
        return replace(reading if p is not None and p > 0.5 else frame, particle_reading=None)

    def save(self, path: Path) -> None:
        """Write as JSON under a temporary name, then rename."""
        with atomic_path(path) as tmp:
            tmp.write_text(
                json.dumps(
                    {
                        "by_verb": [[*k, n] for k, n in sorted(self.by_verb.items())],
                        "pooled": [[*k, n] for k, n in sorted(self.pooled.items())],
                    }
                ),
                encoding="utf-8",
            )

    @classmethod
    def load(cls, path: Path) -> RolePriors:
        """The counts `save` wrote; a damaged file is a ResourceError naming it."""
        return read_resource(
            path, "role priors", lambda data: cls(_counts(data["by_verb"], 3), _counts(data["pooled"], 2))
        )


def _counts(rows: list, keys: int) -> Counter:
    """Rows [key words..., count] as a Counter; a row of another shape is a ValueError."""

    def key(row: object) -> tuple[str, ...]:
        if not (
            isinstance(row, list)
            and len(row) == keys + 1
            and all(isinstance(k, str) for k in row[:-1])
            and type(row[-1]) is int
        ):
            # read_resource turns this into a ResourceError naming the file
            raise ValueError(f"{str(row)[:60]} is not [{', '.join(['word'] * keys)}, count]")
        return tuple(row[:-1])

    return Counter({key(r): r[-1] for r in rows})
