"""A complete (or candidate) verb frame: a predicate and its roles in order, e.g. (pour, Theme: water,
Destination: cup). Frozen and hashable, so frames are set members and dict keys as they are; scorers,
completion, rating tasks and evaluation all pass this one type. (A frame found in text, with spans, is
`lmcr.srl.frames.FrameMention`.)"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterator, Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class Frame:
    predicate: str
    roles: tuple[tuple[str, str], ...]  # (role, value) in the order the frame states them

    @classmethod
    def of(cls, predicate: str, roles: Mapping[str, str]) -> Frame:
        """From a predicate and a role -> value mapping (its order kept)."""
        return cls(predicate, tuple(roles.items()))

    @property
    def role_map(self) -> dict[str, str]:
        return dict(self.roles)

    @property
    def key(self) -> tuple[str, ...]:
        """(predicate, role1, value1, role2, value2, ...): the rating tables' columns."""
        return (self.predicate, *(part for pair in self.roles for part in pair))

    @property
    def id(self) -> str:
        """A stable identifier independent of role order: 'f-' + 12 hex digits."""
        text = json.dumps([self.predicate, sorted(self.roles)])
        return "f-" + hashlib.sha256(text.encode()).hexdigest()[:12]

    def to_json(self) -> dict:
        return {"predicate": self.predicate, "roles": self.role_map}

    def __iter__(self) -> Iterator:
        """`verb, roles = frame`: the predicate and a role -> value dict."""
        yield self.predicate
        yield self.role_map
