"""The scorer registry: each method's name, how its scorer is built from the resources, and what a
completion calibration of it is valid for. A scorer takes complete frames and returns one float each
(higher = more plausible); 'a+b' sums two methods' scores."""

from __future__ import annotations

import functools
import random
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from lmcr.files import file_sha256
from lmcr.lexicon import learned_table_file, load_lexicon
from lmcr.scorers.caches import cache_dir, count_cache, superseding, word_vectors
from lmcr.scorers.lm_checkpoints import lm_experts, lm_version_dir, load_lm
from lmcr.scorers.resources import (
    MethodResources,
    MethodUnavailable,
    corpus_sentences,
    corpus_words,
    robot_terms,
    store_corpus_hash,
    store_path,
)
from lmcr.setting import LM_METHODS

if TYPE_CHECKING:
    from pathlib import Path

    from lmcr.frame import Frame

# The scorers' own modules (torch, gensim, scipy) are imported where a scorer is built, so that the
# command line and light commands start fast (`bench/bench_cli.py`).

# What completes instructions by default: the sentence LM times the frame counts times what the verbs
# most like the predicate do with the same fillers (lmcr/scorers/similar_verbs.py), less how common the fillers
# are anyway (lmcr/scorers/rarity.py), plus what the instruction's purpose says of each filler
# (lmcr/scorers/context_pmi.py; 0 without one, so on the rated frames), and, within a role, how much
# likelier a learned verb itself fills it with each object than the verbs of its class do
# (`FrameCountScorer.verb_preference`; 0 for the eleven) and how much likelier the sentence LM finds it
# there with the request's stated words than without (lmcr/scorers/stated_pmi.py; 0 for the eleven).
# The household weight under which it runs is chosen on both dev sets (lmcr/evaluate/choose_mixture.py);
# its figures are in docs/guide/complete.md.
COMPLETION_METHOD = "sentence_lm+frame_counts+similar_verbs+rarity+context_pmi+verb_fillers+stated_pmi"


class Scorer(Protocol):
    """Complete frames in, one float each out (higher = more plausible; log-probabilities for the LMs
    and frame_counts, so that 'a+b' sums are products of experts). `context` is the rest of the
    instruction ("for my tea", `srl.context`): scorers that can read text take it, the others ignore it,
    and "" scores as if there were none."""

    def __call__(self, frames: list[Frame], context: str = "") -> list[float]: ...


@dataclass(frozen=True)
class ScorerSpec:
    """How to build a method's scorer from the resources (a function of the frames, and of the context
    when `reads_context`), and what a completion calibration of it is valid for (None: not calibrated)."""

    build: Callable[[MethodResources], Callable[..., list[float]]]
    fingerprint: Callable[[MethodResources], str | None] = lambda res: None
    reads_context: bool = False
    # a term that ranks the fillers of one role and leaves the choice among open roles to the rest
    # (its scores are centred per role set, but their spread would still move which role wins)
    within_role: bool = False


class SharedLM:
    """A loaded LM (`LMScorer` or `MixedLM`) as the scorer of its method, `(frames, context) -> scores`,
    that other parts of a sum can read frames of their own with, in the same pass as the method's frames
    (`read_together`): the stated_pmi term's masked frames are a second set of texts after the same verb,
    and one walk and one context read for both cost about two thirds of two."""

    def __init__(self, lm):
        self.lm = lm
        self._read: dict[tuple, list[float]] = {}  # what read_together read, each group until it is asked for

    def __call__(self, frames: list[Frame], context: str = "") -> list[float]:
        done = self._read.pop((tuple(frames), context), None)
        return done if done is not None else self.lm.score_frames(frames, context)

    def read_together(self, groups: list[list[Frame]], context: str = "") -> None:
        """Read the groups of frames in one pass; each group's scores are then what the next call with just
        those frames and that context returns (the same scores a call of its own gives, up to the last bits
        of a batched product)."""
        scores = self.lm.score_frame_groups(groups, context)
        self._read = {(tuple(group), context): values for group, values in zip(groups, scores)}


