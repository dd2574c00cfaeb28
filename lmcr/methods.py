"""Frame scorers behind one interface: complete frames in, one float each out (higher = more plausible)."""

from __future__ import annotations

import csv
import functools
import random
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from lmcr.config import SQL_DIR
from lmcr.context_pmi import WEIGHT as CONTEXT_WEIGHT
from lmcr.files import atomic_path, file_sha256
from lmcr.frame import Frame
from lmcr.jsonl import InputError, read_lines
from lmcr.lexicon import load_lexicon
from lmcr.mixture import Mixture
from lmcr.setting import LM_METHODS, Setting
from lmcr.store import read_connection
from lmcr.workspace import SPACY_MODEL

# The scorers' own modules (torch, gensim, scipy) are imported where a scorer is built, so that the
# command line and light commands start fast (`bench/bench_cli.py`).

# What completes instructions by default: the sentence LM times the frame counts times what the verbs
# most like the predicate do with the same fillers (lmcr/similar_verbs.py), less how common the fillers
# are anyway (lmcr/rarity.py), plus what the instruction's purpose says of each filler
# (lmcr/context_pmi.py; 0 without one, so on the rated frames). The household weight under which it runs is
# chosen on both dev sets (lmcr/evaluate/mixture.py); its figures are in the README.
COMPLETION_METHOD = "sentence_lm+frame_counts+similar_verbs+rarity+context_pmi"
REQUIRED_COLUMNS = ("verb", "role1", "arg1", "role2", "arg2")


@dataclass(frozen=True)
class MethodResources:
    """What the scorers are built from: checkpoints for the LMs, the store's sentences for co-occurrence
    and word2vec training, a vector file (else word2vec trained on the corpus, cached under
    `cache_dir`), and a ConceptNet edge list or Numberbatch file."""

    checkpoints: Path
    corpus: str = "all"
    db: Path | None = None
    sql_dir: Path = SQL_DIR
    vectors: Path | None = None
    conceptnet: Path | None = None
    spacy_model: str = SPACY_MODEL
    cache_dir: Path | None = None
    seed: int = 0
    mixture: Mixture = Mixture()  # per-corpus weights of the `all` setting (lmcr/mixture.py)
    context_weight: float = CONTEXT_WEIGHT  # the context term's, chosen with the mixture (lmcr/context_pmi.py)

    @property
    def mixed(self) -> bool:
        """True when the scorers pool the corpora with weights other than 1."""
        return self.corpus == "all" and not self.mixture.plain


@dataclass(frozen=True)
class FrameRow:
    line: int
    frame: Frame
    raw: dict


def lm_checkpoint_dir(checkpoints: Path, linearization: str, corpus: str) -> Path:
    """The setting folder `<checkpoints>/<linearization>-<corpus>`, or `checkpoints` itself when it is one
    checkpoint (a setting or version folder) of that linearisation."""
    setting = checkpoints / Setting(linearization, corpus).name
    if setting.exists():
        return setting
    if (checkpoints / "LATEST").exists() or (checkpoints / "manifest.json").exists():
        return checkpoints
    from lmcr.lm.checkpoint import CheckpointError

    raise CheckpointError(f"no {linearization} checkpoint for corpus {corpus!r} under {checkpoints} "
                               f"(run `lmcr train --linearization {linearization} --corpus {corpus}`)")


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


def _load_lm(res: MethodResources, linearization: str, corpus: str):
    from lmcr.lm import checkpoint as ckpt
    from lmcr.lm.score import LMScorer

    loaded = ckpt.load(lm_checkpoint_dir(res.checkpoints, linearization, corpus))
    if loaded.linearization != linearization:
        raise ckpt.CheckpointError(f"{loaded.path} is a {loaded.linearization} model, not {linearization}")
    return LMScorer(loaded)


def lm_experts(res: MethodResources) -> list[tuple[str, float]]:
    """(corpus, interpolation weight) of the LMs an LM scorer mixes: the setting's own alone, or under a
    mixture the all-corpora LM and each weighted corpus's LM at its share of the weighted words."""
    if not res.mixed:
        return [(res.corpus, 1.0)]
    shares = res.mixture.shares(corpus_words(res))
    return [("all", 1.0 - sum(shares.values())), *shares.items()]


def lm_settings(method: str, res: MethodResources) -> list[Setting]:
    """The LM checkpoints the scorer of `method` ('a+b' sums) may load under `res`: each LM part's
    linearisation in the setting's corpus, or, under a mixture, in `all` and in each weighted corpus (the
    experts of `lm_experts`, counted before a corpus without words drops out)."""
    corpora = ["all", *(c for c, _ in res.mixture.weights)] if res.mixed else [res.corpus]
    return [Setting(LM_METHODS[part], corpus) for part in method.split("+") if part in LM_METHODS
            for corpus in corpora]


