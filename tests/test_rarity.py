"""The rarity term: phrase counts from a tiny store's sentences, by hand, and what it does to a ranking; the
word n-gram index that counts the phrases met while scoring."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from lmcr.frame import Frame
from lmcr.scorers import ngram_index
from lmcr.scorers.mixture import Mixture
from lmcr.scorers.ngram_index import NgramIndex
from lmcr.scorers.rarity import WEIGHT, PhraseCounts, phrase_pattern
from lmcr.scorers.registry import make_scorer, scorer_fingerprint
from lmcr.scorers.resources import MethodResources, corpus_words
from lmcr.store import connect
from lmcr.workspace import Workspace

SENTENCES = [  # (corpus, text)
    ("recipes", "Dump the pan into the bowl."),
    ("recipes", "Wash the pans and the pan lids."),
    ("recipes", "Dump the cheese into a bowl; use a cutting board."),
    ("household", "put pan on cutting boards"),
    ("household", "rinse panini pan"),  # 'panini' is not 'pan'
]


@pytest.fixture
def store(tmp_path):
    db = tmp_path / "lmcr.duckdb"
    sql_dir = Workspace.from_env().sql_dir
    con = connect(db, sql_dir)
    con.executemany(
        "insert into sentences values (?, 's', ?, ?, 'instruction', ?, ?, 'f', 0, null, null)",
        [(corpus, f"d{i}", i, text, len(text.split())) for i, (corpus, text) in enumerate(SENTENCES)],
    )
    con.close()
    return db, sql_dir, corpus_words(MethodResources(checkpoints=tmp_path, db=db))


def test_phrases_are_counted_whole_with_plurals_and_smoothed(store):
    counts = PhraseCounts(*store)
    counts.count(["pan", "cutting board", "cheese", "board", "scissors"])
    # 'pans' counts as pan, 'panini' does not; 'cutting boards' is the phrase, so not a bare 'board'
    assert counts.counts == {"pan": 5, "cutting board": 2, "cheese": 1, "board": 0, "scissors": 0}
    words = sum(len(text.split()) for _, text in SENTENCES)
    assert counts.words == words
    assert counts.log_p("pan") == pytest.approx(math.log(6 / (words + 1)))
    assert counts.log_p("Scissors") == pytest.approx(math.log(1 / (words + 1)))  # unseen: as rare as one in N + 1


def test_longest_phrase_first():
    assert phrase_pattern(["ab", "pepper", "black pepper", "a.b"]) == r"black\ pepper|pepper|a\.b|ab"


def test_a_corpus_and_a_mixture_weigh_the_counts(store):
    assert PhraseCounts(*store, corpus="household").counts == {}
    household = PhraseCounts(*store, corpus="household")
    household.count(["pan"])
    assert household.counts == {"pan": 2} and household.words == 8
    mixed = PhraseCounts(*store, mixture=Mixture.of({"household": 3}))
    mixed.count(["pan", "cheese"])
    assert mixed.counts == {"pan": 3 + 3 * 2, "cheese": 1}
    assert mixed.words == sum(len(t.split()) * (3 if c == "household" else 1) for c, t in SENTENCES)


def test_rarity_lifts_the_rarer_filler_by_its_log_frequency(store):
    counts = PhraseCounts(*store)
    frames = [Frame.of("dump", {"Theme": theme, "Destination": "bowl"}) for theme in ("pan", "cheese")]
    pan, cheese = counts.rarity(frames)
    assert cheese > pan
    assert cheese - pan == pytest.approx(WEIGHT * (counts.log_p("pan") - counts.log_p("cheese")))
    assert cheese == pytest.approx(-WEIGHT * (counts.log_p("cheese") + counts.log_p("bowl")))


def test_rarity_is_a_term_of_sums_with_a_fingerprint(store):
    db, sql_dir, _ = store
    res = MethodResources(checkpoints=db.parent, db=db, sql_dir=sql_dir)
    frames = [Frame.of("dump", {"Theme": theme, "Destination": "bowl"}) for theme in ("pan", "cheese")]
    alone = make_scorer("rarity", res)(frames)
    assert make_scorer("random+rarity", res)(frames) == pytest.approx(
        [a + b for a, b in zip(make_scorer("random", res)(frames), alone)]
    )
    assert scorer_fingerprint("rarity", res).endswith(f"*{WEIGHT:g}")
    with pytest.raises(ValueError, match="rarity needs the store's sentences"):
        make_scorer("rarity", MethodResources(checkpoints=db.parent, db=db.parent / "none.duckdb", sql_dir=sql_dir))


def test_counts_are_cached_by_the_caller_named_file_and_a_bad_cache_is_recounted(store, tmp_path):
    cache = tmp_path / "cache" / "phrases.json"
    first = PhraseCounts(*store)
    first.count_cached(["pan", "cheese"], cache)
    assert json.loads(cache.read_text())["counts"] == {"cheese": 1, "pan": 5}
    # a second build reads the file instead of scanning: a count put there by hand shows it
    cache.write_text(json.dumps({"words": first.words, "counts": {"pan": 7, "cheese": 1}}))
    again = PhraseCounts(*store)
    again.count_cached(["pan"], cache)
    assert again.counts["pan"] == 7
    for bad in (
        "{not json",
        json.dumps({"words": first.words + 1, "counts": {"pan": 7}}),
        "[1, 2]",
        json.dumps({"words": first.words, "counts": {"pan": 7}}),
    ):  # the last lacks cheese
        cache.write_text(bad)
        fresh = PhraseCounts(*store)
        fresh.count_cached(["pan", "cheese"], cache)
        assert fresh.counts == {"pan": 5, "cheese": 1}
        assert json.loads(cache.read_text())["counts"] == {"pan": 5, "cheese": 1}


def test_the_ngram_index_counts_phrases_as_the_scan_counts_one_alone(store):
    db, sql_dir, _ = store
    index = NgramIndex.build(db, sql_dir, progress=lambda line: None)
    assert index.corpora == ["household", "recipes"]
    for phrase in ("pan", "cutting board", "cheese", "board", "bowl", "scissors", "Cutting Boards"):
        alone = PhraseCounts(*store)
        alone.count([phrase])
        assert index.count(phrase, {"all": 1.0}) == alone.counts[phrase.lower()], phrase
    assert index.count("pan", {"household": 3.0}) == 3 * 2
    assert index.count("pan", {"recipes": 1.0, "household": 0.5}) == 3 + 0.5 * 2


def test_a_phrase_the_index_cannot_hold_is_not_looked_up():
    assert ngram_index.words("Cutting  Board") == ["cutting", "board"]
    for phrase in ("crème fraîche", "m&m", "salt and black pepper", "  "):
        assert ngram_index.words(phrase) is None, phrase
    assert NgramIndex(np.zeros(0, dtype=np.uint64), np.zeros((0, 0)), []).count("pan", {"all": 1.0}) == 0.0


def test_the_key_is_duckdbs_md5_number():
    duckdb = pytest.importorskip("duckdb")
    for ngram in ("pan", "cutting board", "a b c"):
        assert (
            ngram_index.key(ngram) == duckdb.connect().execute("select md5_number_upper(?)", [ngram]).fetchall()[0][0]
        )


def test_phrases_met_while_scoring_are_looked_up_in_the_index_and_the_rest_scanned(store):
    keys = np.array(sorted(ngram_index.key(k) for k in ("pan", "pans")), dtype=np.uint64)
    made_up = NgramIndex(keys, np.array([[40], [2]], dtype=np.uint32), ["recipes"])  # counts no scan gives
    calls = []
    counts = PhraseCounts(*store, index=lambda: calls.append(1) or made_up)
    counts.look_up(["Pan", "dump the pan into", "crème"])
    assert counts.counts == {"pan": 42, "dump the pan into": 1, "crème": 0} and calls == [1]
    counts.count(["cheese"])  # the up-front count is a scan, the index untouched
    assert counts.counts["cheese"] == 1 and calls == [1]


def test_the_index_is_cached_and_an_unreadable_one_is_rebuilt(store, tmp_path, monkeypatch):
    db, sql_dir, _ = store
    path = tmp_path / "cache" / "ngrams.npz"
    first = NgramIndex.cached(db, sql_dir, path)
    assert path.is_file() and first.count("pan", {"all": 1.0}) == 5

    def no_build(*args, **kwargs):
        raise AssertionError("built again")

    monkeypatch.setattr(NgramIndex, "build", no_build)
    assert NgramIndex.cached(db, sql_dir, path).count("cutting board", {"all": 1.0}) == 2
    monkeypatch.undo()
    path.write_bytes(b"not an index")
    assert NgramIndex.cached(db, sql_dir, path).count("pan", {"all": 1.0}) == 5
    assert NgramIndex.load(path).count("pan", {"all": 1.0}) == 5


def test_the_rarity_scorer_indexes_the_store_at_its_first_new_label(store, tmp_path):
    db, sql_dir, _ = store
    res = MethodResources(checkpoints=db.parent, db=db, sql_dir=sql_dir, cache_dir=tmp_path / "caches")
    frames = [Frame.of("dump", {"Theme": "cheese", "Destination": "panini pan"})]
    scanned = PhraseCounts(*store)
    expected = -WEIGHT * (scanned.log_p("cheese") + scanned.log_p("panini pan"))
    assert make_scorer("rarity", res)(frames) == pytest.approx([expected])
    assert [p.name.split("-")[0] for p in (tmp_path / "caches").glob("ngrams-*.npz")] == ["ngrams"]


def test_a_cache_named_afresh_removes_only_those_it_supersedes(tmp_path):
    """Files named as the new cache but for their content hashes (another corpus content, frame build or
    learned table), with any ending, are removed; other settings, mixtures, kinds and the new cache's own
    files stay, and so does a name with no hash."""
    from lmcr.scorers.caches import superseding

    old, new = "0123456789ab", "ba9876543210"
    names = [
        f"frame-counts-all-household=10-{old}-{old}-frame_fillers.parquet",  # superseded
        f"frame-counts-all-household=10-{old}-{new}-frame_filler_pairs.parquet",  # superseded (frames)
        f"frame-counts-all-household=10-{new}-{new}-frame_fillers.parquet",  # the new one's own
        f"frame-counts-all-household=100-{old}-{old}-frame_fillers.parquet",  # another mixture
        f"frame-counts-recipes-household=10-{old}-{old}-frame_fillers.parquet",  # another setting
        f"context-sentences-all-household=10-{old}.json",  # another kind
        "frame-counts-all-household=10-notes.txt",  # no hash
    ]
    for name in names:
        (tmp_path / name).write_text("x")
    path = tmp_path / f"frame-counts-all-household=10-{new}-{new}.json"
    assert superseding(path) == path
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names[2:])
    assert superseding(tmp_path / "missing" / f"ngrams-{new}.npz").name == f"ngrams-{new}.npz"  # no folder yet
    (tmp_path / f"ngrams-{old}.npz").write_text("x")
    superseding(tmp_path / f"ngrams-{new}.npz")
    assert not (tmp_path / f"ngrams-{old}.npz").exists()
