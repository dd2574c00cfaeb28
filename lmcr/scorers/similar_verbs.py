"""What the verbs most like a predicate do with the same two fillers: similarity-based smoothing of the
frame counts (Dagan, Lee and Pereira 1999), learned from the frame corpus.

The frame counts know a pair of fillers only where the predicate itself was seen with it. "dump" fills
both its roles in 58 frames of the whole corpus, so "dump the rice into the bowl" and "dump the pan into
the bowl" are both unseen and the counts fall back on how often rice and pans are dumped at all. Verbs
that take the same fillers in the same relation know better: rice is tipped, transferred and scraped
into bowls hundreds of times, pans hardly ever.

For a robot predicate v whose object states role R (the lexicon's `object`: Theme for pour, Destination
for fill) and whose other role is S, another verb u states the same relation as
  - a verb that is no robot predicate: its object (a) and the object (o) of one of S's prepositions
    (the lexicon's `preps` of S, and `with` when S is the with-role): "transfer the rice into a bowl";
  - a robot predicate with the same two roles: by role name ("pour water into the glass" for "fill the
    glass with water").
Each such verb has pair counts c_u(a, o). How alike u is to v: the cosine of their PPMI-weighted
vectors of R fillers times that of their S fillers (PPMI over every verb of the relation). The
NEIGHBOURS most alike, each with at least MIN_PAIRS pair frames, pool their counts weighted by their
similarity over the best neighbour's:

    C(a, o)  = sum over neighbours u of w_u c_u(a, o)
    score    = WEIGHT * (log P(o | a) + log P(a | o))
    P(o | a) = (C(a, o) + ALPHA P(o)) / (C(a) + ALPHA),   P(o) = (C(o) + 1) / (C + types of o + 1)

v's own frames are not pooled: `frame_counts` counts them, and the default completion method adds this
model as a further expert. Nothing in it is written by hand: the relation is the lexicon's (how English
states each role, which the parser uses too), the neighbours and their weights are the corpus's.
NEIGHBOURS and the similarity were chosen on the dev ratings among a few settings (README, Results: 10/20/40
neighbours, raw or PPMI cosine); WEIGHT among 0.25, 0.5 and 1 as the one that meets the Table I target
while losing the fewest dev instructions.
"""

from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from lmcr.files import cached_json
from lmcr.frame import Frame
from lmcr.lexicon import Lexicon, PredicateSpec
from lmcr.scorers.frame_counts import add_one, dirichlet, weighted_counts
from lmcr.scorers.mixture import Mixture
from lmcr.scorers.resources import MethodUnavailable
from lmcr.text import counted_form

WEIGHT = 0.25
NEIGHBOURS = 20
MIN_PAIRS = 20  # a verb seen with fewer pairs has too few fillers to compare
# smoothing: lmcr/scorers/frame_counts.py's add-one marginal and Dirichlet interpolation, with the frame counts' mass


@dataclass(frozen=True)
class Relation:
    """How a robot predicate's two roles are stated: its object fills `object_role`; `preps` head the
    phrases that fill `other_role`."""

    object_role: str
    other_role: str
    preps: frozenset[str]

    @classmethod
    def of(cls, spec: PredicateSpec) -> Relation:
        other = spec.other(spec.object_role)
        preps = set(spec.preps.get(other, ()))
        if spec.with_role == other:
            preps.add("with")
        return cls(spec.object_role, other, frozenset(preps))

    def filler_pair(self, frame: Frame) -> tuple[str, str] | None:
        """(object-role filler, other-role filler) of a frame; None for a frame that has neither role or only
        one of them (a purpose clause's frame: "hand me something to pour"). A role it has but left empty
        is a bug: completion and evaluation fill every role they score."""
        roles = frame.role_map
        if self.object_role not in roles or self.other_role not in roles:
            return None
        if not roles[self.object_role] or not roles[self.other_role]:
            raise ValueError(
                f"similar_verbs scores complete frames: {frame.to_json()} lacks {self.object_role} or {self.other_role}"
            )
        return roles[self.object_role], roles[self.other_role]