def _lm_scorer(linearization: str) -> Callable[[MethodResources], Callable[..., list[float]]]:
    def build(res: MethodResources):
        from lmcr.lm.score import MixedLM

        experts = [(w, _load_lm(res, linearization, corpus)) for corpus, w in lm_experts(res) if w > 0]
        return experts[0][1].score_frames if len(experts) == 1 else MixedLM(experts).score_frames
    return build


def lm_version_dir(res: MethodResources, linearization: str, corpus: str | None = None) -> Path:
    """The checkpoint version folder an LM scorer of `linearization` loads (a setting's LATEST resolved)."""
    from lmcr.lm import checkpoint as ckpt

    return ckpt.resolve(lm_checkpoint_dir(res.checkpoints, linearization, corpus or res.corpus))


def _lm_fingerprint(linearization: str) -> Callable[[MethodResources], str]:
    def fingerprint(res: MethodResources) -> str:
        return ",".join(file_sha256(lm_version_dir(res, linearization, corpus) / "manifest.json")
                        for corpus, _ in lm_experts(res))
    return fingerprint


def _store(res: MethodResources, method: str, what: str = "frames") -> Path:
    """The store a count-based scorer reads, or why there is none."""
    if res.db is None or not Path(res.db).exists():
        raise ValueError(f"{method} needs the store's {what}: no store at {res.db}")
    return Path(res.db)


def _frame_counts(res: MethodResources) -> Scorer:
    from lmcr.counts import FrameCountScorer

    return FrameCountScorer.from_store(_store(res, "frame_counts"), res.sql_dir, res.corpus, mixture=res.mixture).score_frames


def _similar_verbs(res: MethodResources) -> Scorer:
    from lmcr.similar_verbs import MIN_PAIRS, NEIGHBOURS, SimilarVerbs

    db = _store(res, "similar_verbs")
    cache = _count_cache(res, "similar-verbs", "frame", f"-{NEIGHBOURS}-{MIN_PAIRS}")
    return SimilarVerbs.cached(db, res.sql_dir, load_lexicon(), res.corpus, res.mixture, cache).score_frames


def _similar_verbs_fingerprint(res: MethodResources) -> str:
    from lmcr.similar_verbs import MIN_PAIRS, NEIGHBOURS, WEIGHT

    return f"{_frame_corpus_hash(res)}*{WEIGHT:g}/{NEIGHBOURS}/{MIN_PAIRS}"


def store_corpus_hash(db: Path, linearization: str) -> str:
    """The content hash of the store's sentences ('sentence') or frames ('frame')."""
    from lmcr.lm.corpus import corpus_hash

    con = read_connection(db)
    try:
        return corpus_hash(con, linearization)
    finally:
        con.close()


def _frame_corpus_hash(res: MethodResources) -> str:
    return store_corpus_hash(res.db, "frame")


def _rarity(res: MethodResources) -> Scorer:
    from lmcr.rarity import PhraseCounts

    counts = PhraseCounts(_store(res, "rarity", "sentences"), res.sql_dir, corpus_words(res), res.corpus, res.mixture)
    # the detector's objects up front (completion then never scans), cached by the corpus content
    counts.count_cached(load_lexicon().objects, _count_cache(res, "phrases", "sentence"))
    return counts.rarity


def _rarity_fingerprint(res: MethodResources) -> str:
    from lmcr.rarity import WEIGHT

    return f"{store_corpus_hash(res.db, 'sentence')}*{WEIGHT:g}"


def _context_pmi(res: MethodResources) -> Scorer:
    from lmcr.context_pmi import ContextCooccurrence

    _store(res, "context_pmi", "sentences")
    corpora = res.mixture.parts(res.corpus)
    cache = _count_cache(res, "context-sentences", "sentence")

    @functools.cache
    def counts() -> ContextCooccurrence:  # counted (or read) at the first context: rated frames have none
        return ContextCooccurrence.cached(res.db, res.sql_dir, load_lexicon().objects, corpora, cache)

    weight = res.context_weight
    return lambda frames, context="": counts().score(frames, context, weight) if context else [0.0] * len(frames)


def _context_pmi_fingerprint(res: MethodResources) -> str:
    from lmcr.context_pmi import MIN_SENTENCES

    return f"{store_corpus_hash(res.db, 'sentence')}*{res.context_weight:g}/{MIN_SENTENCES}/sentences"


def _cooccur(res: MethodResources) -> Scorer:
    from lmcr.baselines.cooccur import CooccurrenceScorer
    from lmcr.baselines.terms import default_lemmatizer

    return CooccurrenceScorer(corpus_sentences(res), default_lemmatizer(res.spacy_model), robot_terms()).score_frames