class SummedScorer:
    """'a+b+...': the parts' scores summed (for log-probability methods, a product of experts).
    `with_roles` also gives the sum of the parts that choose among open roles (all but the within-role
    terms), each part scored once. A part that reads frames of its own with an LM the sum scores with
    (its `lm` is a `SharedLM` part; its `lm_frames(frames)` those frames) has them read in that LM's pass."""

    def __init__(self, parts: list[tuple[Scorer, bool]]):
        self.parts = parts
        self.has_within_role = any(within_role for _, within_role in parts)
        lms = [part for part, _ in parts if isinstance(part, SharedLM)]
        self.riders = [part for part, _ in parts if any(getattr(part, "lm", None) is lm for lm in lms)]

    def __call__(self, frames: list[Frame], context: str = "") -> list[float]:
        return self.with_roles(frames, context)[0]

    def with_roles(self, frames: list[Frame], context: str = "") -> tuple[list[float], list[float]]:
        """(the full sums, the sums without the within-role terms)."""
        for rider in self.riders:
            if extra := rider.lm_frames(frames):  # none for the eleven's frames: nothing to join
                rider.lm.read_together([frames, extra], context)
        full, roles = [0.0] * len(frames), [0.0] * len(frames)
        for part, within_role in self.parts:
            for k, score in enumerate(part(frames, context)):
                full[k] += score
                roles[k] += 0.0 if within_role else score
        return full, roles


# The last LM scorer built, by its linearisation, resources, checkpoint manifests and experts' shares (a
# checkpoint trained again is loaded again): `stated_pmi` reads the sentence LM that `sentence_lm` loaded
# just before it, instead of loading the checkpoints twice (and, in a sum of both, in the same pass).
_LAST_LM: dict[tuple, SharedLM] = {}


def _lm_scorer(linearization: str) -> Callable[[MethodResources], Callable[..., list[float]]]:
    def build(res: MethodResources):
        from lmcr.lm.score import MixedLM

        shares = [(corpus, w) for corpus, w in lm_experts(res) if w > 0]
        key = (linearization, res, _lm_fingerprint(linearization)(res), tuple(shares))
        if key in _LAST_LM:
            return _LAST_LM[key]
        experts = [(w, load_lm(res, linearization, corpus)) for corpus, w in shares]
        lex = load_lexicon(learned=res.predicates)
        for _, expert in experts:
            expert.lex = lex  # the parser's predicates: the eleven and those learned beside the store
        _LAST_LM.clear()
        _LAST_LM[key] = SharedLM(experts[0][1] if len(experts) == 1 else MixedLM(experts))
        return _LAST_LM[key]

    return build


def _lm_fingerprint(linearization: str) -> Callable[[MethodResources], str]:
    def fingerprint(res: MethodResources) -> str:
        return ",".join(
            file_sha256(lm_version_dir(res, linearization, corpus) / "manifest.json") for corpus, _ in lm_experts(res)
        )

    return fingerprint


# The last frame-count model built (with whether it has the pairs), by the counts it was made of: the
# default method's `verb_fillers` reads the model `frame_counts` built just before it, instead of summing
# the same fillers again (a second of every start on the full store).
_LAST_MODEL: dict[tuple, tuple] = {}


def _frame_count_model(res: MethodResources, method: str, pairs: bool = True):
    """The store's frame counts for `method`, each learned verb with its class of motion (its pairs back
    off to its class's; `verb_fillers` sets it against its class); `pairs`: as `FrameCountScorer.from_store`."""
    from lmcr.scorers.frame_counts import FrameCountScorer

    db = store_path(res, method)
    # named by the frames' content, the mixture, the setting and the learned table (its classes too)
    cache = count_cache(res, "frame-counts", "frame", f"-{_learned_table_digest(res)}").with_suffix("")
    key = (cache, res.sql_dir)
    found = _LAST_MODEL.get(key)
    if found is not None and (found[1] or not pairs):
        return found[0]
    classes = load_lexicon(learned=res.predicates).motion_classes
    model = FrameCountScorer.from_store(
        db, res.sql_dir, res.corpus, mixture=res.mixture, classes=classes, pairs=pairs, cache=cache
    )
    _LAST_MODEL.clear()
    _LAST_MODEL[key] = (model, pairs)
    return model


def _frame_counts(res: MethodResources) -> Scorer:
    return _frame_count_model(res, "frame_counts").score_frames


def _verb_fillers(res: MethodResources) -> Scorer:
    counts = _frame_count_model(res, "verb_fillers", pairs=False)
    return lambda frames: [counts.verb_preference(frame) for frame in frames]


def _frame_counts_fingerprint(res: MethodResources) -> str:
    from lmcr.scorers.frame_counts import ALPHA, BACKOFF

    return f"{_frame_corpus_hash(res)}*{ALPHA:g}/{BACKOFF}/{_learned_table_digest(res)}"


def _learned_table_digest(res: MethodResources) -> str:
    """The content hash of the learned predicate table: its slots decide what the frame counts count (the
    store's robot_fillers view), its classes of motion what a learned verb's pairs back off to; both can
    change while the frames do not (a table learned again with other settings)."""
    table = learned_table_file(res.predicates)
    return file_sha256(table)[:12] if table is not None else "none"


