"""The verb-frame lexicon: the 11 robot predicates, their two roles, and how English realises each role."""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path

from lmcr.data_dir import PREDICATES_FILE, SRL_SUBDIR, data_dir_from_env

LEXICON_PATH = Path(__file__).with_name("lexicon.json")
# What the lexicon is made of: a change to either changes every frame the parser finds.
LEXICON_FILES = (Path(__file__), LEXICON_PATH)
# What can name a thing on the table: one to four words of letters ("salsa", "crème fraîche", "half-and-half"),
# at most 40 characters, not only function words; emoji, digits, "into the" or a pasted paragraph name
# nothing a robot could pick up (and an LM that drops articles would score "the" as an empty filler).
_OBJECT_NAME_RE = re.compile(r"[^\W\d_]+(?:[ '-][^\W\d_]+){0,3}")
MAX_OBJECT_NAME_CHARS = 40


# Roles a preposition can introduce, most usual first (English grammar, the same for every verb).
PREP_ROLES: dict[str, tuple[str, ...]] = {
    "into": ("Destination",),
    "onto": ("Destination",),
    "to": ("Destination",),
    "inside": ("Destination", "Instrument"),
    "in": ("Destination", "Instrument"),
    "on": ("Destination", "Instrument"),
    "over": ("Destination",),
    "under": ("Destination",),
    "at": ("Destination", "Instrument"),
    "with": ("Instrument",),
    "using": ("Instrument",),
    "from": ("Source",),
    "off": ("Source",),
    "of": ("Theme",),
}


def normalize_name(name: str) -> str:
    """A predicate or object name as the lexicon keys it: lowercase, one space between words ("Put  Away"
    -> "put away")."""
    return " ".join(name.lower().split())


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
    # a learned predicate's other open roles: role -> its sentence ("cut {Theme} with the {Instrument}" beside
    # "cut {Theme} into the {Destination}"); a request states one of them, or completion lets the objects choose
    alternatives: dict[str, str] = field(default_factory=dict)
    # how often each open role is stated with it (a learned predicate's valence; empty for the eleven)
    rates: dict[str, float] = field(default_factory=dict)
    # a learned predicate's class of motion, learned from its fillers ("place", "stir", ...; frame_corpus.predicates)
    motion: str | None = None

    def open_role_prior(self, role: str) -> float:
        """log of how much likelier a request leaves `role` open than the second role, by how often each is
        stated (0 for the second role itself, and for a predicate without learned rates)."""
        if not self.rates or role == self.roles[1]:
            return 0.0
        return math.log(max(self.rates.get(role, 0.0), 1e-6) / max(self.rates.get(self.roles[1], 0.0), 1e-6))

    @property
    def open_roles(self) -> tuple[str, ...]:
        """The roles besides the object role a frame of it can have: its second role, then the alternatives."""
        return (self.other(self.object_role), *self.alternatives)

    def roles_for(self, stated: Iterable[str]) -> tuple[str, str]:
        """The two roles of a frame whose prepositional phrases use `stated` prepositions: the spec's, unless
        only an alternative role is stated ("cut the bread with a knife": Theme, Instrument)."""
        found = [self.prep_role(p) for p in stated]
        if self.roles[1] in found or not self.alternatives:
            return self.roles
        alternative = next((r for r in found if r in self.alternatives), None)
        return (self.roles[0], alternative) if alternative else self.roles

    def template(self, roles: Iterable[str]) -> str:
        """The sentence for a frame with these roles (an alternative role's own, else the spec's)."""
        other = next((r for r in roles if r in self.alternatives), None)
        return self.alternatives[other] if other else self.sentence

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
    speaker_labels: frozenset[str] = frozenset()  # "person": the label a scene gives a person
    speaker_places: frozenset[str] = frozenset()  # "here": where the person who asks is
    # "can I have an apple", "we need a spoon": a verb the person who asks (one of `speaker_subjects`, as its
    # subject) asks for a thing with, read as the robot doing `request_predicate` to bring it to them
    request_verbs: frozenset[str] = frozenset()
    speaker_subjects: frozenset[str] = frozenset()
    request_predicate: str | None = None
    objects: tuple[str, ...] = ()  # the robot detector's object labels (the simulated kitchen's vocabulary)
    # the predicates learned from the frame corpus (a subset of `predicates`), and the verbs the corpus uses
    # too seldom to learn (verb -> frames): a request with one of those is refused by name
    learned: frozenset[str] = frozenset()
    refused: dict[str, int] = field(default_factory=dict)
    # the frames the table needed to learn a verb: a refused verb with as many was refused for what its
    # frames say (no role a request leaves open), one with fewer for having too few of them
    min_frames: int = 0

    # the two reasons of `refusal`, for a count of refused verbs
    REFUSED_BECAUSE = "too few frames, or no place or tool said"

    def refusal(self, name: str) -> str:
        """Why the refused verb `name` was not learned, in words for a one-line message: too few frames, or
        frames that seldom say where it puts things or with what (the roles a request leaves open)."""
        seen = self.refused[name]
        if seen < self.min_frames:
            return f"the corpora have {seen:,} frames of {name!r}, too few to learn what it needs"
        return f"the corpora's {seen:,} frames of {name!r} seldom say where it puts things or with what"

    @property
    def person_words(self) -> frozenset[str]:
        """The words that name a person in a request: a recipient ("me", "her") or the person who asks as a
        request's subject ("i", "we")."""
        return self.recipient_pronouns | self.speaker_subjects

    @property
    def hand_written(self) -> list[str]:
        """The predicates of the hand-written lexicon (the paper's eleven)."""
        return sorted(p for p in self.predicates if p not in self.learned)

    @property
    def motion_classes(self) -> dict[str, str]:
        """predicate -> its class of motion, for the predicates that have one (the learned ones)."""
        return {name: spec.motion for name, spec in self.predicates.items() if spec.motion}


