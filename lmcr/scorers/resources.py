"""What the scorers are built from (`MethodResources`) and what they read of the store: its path, words
per corpus, the corpus sentences as a stream, and the content hash of its sentences or frames."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from lmcr.checkout import SQL_DIR
from lmcr.errors import LMCRError
from lmcr.lexicon import load_lexicon
from lmcr.scorers.context_pmi import WEIGHT as CONTEXT_WEIGHT
from lmcr.scorers.mixture import Mixture
from lmcr.srl.spacy_model import SPACY_MODEL
from lmcr.store import read_connection


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
    mixture: Mixture = Mixture()  # per-corpus weights of the `all` setting (lmcr/scorers/mixture.py)
    context_weight: float = CONTEXT_WEIGHT  # the context term's, chosen with the mixture (scorers/context_pmi.py)
    # the learned predicate table the parser reads (the LMs score its predicates with its templates);
    # True: the workspace's, from the environment
    predicates: Path | bool = True

    @property
    def mixed(self) -> bool:
        """True when the scorers pool the corpora with weights other than 1."""
        return self.corpus == "all" and not self.mixture.plain


class MethodUnavailable(LMCRError, ValueError):
    """A method the user asked for that cannot be built (no checkpoint or store, a bad vector or edge file, ...)."""


def store_path(res: MethodResources, method: str, what: str = "frames") -> Path:
    """The store a count-based scorer reads, or why there is none."""
    if res.db is None or not Path(res.db).exists():
        raise MethodUnavailable(f"{method} needs the store's {what}: no store at {res.db}")
    return Path(res.db)


def store_corpus_hash(db: Path, linearization: str) -> str:
    """The content hash of the store's sentences ('sentence') or frames ('frame')."""
    from lmcr.lm.corpus import corpus_hash

    con = read_connection(db)
    try:
        return corpus_hash(con, linearization)
    finally:
        con.close()


def robot_terms() -> set[str]:
    """The hand-written predicates and the detector's object vocabulary: indexed up front by count-based
    scorers (other terms are counted when first asked for)."""
    lex = load_lexicon(learned=False)
    return set(lex.predicates) | set(lex.objects)


def corpus_words(res: MethodResources) -> dict[str, int]:
    """Words per source corpus in the store: what a mixture's shares and the rarity term's frequencies are
    taken of."""
    con = read_connection(store_path(res, "a corpus mixture", "corpus sizes"))
    try:
        return dict(con.execute("select corpus, sum(n_words)::bigint from sentences group by corpus").fetchall())
    finally:
        con.close()


def corpus_sentences(res: MethodResources) -> Callable[[], Iterator[str]]:
    """A re-iterable source of the setting's corpus sentences (all kinds), streamed from the store."""
    store_path(res, "this method", "ingested sentences")
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