def _similar_verbs(res: MethodResources) -> Scorer:
    from lmcr.scorers.similar_verbs import MIN_PAIRS, NEIGHBOURS, SimilarVerbs

    db = store_path(res, "similar_verbs")
    cache = count_cache(res, "similar-verbs", "frame", f"-{NEIGHBOURS}-{MIN_PAIRS}")
    # the eleven's tables: learned predicates are scored by their own counts (`SimilarVerbs.score_frames`)
    return SimilarVerbs.cached(
        db, res.sql_dir, load_lexicon(learned=False), res.corpus, res.mixture, cache
    ).score_frames


def _similar_verbs_fingerprint(res: MethodResources) -> str:
    from lmcr.scorers.similar_verbs import MIN_PAIRS, NEIGHBOURS, WEIGHT

    return f"{_frame_corpus_hash(res)}*{WEIGHT:g}/{NEIGHBOURS}/{MIN_PAIRS}"


def _frame_corpus_hash(res: MethodResources) -> str:
    return store_corpus_hash(res.db, "frame")


def _rarity(res: MethodResources) -> Scorer:
    from lmcr.scorers.ngram_index import NgramIndex
    from lmcr.scorers.rarity import PhraseCounts

    db = store_path(res, "rarity", "sentences")

    @functools.cache
    def index() -> NgramIndex:  # named by the corpus content, read (or built) at the first new label only
        return NgramIndex.cached(
            db, res.sql_dir, superseding(cache_dir(res) / f"ngrams-{store_corpus_hash(db, 'sentence')[:12]}.npz")
        )

    counts = PhraseCounts(db, res.sql_dir, corpus_words(res), res.corpus, res.mixture, index)
    # the detector's objects up front (completion then never scans), cached by the corpus content
    counts.count_cached(load_lexicon().objects, count_cache(res, "phrases", "sentence"))
    return counts.rarity


def _rarity_fingerprint(res: MethodResources) -> str:
    from lmcr.scorers.rarity import WEIGHT

    return f"{store_corpus_hash(res.db, 'sentence')}*{WEIGHT:g}"


def _context_pmi(res: MethodResources) -> Scorer:
    from lmcr.scorers.context_pmi import ContextCooccurrence

    store_path(res, "context_pmi", "sentences")
    corpora = res.mixture.parts(res.corpus)
    cache = count_cache(res, "context-sentences", "sentence")

    @functools.cache
    def counts() -> ContextCooccurrence:  # counted (or read) at the first context: rated frames have none
        return ContextCooccurrence.cached(res.db, res.sql_dir, load_lexicon().objects, corpora, cache)

    weight = res.context_weight
    return lambda frames, context="": counts().score(frames, context, weight) if context else [0.0] * len(frames)


def _context_pmi_fingerprint(res: MethodResources) -> str:
    from lmcr.scorers.context_pmi import ESTIMATE, MIN_SENTENCES

    return f"{store_corpus_hash(res.db, 'sentence')}*{res.context_weight:g}/{MIN_SENTENCES}/sentences/{ESTIMATE}"


def _cooccur(res: MethodResources) -> Scorer:
    from lmcr.scorers.baselines.cooccur import CooccurrenceScorer
    from lmcr.scorers.baselines.terms import default_lemmatizer

    return CooccurrenceScorer(corpus_sentences(res), default_lemmatizer(res.spacy_model), robot_terms()).score_frames


def _word2vec(res: MethodResources) -> Scorer:
    from lmcr.scorers.baselines.vectors import VectorScorer, load_vectors

    return VectorScorer(load_vectors(word_vectors(res))).score_frames


def _conceptnet_edges(res: MethodResources, method: str = "conceptnet") -> Path:
    if res.conceptnet is None:
        raise MethodUnavailable(f"{method} needs an edge list or Numberbatch file (--conceptnet / $LMCR_CONCEPTNET)")
    return res.conceptnet


def _conceptnet(res: MethodResources) -> Scorer:
    from lmcr.scorers.baselines.conceptnet import ConceptNetScorer

    return ConceptNetScorer.from_path(_conceptnet_edges(res)).score_frames


def _conceptnet_retrofit(res: MethodResources) -> Scorer:
    from lmcr.scorers.baselines.conceptnet import read_edges, relatedness
    from lmcr.scorers.baselines.retrofit import retrofit
    from lmcr.scorers.baselines.vectors import VectorScorer, load_vectors

    retrofitted = VectorScorer(retrofit(read_edges(_conceptnet_edges(res)), load_vectors(word_vectors(res))))
    return relatedness(retrofitted.vector)


def _commonsense(res: MethodResources) -> Scorer:
    import sys

    from lmcr.scorers.commonsense import WEIGHT, commonsense_scorer, trained_model

    progress = lambda line: print(line, file=sys.stderr)  # noqa: E731 - training shows its epochs
    model = trained_model(_conceptnet_edges(res, "commonsense"), word_vectors(res), cache_dir(res), progress)
    return commonsense_scorer(model, WEIGHT, load_lexicon(learned=res.predicates).learned)


