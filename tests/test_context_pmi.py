"""The context term: document counts from a tiny store, by hand, and what a purpose does to a ranking."""

from __future__ import annotations

import json
import math

import pytest

from lmcr.context_pmi import MIN_DOCS, WEIGHT, ContextCooccurrence
from lmcr.frame import Frame
from lmcr.methods import MethodResources, make_scorer, scorer_fingerprint
from lmcr.store import connect
from lmcr.workspace import Workspace

DOCUMENTS = [  # (corpus, document, its sentences)
    ("recipes", "apple pie", ["Apple Pie", "Toss the apples with cinnamon and sugar.", "Bake the pie."]),
    ("recipes", "cherry pie", ["Cherry pie", "Stir cinnamon into the cherries; add a pinch of salt."]),
    ("recipes", "soup", ["Season the soup with salt.", "Simmer in a pot."]),
    ("recipes", "pasta", ["Boil the pasta in a pot of salted water.", "Season with salt and black pepper."]),
    ("household", "P01_01", ["boil water in pot", "pour water into cup"]),
]
OBJECTS = ["cinnamon", "salt", "black pepper", "pot", "cup", "pasta", "apple"]


@pytest.fixture
def store(tmp_path):
    db = tmp_path / "lmcr.duckdb"
    sql_dir = Workspace.from_env().sql_dir
    con = connect(db, sql_dir)
    rows = [(corpus, doc, i, text, len(text.split())) for corpus, doc, texts in DOCUMENTS for i, text in enumerate(texts)]
    con.executemany("insert into sentences values (?, 's', ?, ?, 'instruction', ?, ?, 'f', 0, null, null)", rows)
    con.close()
    return db, sql_dir


def test_documents_are_counted_whole_with_plurals(store):
    counts = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_docs=1)
    assert counts.docs == 5
    # 'apples' names the apple; 'pepper' alone is not 'black pepper'; 'salted' is not salt
    assert counts.object_docs == {"cinnamon": 2, "salt": 3, "black pepper": 1, "pot": 3, "cup": 1, "pasta": 1, "apple": 1}
    assert counts.word_docs["pie"] == 2 and counts.word_docs["boil"] == 2 and counts.word_docs["the"] == 4
    # a word and an object in different sentences of one document count together
    assert counts.pair_docs["cinnamon"]["pie"] == 2 and counts.pair_docs["salt"]["pie"] == 1
    assert "pie" not in counts.pair_docs["pot"]
    assert ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_docs=3).word_docs.keys() == {"the", "with", "in", "a", "salt", "pot"}


def test_a_purpose_lifts_the_filler_that_shares_its_documents(store):
    counts = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_docs=1)
    frames = [Frame.of("season", {"Theme": "apple", "Instrument": spice}) for spice in ("salt", "cinnamon")]
    salt, cinnamon = counts.score(frames, "for the pie")
    assert cinnamon > salt
    # D = 5; pie: 2 documents; cinnamon: 2, both with pie; salt: 3, one with pie; the apple: 1, with pie
    assert cinnamon - salt == pytest.approx(WEIGHT * (math.log(3 * 6 / (3 * 3)) - math.log(2 * 6 / (3 * 4))))
    assert counts.score(frames, "") == [0.0, 0.0]  # no context: as without the term
    assert counts.score(frames, "for the") == [0.0, 0.0]  # stop words say nothing


def test_words_of_the_filler_itself_do_not_count(store):
    counts = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_docs=1)
    assert counts.context_words("so I can boil the pasta, the pasta and the pastas!") == ["boil", "pasta"]  # no 'pastas' document
    pot, pasta = counts.score([Frame.of("fill", {"Theme": "water", "Destination": d}) for d in ("pot", "pasta")],
                              "so I can boil the pasta")
    # the pasta is credited for 'boil' only, the pot for 'boil' and 'pasta' (each with the water too)
    assert pasta == pytest.approx(WEIGHT * (counts.pmi("boil", "pasta") + counts.pmi("boil", "water") + counts.pmi("pasta", "water")))
    assert pot == pytest.approx(WEIGHT * sum(counts.pmi(w, o) for w in ("boil", "pasta") for o in ("pot", "water")))


def test_a_mixture_weighs_each_corpus_documents(store):
    plain = ContextCooccurrence.count(*store, OBJECTS, {"recipes": 1.0, "household": 1.0}, min_docs=1)
    mixed = ContextCooccurrence.count(*store, OBJECTS, {"recipes": 1.0, "household": 3.0}, min_docs=1)
    assert plain.docs == 5 and mixed.docs == 4 + 3
    assert plain.object_docs["cup"] == 1 and mixed.object_docs["cup"] == 3
    assert mixed.pair_docs["pot"]["boil"] == 1 + 3


def test_context_pmi_is_a_context_reading_term_with_a_cache(store, tmp_path):
    db, sql_dir = store
    res = MethodResources(checkpoints=db.parent, db=db, sql_dir=sql_dir, cache_dir=tmp_path / "cache")
    frames = [Frame.of("season", {"Theme": "apple", "Instrument": s}) for s in ("salt", "cinnamon")]
    term = make_scorer("context_pmi", res)
    assert term(frames) == [0.0, 0.0] and not (tmp_path / "cache").exists()  # nothing counted without context
    assert term(frames, "for my tea") == [0.0, 0.0]  # 'tea' is in fewer than MIN_DOCS documents
    [cache] = (tmp_path / "cache").glob("context-all-plain-*.json")
    assert json.loads(cache.read_text())["docs"] == 5
    summed = make_scorer("random+context_pmi", res)(frames, "for my tea")
    assert summed == pytest.approx(make_scorer("random", res)(frames))
    assert scorer_fingerprint("context_pmi", res).endswith(f"*{WEIGHT:g}/{MIN_DOCS}")
