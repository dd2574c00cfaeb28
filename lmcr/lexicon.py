"""The verb-frame lexicon: the 11 robot predicates, their two roles, and how English realises each role."""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

LEXICON_PATH = Path(__file__).with_name("lexicon.json")
# What the lexicon is made of: a change to either changes every frame the parser finds.
LEXICON_FILES = (Path(__file__), LEXICON_PATH)
# What can name a thing on the table: one to four words of letters ("salsa", "crème fraîche", "half-and-half"),
# at most 40 characters, not only function words; emoji, digits, "into the" or a pasted paragraph name
# nothing a robot could pick up (and an LM that drops articles would score "the" as an empty filler).
_OBJECT_NAME_RE = re.compile(r"[^\W\d_]+(?:[ '-][^\W\d_]+){0,3}")
MAX_OBJECT_NAME_CHARS = 40


def is_object_name(label: str) -> bool:
    """True when `label` (lowercase, single spaces) could name an object: words of letters, not too long,
    not only function words."""
    from spacy.lang.en.stop_words import STOP_WORDS  # here, not at import: the CLI starts without spaCy

    return (
        len(label) <= MAX_OBJECT_NAME_CHARS
        and _OBJECT_NAME_RE.fullmatch(label) is not None
        and not STOP_WORDS.issuperset(label.split())
    )


@dataclass(frozen=True)
class PredicateSpec:
    """How one predicate's roles surface: object role, with-role, role prepositions, particles."""

    name: str
    roles: tuple[str, str]
    object_role: str
    with_role: str | None
    preps: dict[str, tuple[str, ...]]  # per role, the most usual preposition first
    particles: frozenset[str]
    alternating: bool
    sentence: str  # "pour {Theme} into the {Destination}": the sentence-LM linearisation
    past: str | None = None  # the verb's simple past where it is irregular ("put"); else English's regular rule

    def prep_role(self, prep: str) -> str | None:
        """The role a prepositional phrase headed by `prep` fills, if any."""
        if prep == "with" and self.with_role:
            return self.with_role
        return next((role for role, preps in self.preps.items() if prep in preps), None)

    def prep_rank(self, prep: str) -> int:
        """How usual `prep` is for the role it fills (0 = the most usual; "with" of the with-role is 0):
        which of two phrases for one role names it ("fry on both sides in hot oil": in)."""
        if prep == "with" and self.with_role:
            return 0
        return next((preps.index(prep) for preps in self.preps.values() if prep in preps), 99)

    def other(self, role: str) -> str:
        return self.roles[1] if role == self.roles[0] else self.roles[0]


@dataclass(frozen=True)
class Lexicon:
    predicates: dict[str, PredicateSpec]
    measure_nouns: frozenset[str]
    quantity_nouns: frozenset[str]
    object_pronouns: frozenset[str]
    recipient_pronouns: frozenset[str]
    courtesy_words: frozenset[str] = frozenset()  # "please": closes a request, never part of a name
    objects: tuple[str, ...] = ()  # the robot detector's object labels (the simulated kitchen's vocabulary)


@lru_cache(maxsize=4)
def load_lexicon(path: str | None = None) -> Lexicon:
    """Load the lexicon (`LMCR_LEXICON` or the packaged `lexicon.json`)."""
    data = json.loads(Path(path or os.environ.get("LMCR_LEXICON") or LEXICON_PATH).read_text("utf-8"))
    predicates = {
        name: PredicateSpec(
            name=name,
            roles=tuple(spec["roles"]),
            object_role=spec["object"],
            with_role=spec.get("with"),
            preps={role: tuple(p) for role, p in spec.get("preps", {}).items()},
            particles=frozenset(spec.get("particles", [])),
            alternating=bool(spec.get("alternating")),
            sentence=spec["sentence"],
            past=spec.get("past"),
        )
        for name, spec in data["predicates"].items()
    }
    return Lexicon(
        predicates=predicates,
        measure_nouns=frozenset(data["measure_nouns"]),
        quantity_nouns=frozenset(data["quantity_nouns"]),
        object_pronouns=frozenset(data["object_pronouns"]),
        recipient_pronouns=frozenset(data["recipient_pronouns"]),
        objects=tuple(data.get("objects", ())),
        courtesy_words=frozenset(data.get("courtesy_words", ())),
    )