def _spec(name: str, spec: dict) -> PredicateSpec:
    return PredicateSpec(
        name=name,
        roles=tuple(spec["roles"]),
        object_role=spec["object"],
        with_role=spec.get("with"),
        preps={role: tuple(p) for role, p in spec.get("preps", {}).items()},
        particles=frozenset(spec.get("particles", [])),
        alternating=bool(spec.get("alternating")),
        sentence=spec["sentence"],
        past=spec.get("past"),
        alternatives=dict(spec.get("alternatives") or {}),
        rates={role: float(rate) for role, rate in (spec.get("rates") or {}).items()},
        motion=spec.get("motion"),
    )


@lru_cache(maxsize=4)
def _hand_written(path: str) -> Lexicon:
    data = json.loads(Path(path).read_text("utf-8"))
    return Lexicon(
        predicates={name: _spec(name, spec) for name, spec in data["predicates"].items()},
        measure_nouns=frozenset(data["measure_nouns"]),
        quantity_nouns=frozenset(data["quantity_nouns"]),
        object_pronouns=frozenset(data["object_pronouns"]),
        recipient_pronouns=frozenset(data["recipient_pronouns"]),
        objects=tuple(data.get("objects", ())),
        courtesy_words=frozenset(data.get("courtesy_words", ())),
        speaker_labels=frozenset(data.get("speaker_labels", ())),
        speaker_places=frozenset(data.get("speaker_places", ())),
        request_verbs=frozenset(data.get("request_verbs", ())),
        speaker_subjects=frozenset(data.get("speaker_subjects", ())),
        request_predicate=data.get("request_predicate"),
    )


@lru_cache(maxsize=8)
def _with_learned(path: str, table: str, modified_ns: int) -> Lexicon:
    """The hand-written lexicon with a learned table's predicates added (the hand-written ones win); a table
    that cannot be read is a ResourceError naming it."""
    from lmcr.files import read_resource

    lex = _hand_written(path)
    data = read_resource(Path(table), "learned predicate table", _learned_table)
    learned = {
        name: _with_english_preps(_spec(name, entry["spec"]))
        for name, entry in data["predicates"].items()
        if name not in lex.predicates
    }
    return replace(
        lex,
        predicates={**learned, **lex.predicates},
        learned=frozenset(learned),
        refused={name: int(n) for name, n in data.get("refused", {}).items()},
        min_frames=data.get("settings", {}).get("min_frames", 0),
    )


def _with_english_preps(spec: PredicateSpec) -> PredicateSpec:
    """A learned spec that also takes, for each of its open roles, the prepositions English gives that role
    alone (`PREP_ROLES`: "to", "into" a Destination) and the verb's frames left to no role: recipes bring
    things to a boil, so "to" introduces no place of bring's in the corpora, yet "bring the plates to the
    sink" says where they go. The learned prepositions stay first (`prep_rank`)."""
    taken = {p for preps in spec.preps.values() for p in preps}
    added = {
        role: tuple(p for p, roles in PREP_ROLES.items() if roles == (role,) and p not in taken)
        for role in spec.open_roles
    }
    return replace(spec, preps={**spec.preps, **{r: (*spec.preps.get(r, ()), *added[r]) for r in added if added[r]}})


def _learned_table(value: object) -> dict:
    if not (isinstance(value, dict) and isinstance(value.get("predicates"), dict)):
        raise ValueError("not a learned predicate table: no 'predicates' object")
    settings = value.get("settings", {})
    min_frames = settings.get("min_frames", 0) if isinstance(settings, dict) else None
    if not isinstance(min_frames, int) or isinstance(min_frames, bool) or min_frames < 0:
        raise ValueError("its settings give no count of frames a verb needs ('min_frames')")
    for name, entry in value["predicates"].items():
        spec = entry.get("spec") if isinstance(entry, dict) else None
        if not (isinstance(spec, dict) and isinstance(spec.get("roles"), list) and len(spec["roles"]) == 2):
            raise ValueError(f"predicate {name!r} has no spec with two roles")
        if not isinstance(spec.get("sentence"), str) or not isinstance(spec.get("object"), str):
            raise ValueError(f"predicate {name!r} has no sentence template or object role")
        if not isinstance(spec.get("motion"), (str, type(None))):
            raise ValueError(f"predicate {name!r} has a class of motion that is not a name")
    return value


def learned_table_path() -> Path:
    """Where the workspace's learned predicate table is: `$LMCR_DATA_DIR/srl/predicates.json`."""
    return data_dir_from_env() / SRL_SUBDIR / PREDICATES_FILE


def learned_table_file(learned: Path | str | bool = True) -> Path | None:
    """The learned table `load_lexicon(learned=...)` merges in: the given path, or the workspace's for
    True; None for False, or when there is no such file."""
    table = learned_table_path() if learned is True else Path(learned) if learned else None
    return table if table is not None and table.is_file() else None


def load_lexicon(path: str | None = None, learned: Path | str | bool = True) -> Lexicon:
    """The lexicon (`LMCR_LEXICON` or the packaged `lexicon.json`), with the predicates learned from the
    frame corpus merged in: `learned` a table's path, True for the workspace's (`learned_table_path`, when
    the frame build has written one), False for none (the frame build itself parses with the eleven)."""
    base = str(path or os.environ.get("LMCR_LEXICON") or LEXICON_PATH)
    table = learned_table_file(learned)
    if table is None:
        return _hand_written(base)
    return _with_learned(base, str(table.resolve()), table.stat().st_mtime_ns)
