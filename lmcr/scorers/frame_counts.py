"""Count-based frame model: how plausible a frame is from how often its fillers fill those roles
together in the SRL frame corpus, with interpolated (Dirichlet) smoothing that backs off.

A complete frame (v, r1: a1, r2: a2) scores log P(a2 | v, r1 = a1) + log P(a1 | v, r2 = a2): both
directions, so the score does not depend on which role a scenario or a completion varies. With c the
counts over frames of robot predicates and alpha the smoothing mass:

    P(o | v, s = a, m) = (c(v, s=a, m=o) + alpha P(o | b, s = a, m)) / (c(v, s=a, m) + alpha)
    P(o | b, s = a, m) = (c(b, s=a, m=o) + alpha P(o | K, s = a, m)) / (c(b, s=a, m) + alpha)
    P(o | K, s = a, m) = (c(K, s=a, m=o) + alpha P(o | v, m))        / (c(K, s=a, m) + alpha)
    P(o | v, m)        = (c(v, m=o)      + alpha P(o | m))    / (c(v, m)      + alpha)
    P(o | m)           = (c(m=o)         + alpha P(o))        / (c(m)         + alpha)
    P(o)               = (c(o) + 1) / (N + V + 1)   N filler occurrences, V distinct fillers, +1 unseen

P(o | m) is what fills role m across every predicate, hand-written and learned: a verb seldom seen with a
filler still knows that bins are where things go and an orange is what is moved.

A learned predicate's pairs back off to those of the verbs it is one of, most alike first. b is the base
verb of a phrasal verb ("warm" of "warm up": what is warmed up is warmed in a saucepan or the microwave).
K is its class of motion (`frame_corpus.predicates.MOTION_CLASSES`: place, serve, cut, ...), and c(K, ...)
pools the pair counts of every learned predicate of that class: "put away" states its place in 132 frames
and never with milk, but the verbs that place things put milk in the fridge hundreds of times; "serve
the toast" learns the plate from what the serving verbs do with toast. A level a predicate lacks (a verb
with no particle, a base verb never counted, the hand-written eleven's class) is skipped, so the
eleven's scores do not change. On the external request sets the two levels raised the top guesses right
of every set (docs/guide/complete.md). Tried there and not kept: the class's fillers as a level between
P(o | v, m) and P(o | m) (IntroPlan lost most of its top guesses), and more smoothing mass at the class
level (50, 500: fewer top guesses right on three sets).

The class level can outvote the verb's own fillers: "chill" puts things in the refrigerator hundreds of
times and never chills an apple, so P(o | chill, Theme = apple, Destination) is the placing verbs' (a
cup, a bowl). The `verb_fillers` term (`verb_preference`) gives the verb its say within a role:

    log P~(o | v, m) - log P(o | K, m),  P~(o | v, m) = (c(v, m=o) + alpha P(o | K, m)) / (c(v, m) + alpha)

summed over the frame's fillers: how much likelier the verb itself fills role m with o than the verbs of
its class do (0 for a verb seldom seen: P~ is then its class's; 0 for the eleven, which have no class).
It is a ratio, not a probability, so it only orders the fillers of one role (`ScorerSpec.within_role`):
as a factor of the pair level it moved which open role won (HuRIC's right role 0.973 to 0.904). On the
external request sets it raised COAT's top guesses from 23 to 28 of 59 and left the other three sets'
and every right role unchanged (docs/guide/complete.md); weights 0.5 and 2 gave 144 and 145 of 399, 1
gave 145.

The frame corpus keeps a filler's head as its lemma ("whisk the eggs" counts egg), so an object labelled
in the plural is counted as its singular where the counts know that form better (`text.counted_form`):
"whisk the eggs" had scored a sponge above the bowl, eggs being a filler seen 7 times and egg 22,236.

alpha = 5: of the two values tried on the dev ratings (1 and 5), the better at lambda=1, k=6. Unlike the
LMs this model sees only frames whose roles the SRL filled, and treats a filler as one symbol: it knows
"sprinkle cheese on the pizza" was said five times, not how "cheese" relates to "parmesan".
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path

import pandas as pd
from pyarrow import ArrowException

from lmcr.files import OutputError, atomic_path
from lmcr.frame import Frame
from lmcr.scorers.mixture import Mixture
from lmcr.scorers.resources import MethodUnavailable
from lmcr.store import named_query, read_connection
from lmcr.text import counted_form

ALPHA = 5.0  # the smoothing mass (module docstring)
# what the levels back off to, in the calibration's fingerprint: a pair to the base verb's, then to the
# predicate's class of motion; P(o | v, m) to P(o | m) (module docstring)
BACKOFF = "base/class/role"


def add_one(count: float, total: float, types: int) -> float:
    """P(x) = (c(x) + 1) / (N + V + 1): a marginal that keeps some mass for a filler never seen."""
    return (count + 1) / (total + types + 1)


def dirichlet(count: float, total: float, prior: float, alpha: float = ALPHA) -> float:
    """(c + alpha prior) / (total + alpha): a conditional interpolated with the distribution it backs off to."""
    return (count + alpha * prior) / (total + alpha)


def weighted_counts(
    db: Path, sql_dir: Path, queries: tuple[str, ...], corpus: str = "all", mixture: Mixture = Mixture()
) -> list[list[tuple]]:
    """Each named count query's rows over the setting `corpus` (`all`: every corpus), the count (last
    column) of each corpus's rows times the weight the mixture gives it."""
    return [
        list(df.itertuples(index=False, name=None)) for df in weighted_frames(db, sql_dir, queries, corpus, mixture)
    ]