CORPUS_VECTORS = Path("corpus")  # `--vectors corpus`: word2vec trained on the setting's sentences


def word_vectors(res: MethodResources) -> Path:
    """The word vectors of the baselines: the given file, else the full GloVe of the `vectors` extra, else
    (or when asked for with 'corpus') word2vec trained on the corpus."""
    from lmcr.baselines.vectors import installed_glove

    if res.vectors == CORPUS_VECTORS:
        return corpus_word2vec(res)
    return res.vectors or installed_glove() or corpus_word2vec(res)


def _word2vec(res: MethodResources) -> Scorer:
    from lmcr.baselines.vectors import VectorScorer, load_vectors

    return VectorScorer(load_vectors(word_vectors(res))).score_frames


def _conceptnet_edges(res: MethodResources) -> Path:
    if res.conceptnet is None:
        raise ValueError("conceptnet needs an edge list or Numberbatch file (--conceptnet / $LMCR_CONCEPTNET)")
    return res.conceptnet


def _conceptnet(res: MethodResources) -> Scorer:
    from lmcr.baselines.conceptnet import ConceptNetScorer

    return ConceptNetScorer.from_path(_conceptnet_edges(res)).score_frames


def _conceptnet_retrofit(res: MethodResources) -> Scorer:
    from lmcr.baselines.conceptnet import read_edges, relatedness
    from lmcr.baselines.retrofit import retrofit
    from lmcr.baselines.vectors import VectorScorer, load_vectors

    retrofitted = VectorScorer(retrofit(read_edges(_conceptnet_edges(res)), load_vectors(word_vectors(res))))
    return relatedness(retrofitted.vector)


def _random(res: MethodResources) -> Scorer:
    rng = random.Random(res.seed)
    return lambda frames: [rng.random() for _ in frames]


# The methods, in the order reports list them: a new method is one entry here. The sentence LM reads
# the instruction's context after the filled frame, as one more stretch of text; the frame LM learned
# bare frames, where a purpose clause never occurs.
SCORERS: dict[str, ScorerSpec] = {
    **{method: ScorerSpec(_lm_scorer(lin), _lm_fingerprint(lin), reads_context=lin == "sentence")
       for method, lin in LM_METHODS.items()},
    "frame_counts": ScorerSpec(_frame_counts, _frame_corpus_hash),
    "similar_verbs": ScorerSpec(_similar_verbs, _similar_verbs_fingerprint),
    "cooccur": ScorerSpec(_cooccur),
    "word2vec": ScorerSpec(_word2vec),
    "conceptnet": ScorerSpec(_conceptnet),
    "conceptnet_retrofit": ScorerSpec(_conceptnet_retrofit),
    "random": ScorerSpec(_random),
    "rarity": ScorerSpec(_rarity, _rarity_fingerprint),  # a term of sums ('a+rarity'), not a method alone
    "context_pmi": ScorerSpec(_context_pmi, _context_pmi_fingerprint, reads_context=True),  # a term, as rarity
}


METHODS = tuple(SCORERS)
TERMS = ("rarity", "context_pmi")  # added to methods ('a+rarity'), not compared as methods of their own
# what `lmcr evaluate` compares by default: the methods, and the default with and without its terms and
# its third expert
EVALUATED = (*METHODS[:4], "sentence_lm+frame_counts", COMPLETION_METHOD.replace("+similar_verbs", ""),
             COMPLETION_METHOD, *(m for m in METHODS[4:] if m not in TERMS))


def make_scorer(method: str, res: MethodResources) -> Scorer:
    """The scorer of `method`; 'a+b' sums the scores of methods a and b (for log-probability methods,
    a product of experts)."""
    if "+" in method:
        parts = [make_scorer(m, res) for m in method.split("+")]
        return lambda frames, context="": [sum(s) for s in zip(*(part(frames, context) for part in parts))]
    if method not in SCORERS:
        raise ValueError(f"unknown method {method!r}; available: {', '.join(METHODS)}")
    spec = SCORERS[method]
    score = spec.build(res)
    if spec.reads_context:
        return lambda frames, context="": score(frames, context=context)
    return lambda frames, context="": score(frames)


def scorer_fingerprint(method: str, res: MethodResources) -> str | None:
    """What a completion calibration of `method` is valid for: each part's fingerprint (an LM's
    checkpoint manifest sha256, the frame corpus hash), joined; None when any part is not calibrated."""
    parts = [SCORERS[m].fingerprint(res) if m in SCORERS else None for m in method.split("+")]
    if None in parts:
        return None
    return "+".join(parts) + (f"@{res.mixture.label}" if res.mixed else "")


def robot_terms() -> set[str]:
    """The predicates and the detector's object vocabulary: indexed up front by count-based scorers."""
    lex = load_lexicon()
    return set(lex.predicates) | set(lex.objects)