@dataclass(frozen=True)
class PairTable:
    """Pooled pair counts of one predicate, with the marginals and sizes the smoothing needs."""

    pairs: dict[tuple[str, str], float]
    objects: dict[str, float]  # C(a)
    others: dict[str, float]  # C(o)
    total: float
    object_types: int
    other_types: int

    @classmethod
    def of(cls, pairs: dict[tuple[str, str], float]) -> PairTable:
        objects, others = Counter(), Counter()
        for (a, o), n in pairs.items():
            objects[a] += n
            others[o] += n
        return cls(dict(pairs), dict(objects), dict(others), sum(objects.values()), len(objects), len(others))

    def log_p(self, a: str, o: str) -> float:
        """log P(o | a) + log P(a | o), each smoothed towards the add-one marginal; a label in the plural as
        the counts know it ("eggs": egg, `counted_form`)."""
        a, o = counted_form(a, self.objects), counted_form(o, self.others)
        joint, c_a, c_o = self.pairs.get((a, o), 0.0), self.objects.get(a, 0.0), self.others.get(o, 0.0)
        p_o, p_a = add_one(c_o, self.total, self.other_types), add_one(c_a, self.total, self.object_types)
        return math.log(dirichlet(joint, c_a, p_o)) + math.log(dirichlet(joint, c_o, p_a))

    def restricted(self, words: set[str]) -> PairTable:
        """The same table holding only pairs and marginals of `words` (what a cache keeps; sizes unchanged)."""
        return PairTable(
            {k: n for k, n in self.pairs.items() if k[0] in words and k[1] in words},
            {a: n for a, n in self.objects.items() if a in words},
            {o: n for o, n in self.others.items() if o in words},
            self.total,
            self.object_types,
            self.other_types,
        )


def relation_pairs(name: str, lex: Lexicon, generic: dict[str, list[tuple]], robot: list[tuple]) -> dict[str, Counter]:
    """verb -> pair counts in the relation of predicate `name`; `generic` holds the rows of the named query
    `verb_filler_pairs` (verb, object, preposition, value, n) by preposition, `robot` those of
    `frame_filler_pairs` (predicate, given role, given value, role, value, n)."""
    relation = Relation.of(lex.predicates[name])
    pairs: dict[str, Counter] = defaultdict(Counter)
    for prep in relation.preps:
        for verb, a, o, n in generic.get(prep, ()):
            pairs[verb][(a, o)] += n
    same_roles = {
        p for p, spec in lex.predicates.items() if set(spec.roles) == {relation.object_role, relation.other_role}
    }
    for predicate, given_role, a, role, o, n in robot:
        if predicate in same_roles and given_role == relation.object_role and role == relation.other_role:
            pairs[predicate][(a, o)] += n
    return pairs


def _ppmi(marginals: dict[str, Counter]) -> dict[str, tuple[dict[str, float], float]]:
    """Each verb's filler vector weighted by positive pointwise mutual information over all the verbs,
    with its norm."""
    totals: Counter = Counter()
    for counts in marginals.values():
        totals.update(counts)
    grand = sum(totals.values())
    vectors = {}
    for verb, counts in marginals.items():
        size = sum(counts.values())
        vector = {
            x: math.log(n * grand / (size * totals[x])) for x, n in counts.items() if n * grand > size * totals[x]
        }
        vectors[verb] = vector, math.sqrt(sum(x * x for x in vector.values()))
    return vectors


def _cosine(u: tuple[dict[str, float], float], v: tuple[dict[str, float], float]) -> float:
    (small, small_norm), (large, large_norm) = (u, v) if len(u[0]) < len(v[0]) else (v, u)
    if not small_norm or not large_norm:
        return 0.0
    return sum(x * large.get(k, 0.0) for k, x in small.items()) / (small_norm * large_norm)


def neighbours(
    pairs: dict[str, Counter], predicate: str, k: int = NEIGHBOURS, min_pairs: int = MIN_PAIRS
) -> dict[str, float]:
    """The k verbs whose fillers are most like `predicate`'s (PPMI cosine of the object-role fillers
    times that of the other role's), each weighted by its similarity over the best one's."""
    sides = []
    for i in (0, 1):
        marginals: dict[str, Counter] = {}
        for verb, counts in pairs.items():
            side = marginals[verb] = Counter()
            for key, n in counts.items():
                side[key[i]] += n
        sides.append(_ppmi(marginals))
    own = [side.get(predicate, ({}, 0.0)) for side in sides]
    similar = [
        (_cosine(own[0], sides[0][verb]) * _cosine(own[1], sides[1][verb]), verb)
        for verb, counts in pairs.items()
        if verb != predicate and sum(counts.values()) >= min_pairs
    ]
    top = sorted(((s, verb) for s, verb in similar if s > 0), key=lambda sv: (-sv[0], sv[1]))[:k]
    return {verb: s / top[0][0] for s, verb in top}