def weighted_frames(
    db: Path, sql_dir: Path, queries: tuple[str, ...], corpus: str = "all", mixture: Mixture = Mixture()
) -> list[pd.DataFrame]:
    """Each named count query's rows over the setting `corpus` as one data frame (read column-wise), the
    count (last column) of each corpus's rows times the weight the mixture gives it."""
    found: list[list[pd.DataFrame]] = [[] for _ in queries]
    con = read_connection(db)
    try:
        for part, weight in mixture.parts(corpus).items():
            for frames, query in zip(found, queries):
                df = con.execute(named_query(sql_dir, query), {"corpus": part}).df()
                df[df.columns[-1]] = df[df.columns[-1]].astype(float) * weight
                frames.append(df)
    finally:
        con.close()
    return [pd.concat(frames, ignore_index=True) for frames in found]


def cached_counts(path: Path | None, columns: int, count: Callable[[], pd.DataFrame]) -> pd.DataFrame:
    """`count()`, kept as Parquet at `path` (written atomically): a saved file is read instead when it is
    a table of `columns` columns; one that is missing, unreadable or otherwise shaped is counted afresh.
    Parquet holds plain columns: reading it runs nothing. Where the file cannot be written (a store in a
    read-only folder), the counts are used unkept: they only save time."""
    if path is None:
        return count()
    try:
        saved = pd.read_parquet(path)
        if len(saved.columns) == columns and pd.api.types.is_numeric_dtype(saved.iloc[:, -1]):
            return saved
    except (OSError, ValueError, ArrowException):
        pass  # no cache yet, or not one of ours
    counted = count()
    try:
        with atomic_path(path) as tmp:
            counted.to_parquet(tmp, index=False)
    except OutputError:
        pass
    return counted


FILLER_COLUMNS = ["v", "role", "value", "n"]
PAIR_COLUMNS = ["v", "given_role", "given", "role", "value", "n"]
COLUMNS = {"frame_fillers": FILLER_COLUMNS, "frame_filler_pairs": PAIR_COLUMNS}  # each count query's


def _frame(rows, columns: list[str]) -> pd.DataFrame:
    """Count rows (tuples, or a data frame with the columns in this order) under the names `columns`."""
    if isinstance(rows, pd.DataFrame):
        return rows.set_axis(columns, axis=1).astype({"n": float})
    return pd.DataFrame(list(rows), columns=columns).astype({"n": float})


def _sums(df: pd.DataFrame, keys: list[str]) -> Counter:
    """The summed counts by `keys`: a tuple per key, or the value itself for one key column."""
    summed = df.groupby(keys, sort=False, dropna=False, as_index=False)["n"].sum()
    columns = [summed[k].tolist() for k in keys]
    return Counter(dict(zip(columns[0] if len(keys) == 1 else zip(*columns), summed["n"].tolist())))