def _commonsense_fingerprint(res: MethodResources) -> str:
    from lmcr.scorers.commonsense import WEIGHT, model_digest

    return f"{model_digest(_conceptnet_edges(res, 'commonsense'), word_vectors(res))}*{WEIGHT:g}"


def _stated_pmi(res: MethodResources) -> Scorer:
    from lmcr.scorers.stated_pmi import stated_pmi_scorer

    return stated_pmi_scorer(_lm_scorer("sentence")(res), load_lexicon(learned=res.predicates).learned)


def _stated_pmi_fingerprint(res: MethodResources) -> str:
    from lmcr.scorers.stated_pmi import WEIGHT

    return f"{_lm_fingerprint('sentence')(res)}*{WEIGHT:g}"


def _random(res: MethodResources) -> Scorer:
    rng = random.Random(res.seed)
    return lambda frames: [rng.random() for _ in frames]


# The methods, in the order reports list them: a new method is one entry here. The sentence LM reads
# the instruction's context after the filled frame, as one more stretch of text; the frame LM learned
# bare frames, where a purpose clause never occurs.
SCORERS: dict[str, ScorerSpec] = {
    **{
        method: ScorerSpec(_lm_scorer(lin), _lm_fingerprint(lin), reads_context=lin == "sentence")
        for method, lin in LM_METHODS.items()
    },
    "frame_counts": ScorerSpec(_frame_counts, _frame_counts_fingerprint),
    "similar_verbs": ScorerSpec(_similar_verbs, _similar_verbs_fingerprint),
    "cooccur": ScorerSpec(_cooccur),
    "word2vec": ScorerSpec(_word2vec),
    "conceptnet": ScorerSpec(_conceptnet),
    "conceptnet_retrofit": ScorerSpec(_conceptnet_retrofit),
    "random": ScorerSpec(_random),
    "commonsense": ScorerSpec(_commonsense, _commonsense_fingerprint, within_role=True),  # a term, as rarity
    # a term, as rarity; it orders the fillers of one role only
    "verb_fillers": ScorerSpec(_verb_fillers, _frame_counts_fingerprint, within_role=True),
    # a term, as rarity; it orders the fillers of one role only
    "stated_pmi": ScorerSpec(_stated_pmi, _stated_pmi_fingerprint, reads_context=True, within_role=True),
    "rarity": ScorerSpec(_rarity, _rarity_fingerprint),  # a term of sums ('a+rarity'), not a method alone
    "context_pmi": ScorerSpec(_context_pmi, _context_pmi_fingerprint, reads_context=True),  # a term, as rarity
}


METHODS = tuple(SCORERS)
# added to methods ('a+rarity'), not compared as methods of their own
TERMS = ("rarity", "context_pmi", "commonsense", "verb_fillers", "stated_pmi")
# what `lmcr evaluate` compares by default: the methods, and the default with and without its terms and
# its third expert
EVALUATED = (
    *METHODS[:4],
    "sentence_lm+frame_counts",
    COMPLETION_METHOD.replace("+similar_verbs", ""),
    COMPLETION_METHOD,
    *(m for m in METHODS[4:] if m not in TERMS),
)


def make_scorer(method: str, res: MethodResources) -> Scorer:
    """The scorer of `method`; 'a+b' sums the scores of methods a and b (for log-probability methods,
    a product of experts)."""
    if "+" in method:
        names = method.split("+")
        return SummedScorer([(make_scorer(m, res), m in SCORERS and SCORERS[m].within_role) for m in names])
    if method not in SCORERS:
        raise MethodUnavailable(f"unknown method {method!r}; available: {', '.join(METHODS)}")
    spec = SCORERS[method]
    score = spec.build(res)
    if spec.reads_context:  # as built (a sum reads a rider's frames in its LM's pass: `SummedScorer`)
        return score
    return lambda frames, context="": score(frames)


def scorer_fingerprint(method: str, res: MethodResources) -> str | None:
    """What a completion calibration of `method` is valid for: each part's fingerprint (an LM's
    checkpoint manifest sha256, the frame corpus hash), joined; None when any part is not calibrated."""
    parts = [SCORERS[m].fingerprint(res) if m in SCORERS else None for m in method.split("+")]
    if None in parts:
        return None
    return "+".join(parts) + (f"@{res.mixture.label}" if res.mixed else "")


def is_method_name(column: str) -> bool:
    """Whether `column` is named like a method or a sum of methods: scores are written under such names."""
    return column in METHODS or "+" in column