class SimilarVerbs:
    """Per robot predicate, the counts its most similar verbs pool; scores complete frames."""

    def __init__(
        self,
        tables: dict[str, PairTable],
        near: dict[str, dict[str, float]],
        lex: Lexicon,
        words: set[str] | None = None,
        full: Callable[[], SimilarVerbs] | None = None,
    ):
        # `words`: the tables hold only these fillers' counts (a cache); a frame with another filler is
        # scored by `full()`, the complete counts, made when first needed.
        self.tables, self.near, self.words, self._full = tables, near, words, full
        self.relations = {name: Relation.of(spec) for name, spec in lex.predicates.items()}

    @classmethod
    def from_counts(cls, lex: Lexicon, generic_rows: Iterable[tuple], robot_rows: list[tuple]) -> SimilarVerbs:
        """From the rows of the named queries `verb_filler_pairs` and `frame_filler_pairs`."""
        generic: dict[str, list[tuple]] = defaultdict(list)
        for verb, a, prep, o, n in generic_rows:
            generic[prep].append((verb, a, o, n))
        tables, near = {}, {}
        for name in lex.predicates:
            pairs = relation_pairs(name, lex, generic, robot_rows)
            near[name] = neighbours(pairs, name)
            pooled: Counter = Counter()
            for verb, weight in near[name].items():
                for key, n in pairs[verb].items():
                    pooled[key] += weight * n
            tables[name] = PairTable.of(pooled)
        return cls(tables, near, lex)

    @classmethod
    def count(
        cls, db: Path, sql_dir: Path, lex: Lexicon, corpus: str = "all", mixture: Mixture = Mixture()
    ) -> SimilarVerbs:
        """Counted in the store's frames of a corpus setting (`all`: each corpus weighted by the mixture)."""
        generic, robot = weighted_counts(db, sql_dir, ("verb_filler_pairs", "frame_filler_pairs"), corpus, mixture)
        if not robot:
            raise MethodUnavailable(f"no robot-predicate frames for corpus {corpus!r} in {db} (run `lmcr frames`)")
        return cls.from_counts(lex, generic, robot)

    @classmethod
    def cached(cls, db: Path, sql_dir: Path, lex: Lexicon, corpus: str, mixture: Mixture, cache: Path) -> SimilarVerbs:
        """The tables for the lexicon's objects from `cache` when it holds them (the caller names the file by
        the frame corpus content and mixture), else counted (seconds on the full store) and saved there."""
        words = sorted(set(lex.objects))

        def full() -> SimilarVerbs:
            return cls.count(db, sql_dir, lex, corpus, mixture)

        def counted() -> dict:
            found = full()
            return {
                "words": words,
                "neighbours": found.near,
                "tables": {name: _table_json(t.restricted(set(words))) for name, t in found.tables.items()},
            }

        def usable(saved) -> bool:  # a malformed table raises here, and is counted afresh
            return (
                saved["words"] == words
                and set(saved["tables"]) == set(lex.predicates)
                and all(_table_of(t) for t in saved["tables"].values())
            )

        saved = cached_json(cache, usable, counted)
        tables = {name: _table_of(t) for name, t in saved["tables"].items()}
        return cls(tables, saved["neighbours"], lex, set(words), full)

    @cached_property
    def complete_counts(self) -> SimilarVerbs:
        return self._full() if self._full else self

    def score_frames(self, frames: list[Frame]) -> list[float]:
        """WEIGHT * (log P(o | a) + log P(a | o)) under each frame's predicate's pooled counts; 0 for a predicate
        learned from the corpus (the tables are the hand-written eleven's, whose rare pairs they back off),
        and for a frame with one filler of the pair (no pair to weigh)."""
        scores = []
        for frame in frames:
            pair = self.relations[frame.predicate].filler_pair(frame) if frame.predicate in self.relations else None
            if pair is None:  # a learned predicate (its own counts score it), or one filler
                scores.append(0.0)
                continue
            table = self.tables[frame.predicate]
            a, o = counted_form(pair[0], table.objects), counted_form(pair[1], table.others)
            source = self if self.words is None or {a, o} <= self.words else self.complete_counts
            scores.append(WEIGHT * source.tables[frame.predicate].log_p(a, o))
        return scores


def _table_json(table: PairTable) -> dict:
    return {
        "pairs": [[a, o, n] for (a, o), n in sorted(table.pairs.items())],
        "objects": table.objects,
        "others": table.others,
        "total": table.total,
        "object_types": table.object_types,
        "other_types": table.other_types,
    }


def _table_of(saved: dict) -> PairTable:
    return PairTable(
        {(a, o): float(n) for a, o, n in saved["pairs"]},
        saved["objects"],
        saved["others"],
        float(saved["total"]),
        int(saved["object_types"]),
        int(saved["other_types"]),
    )