def corpus_words(res: MethodResources) -> dict[str, int]:
    """Words per source corpus in the store: what a mixture's shares and the rarity term's frequencies are
    taken of."""
    con = read_connection(_store(res, "a corpus mixture", "corpus sizes"))
    try:
        return dict(con.execute("select corpus, sum(n_words)::bigint from sentences group by corpus").fetchall())
    finally:
        con.close()


def corpus_sentences(res: MethodResources) -> Callable[[], Iterator[str]]:
    """A re-iterable source of the setting's corpus sentences (all kinds), streamed from the store."""
    _store(res, "this method", "ingested sentences")
    where = "" if res.corpus == "all" else "where corpus = ?"

    def stream() -> Iterator[str]:
        con = read_connection(res.db)
        try:
            cursor = con.execute(f"select text from sentences {where}", [] if res.corpus == "all" else [res.corpus])
            while batch := cursor.fetchmany(50_000):
                yield from (text for (text,) in batch)
        finally:
            con.close()

    return stream


def _cache_dir(res: MethodResources) -> Path:
    """Where scorers keep what they derive from the store (word2vec, phrase counts)."""
    return Path(res.cache_dir or Path(res.db).parent / "baselines")


def _count_cache(res: MethodResources, kind: str, linearization: str, suffix: str = "") -> Path:
    """The cache file of a count-based scorer's counts: named by the setting, the mixture and the content
    hash of the store's sentences or frames (`linearization`), so that changed inputs are counted afresh."""
    digest = store_corpus_hash(res.db, linearization)[:12]
    return _cache_dir(res) / f"{kind}-{res.corpus}-{res.mixture.label}-{digest}{suffix}.json"


def corpus_word2vec(res: MethodResources) -> Path:
    """word2vec vectors trained on the setting's sentences, cached by the corpus content hash."""
    from lmcr.baselines.vectors import train_word2vec

    digest = store_corpus_hash(res.db, "sentence")[:12]
    path = _cache_dir(res) / f"word2vec-{res.corpus}-{digest}.bin"
    if not path.exists():
        train_word2vec(corpus_sentences(res), path, seed=res.seed + 1)
    return path


def read_frames_csv(path: Path) -> tuple[list[str], list[FrameRow]]:
    """Rows of a frames CSV (`verb, role1, arg1, role2, arg2`, other columns kept), validated against the
    lexicon: a bad row fails with file, line and reason."""
    lex = load_lexicon()
    reader = csv.DictReader(read_lines(path))
    try:
        columns = reader.fieldnames or []
        missing = [c for c in REQUIRED_COLUMNS if c not in columns]
        if missing:
            raise InputError(f"{path}:1: missing columns {missing}")
        taken = [c for c in columns if c in METHODS or "+" in c]
        if taken:  # the scores would silently replace them
            raise InputError(f"{path}:1: column {taken[0]!r} is named like a method; rename it")
        rows = [FrameRow(reader.line_num, _frame_of(row, path, reader.line_num, lex, len(columns)), row)
                for row in reader]
    except csv.Error as exc:
        raise InputError(f"{path}:{reader.line_num}: not CSV: {exc}") from exc
    return columns, rows


def _frame_of(row: dict, path: Path, line: int, lex, n_columns: int) -> Frame:
    """The frame of one frames-CSV row, validated against the lexicon."""
    if None in row:
        raise InputError(f"{path}:{line}: {n_columns + len(row[None])} fields, the header has {n_columns}")
    verb = (row["verb"] or "").strip().lower()
    spec = lex.predicates.get(verb)
    if spec is None:
        raise InputError(f"{path}:{line}: unknown verb {row['verb']!r} (one of {', '.join(sorted(lex.predicates))})")
    roles = {(row["role1"] or "").strip(): (row["arg1"] or "").strip().lower(),
             (row["role2"] or "").strip(): (row["arg2"] or "").strip().lower()}
    if set(roles) != set(spec.roles):
        raise InputError(f"{path}:{line}: roles {sorted(roles)} are not {verb}'s {list(spec.roles)}")
    if not all(roles.values()):
        raise InputError(f"{path}:{line}: empty argument")
    return Frame.of(verb, roles)


def write_scores_csv(path: Path, columns: list[str], rows: list[FrameRow], scores: dict[str, list[float]]) -> None:
    """Input columns plus one column per method, written under a temporary name and renamed."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as out:
        writer = csv.DictWriter(out, fieldnames=columns + [m for m in scores if m not in columns])
        writer.writeheader()
        for k, row in enumerate(rows):
            writer.writerow({**row.raw, **{m: f"{values[k]:.6f}" for m, values in scores.items()}})