class FrameCountScorer:
    """Smoothed conditional filler probabilities from (predicate, role, value) and pair counts."""

    def __init__(
        self,
        fillers: Iterable[tuple[str, str, str, float]],
        pairs: Iterable[tuple[str, str, str, str, str, float]],
        alpha: float = ALPHA,
        classes: dict[str, str] | None = None,
    ):
        """`classes`: predicate -> its class of motion, for the predicates that have one (module docstring).
        `fillers` and `pairs`: count rows, or data frames of those columns (what `from_store` reads)."""
        self.alpha = alpha
        self.classes = dict(classes or {})
        # Counts may be weighted (a mixture), hence floats. Each table is summed column-wise: the full
        # store has about a million rows, which a loop over rows took seconds to add up at every start.
        f = _frame(fillers, FILLER_COLUMNS)
        f_k = f.assign(k=f["v"].map(self.classes)).dropna(subset=["k"])
        self.filler = _sums(f, ["v", "role", "value"])  # (v, role, value)
        self.role_total = _sums(f, ["v", "role"])  # (v, role)
        self.in_role = _sums(f, ["role", "value"])  # (role, value), over every predicate
        self.role_n = _sums(f, ["role"])
        self.value = _sums(f, ["value"])
        self.class_filler = _sums(f_k, ["k", "role", "value"])  # (class, role, value): pooled
        self.class_role_total = _sums(f_k, ["k", "role"])
        p = _frame(pairs, PAIR_COLUMNS)
        p_k = p.assign(k=p["v"].map(self.classes)).dropna(subset=["k"])
        self.pair = _sums(p, ["v", "given_role", "given", "role", "value"])  # (v, given role, given value, role, value)
        self.given_total = _sums(p, ["v", "given_role", "given", "role"])
        self.class_pair = _sums(p_k, ["k", "given_role", "given", "role", "value"])  # (class, given role, ...): pooled
        self.class_given_total = _sums(p_k, ["k", "given_role", "given", "role"])
        self.n, self.types = sum(self.value.values()), len(self.value)
        self._forms: dict[str, str] = {}  # object label -> the form the counts name it by (`counted_form`)
        verbs = {v for v, _ in self.role_total}
        # a phrasal verb's base verb ("put" of "put away"), when the frames count it too
        self.base = {v: v.split(" ")[0] for v in verbs if " " in v and v.split(" ")[0] in verbs}

    @classmethod
    def from_store(
        cls,
        db: Path,
        sql_dir: Path,
        corpus: str = "all",
        alpha: float = ALPHA,
        mixture: Mixture = Mixture(),
        classes: dict[str, str] | None = None,
        pairs: bool = True,
        cache: Path | None = None,
    ) -> FrameCountScorer:
        """Counts of the store's frames in one corpus setting (`all` for every corpus); in `all`, each
        corpus's frames count as often as the mixture weighs it. `classes`: as the constructor's. Without
        `pairs`, the fillers alone are read (all `verb_preference` needs; a pair then scores as unseen).
        `cache`: where the weighted counts are kept, each query's in `<cache>-<query>.parquet` (the caller
        names it by the frames' content and the mixture): reading the counts takes the full store's queries
        seconds, which every `lmcr complete` paid."""
        queries = ("frame_fillers", "frame_filler_pairs") if pairs else ("frame_fillers",)
        fillers, *pair_rows = [
            cached_counts(
                cache and cache.with_name(f"{cache.name}-{query}.parquet"),
                len(COLUMNS[query]),
                lambda query=query: weighted_frames(db, sql_dir, (query,), corpus, mixture)[0],
            )
            for query in queries
        ]
        if fillers.empty:
            raise MethodUnavailable(f"no robot-predicate frames for corpus {corpus!r} in {db} (run `lmcr frames`)")
        return cls(fillers, pair_rows[0] if pair_rows else [], alpha, classes)

    def form(self, label: str) -> str:
        """The filler an object's label is counted as: "eggs" as egg, as the frame corpus keeps it."""
        found = self._forms.get(label)
        if found is None:
            found = self._forms[label] = counted_form(label, self.value)
        return found

    def p_value(self, value: str) -> float:
        return add_one(self.value[value], self.n, self.types)

    def p_in_role(self, role: str, value: str) -> float:
        """P(value | role), over every predicate."""
        return dirichlet(self.in_role[(role, value)], self.role_n[role], self.p_value(value), self.alpha)

    def p_filler(self, v: str, role: str, value: str) -> float:
        """P(value | v, role)."""
        return dirichlet(
            self.filler[(v, role, value)], self.role_total[(v, role)], self.p_in_role(role, value), self.alpha
        )

    def p_class_filler(self, k: str, role: str, value: str) -> float:
        """P(value | K, role): what the verbs of class K fill `role` with, backing off to P(value | role)."""
        prior = self.p_in_role(role, value)
        return dirichlet(self.class_filler[(k, role, value)], self.class_role_total[(k, role)], prior, self.alpha)

    def verb_preference(self, frame: Frame) -> float:
        """The summed log ratio of how likely the verb fills each role with its filler to how likely the
        verbs of its class do (module docstring); 0 for a predicate without a class."""
        v, roles = frame
        k = self.classes.get(v)
        if k is None:
            return 0.0
        total = 0.0
        for role, value in ((r, self.form(o)) for r, o in roles.items()):
            of_class = self.p_class_filler(k, role, value)
            own = dirichlet(self.filler[(v, role, value)], self.role_total[(v, role)], of_class, self.alpha)
            total += math.log(own / of_class)
        return total

    def p_given(self, v: str, given_role: str, given: str, role: str, value: str) -> float:
        """P(value | v, given_role = given, role), backing off through v's base verb and class when it has
        them (module docstring)."""
        prior = self.p_filler(v, role, value)
        levels = [(self.pair, self.given_total, v)]
        if v in self.base:
            levels.append((self.pair, self.given_total, self.base[v]))
        if v in self.classes:
            levels.append((self.class_pair, self.class_given_total, self.classes[v]))
        for pairs, totals, key in reversed(levels):  # the most general level first: each smooths the next
            given_key = (key, given_role, given, role)
            prior = dirichlet(pairs[(*given_key, value)], totals[given_key], prior, self.alpha)
        return prior

    def score_frame(self, frame: Frame) -> float:
        v, roles = frame
        items = [(role, self.form(value)) for role, value in roles.items()]
        if len(items) == 1:
            return math.log(self.p_filler(v, *items[0]))
        return sum(math.log(self.p_given(v, s, a, m, o)) for s, a in items for m, o in items if m != s)

    def score_frames(self, frames: list[Frame]) -> list[float]:
        return [self.score_frame(f) for f in frames]
