"""What scorers derive from the store and keep on disk: count caches named by the setting, the mixture
and the corpus content hash (so that changed inputs are counted afresh), and the word vectors of the
baselines (a given file, the installed GloVe, or word2vec trained on the corpus and cached). A cache
named afresh removes those it supersedes (`superseding`)."""

from __future__ import annotations

import re
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
    return superseding(cache_dir(res) / f"{kind}-{res.corpus}-{res.mixture.label}-{digest}{suffix}.json")


CONTENT_HASH = re.compile(r"(?<![0-9a-f])[0-9a-f]{12}(?![0-9a-f])")  # how a cache's name holds a content hash


def superseding(path: Path) -> Path:
    """`path`, a cache named by content hashes (12 hex digits each), once the caches it supersedes are
    removed: the files of its folder named as it is (less its extension, with any ending) but for those
    hashes. They were derived from a corpus, frame build or learned table the store no longer holds, of the
    same kind, setting and mixture, and nothing names them again: each scheduled retrain on new text would
    otherwise leave about 100 MB behind on the full corpora (n-grams 77 MB, counts 3 MB a mixture). A file
    that cannot be removed stays; it only takes room."""
    stem = path.name[: -len(path.suffix)] if path.suffix else path.name
    parts = CONTENT_HASH.split(stem)
    if len(parts) == 1 or not path.parent.is_dir():
        return path
    same_but_hashes = re.compile("[0-9a-f]{12}".join(map(re.escape, parts)) + r"(?![0-9a-f]).*", re.DOTALL)
    try:
        names = [other for other in path.parent.iterdir() if same_but_hashes.fullmatch(other.name)]
    except OSError:  # a folder that cannot be listed: what it holds only takes room
        return path
    for other in names:
        if not other.name.startswith(stem) and other.is_file():
            try:
                other.unlink()
            except OSError:
                pass
    return path


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
    path = superseding(cache_dir(res) / f"word2vec-{res.corpus}-{digest}.bin")
    if not path.exists():
        train_word2vec(corpus_sentences(res), path, seed=res.seed + 1)
    return path
