"""What scorers derive from the store and keep on disk: count caches named by the setting, the mixture
and the corpus content hash (so that changed inputs are counted afresh), and the word vectors of the
baselines (a given file, the installed GloVe, or word2vec trained on the corpus and cached)."""

from __future__ import annotations

from pathlib import Path

from lmcr.scorers.resources import MethodResources, corpus_sentences, store_corpus_hash

CORPUS_VECTORS = Path("corpus")  # `--vectors corpus`: word2vec trained on the setting's sentences


def cache_dir(res: MethodResources) -> Path:
    """Where scorers keep what they derive from the store (word2vec, phrase counts)."""
    return Path(res.cache_dir or Path(res.db).parent / "baselines")


def count_cache(res: MethodResources, kind: str, linearization: str, suffix: str = "") -> Path:
    """The cache file of a count-based scorer's counts: named by the setting, the mixture and the content
    hash of the store's sentences or frames (`linearization`), so that changed inputs are counted afresh."""
    digest = store_corpus_hash(res.db, linearization)[:12]
    return cache_dir(res) / f"{kind}-{res.corpus}-{res.mixture.label}-{digest}{suffix}.json"


def word_vectors(res: MethodResources) -> Path:
    """The word vectors of the baselines: the given file, else the full GloVe of the `vectors` extra, else
    (or when asked for with 'corpus') word2vec trained on the corpus."""
    from lmcr.scorers.baselines.vectors import installed_glove

    if res.vectors == CORPUS_VECTORS:
        return corpus_word2vec(res)
    return res.vectors or installed_glove() or corpus_word2vec(res)


def corpus_word2vec(res: MethodResources) -> Path:
    """word2vec vectors trained on the setting's sentences, cached by the corpus content hash."""
    from lmcr.scorers.baselines.vectors import train_word2vec

    digest = store_corpus_hash(res.db, "sentence")[:12]
    path = cache_dir(res) / f"word2vec-{res.corpus}-{digest}.bin"
    if not path.exists():
        train_word2vec(corpus_sentences(res), path, seed=res.seed + 1)
    return path
