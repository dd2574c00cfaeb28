"""Ingesting the sample into a store: counts, idempotence, replacement, all-or-nothing loads."""

from __future__ import annotations

import shutil

import duckdb
import pytest

from lmcr.ingest import IngestError, expand_inputs
from lmcr.ingest.run import corpus_summary, ingest_sources, parse_and_stage
from lmcr.ingest.stage import load_staged


def sample_sources(sample_dir):
    return expand_inputs([sample_dir / "youcook2"], "youcook2") + expand_inputs(
        [
            sample_dir / "nyc",
            sample_dir / "recipes_json" / "recipes_sample.jsonl",
            sample_dir / "recipes_json" / "folder",
            sample_dir / "feeding_america",
        ],
        "recipes",
    )


# the column of each table that differs between runs (a load time) or by design (the corpus name)
UNSTABLE = {"documents": "corpus", "sentences": "corpus", "quarantine": "quarantined_at", "ingested_files": "loaded_at"}


def snapshot(con):
    return {t: con.execute(f"select * exclude ({col}) from {t} order by all").fetchall() for t, col in UNSTABLE.items()}


def test_sample_counts_balance(con, paths, sample_dir):
    loaded, skipped = ingest_sources(con, sample_sources(sample_dir), paths.staging, workers=2)
    assert (len(loaded), skipped) == (6, [])
    summary = {row["corpus"]: row for row in corpus_summary(con, paths.sql_dir)}
    assert summary["youcook2"] == {
        **summary["youcook2"],
        "records_in": 59,
        "records_loaded": 56,
        "quarantined": 3,
        "documents": 11,
        "sentences": 56,
    }
    assert summary["recipes"] == {
        **summary["recipes"],
        "records_in": 31,
        "records_loaded": 22,
        "quarantined": 9,
        "documents": 22,
    }
    assert con.execute("select count(*) from quarantine").fetchone()[0] == 12
    assert con.execute("select count(*) from quarantine where reason = '' or source_file is null").fetchone()[0] == 0


def test_reingest_is_a_no_op(con, paths, sample_dir):
    ingest_sources(con, sample_sources(sample_dir), paths.staging)
    before = snapshot(con)
    loaded, skipped = ingest_sources(con, sample_sources(sample_dir), paths.staging)
    assert loaded == [] and len(skipped) == 6
    assert snapshot(con) == before


def test_changed_file_replaces_its_rows(con, paths, sample_dir, tmp_path):
    path = tmp_path / "r.jsonl"
    path.write_text('{"title": "A", "ingredients": ["salt"], "directions": ["Pour milk. Stir."]}\n')
    ingest_sources(con, expand_inputs([path], "recipes"), paths.staging)
    path.write_text('{"title": "B", "ingredients": [], "directions": ["Heat oil."]}\n{"bad"\n')
    loaded, _ = ingest_sources(con, expand_inputs([path], "recipes"), paths.staging)
    assert len(loaded) == 1
    assert con.execute("select text from sentences order by sent_id").fetchall() == [("B",), ("Heat oil.",)]
    assert con.execute("select position, reason from quarantine").fetchall()[0][0] == 2
    corpus_summary(con, paths.sql_dir)  # contracts hold after the replacement


def test_failed_load_leaves_previous_rows(con, paths, sample_dir):
    source = expand_inputs([sample_dir / "recipes_json" / "recipes_sample.jsonl"], "recipes")[0]
    staged = parse_and_stage(source, source.sha256(), paths.staging)
    load_staged(con, staged)
    before = snapshot(con)
    # A crash between the deletes and the inserts: the staged sentences file vanished.
    broken = parse_and_stage(source, "f" * 64, paths.staging)
    shutil.os.remove(broken.parquet["sentences"])
    with pytest.raises((duckdb.Error, OSError)):
        load_staged(con, broken)
    assert snapshot(con) == before


def test_document_id_clash_is_refused(con, paths, sample_dir, tmp_path):
    for sub in ("a", "b"):
        (tmp_path / sub).mkdir()
        shutil.copy(sample_dir / "recipes_json" / "recipes_sample.jsonl", tmp_path / sub / "recipes.jsonl")
    ingest_sources(con, expand_inputs([tmp_path / "a" / "recipes.jsonl"], "recipes"), paths.staging)
    (tmp_path / "b" / "recipes.jsonl").write_text('{"title": "X", "ingredients": ["salt"]}\n')
    with pytest.raises(IngestError, match="document id 'recipes:1' is already loaded from"):
        ingest_sources(con, expand_inputs([tmp_path / "b" / "recipes.jsonl"], "recipes"), paths.staging)
    corpus_summary(con, paths.sql_dir)


def test_a_removed_source_takes_its_rows_and_nothing_else(con, paths, sample_dir, monkeypatch):
    from typer.testing import CliRunner

    from lmcr.cli import app
    from lmcr.ingest.stage import remove_sources

    ingest_sources(con, sample_sources(sample_dir), paths.staging)
    jsonl = str(sample_dir / "recipes_json" / "recipes_sample.jsonl")
    sentences = con.execute("select count(*) from sentences where source_file = ?", [jsonl]).fetchone()[0]
    total = con.execute("select count(*) from sentences").fetchone()[0]
    with pytest.raises(IngestError, match="not an ingested source: nothing removed"):
        remove_sources(con, [jsonl, str(sample_dir / "nowhere.jsonl")])
    assert con.execute("select count(*) from sentences").fetchone()[0] == total  # all or nothing
    removed = remove_sources(con, [jsonl])
    assert [(r["source_file"], r["sentences"]) for r in removed] == [(jsonl, sentences)]
    assert con.execute("select count(*) from sentences").fetchone()[0] == total - sentences > 0
    assert con.execute("select count(*) from documents where source_file = ?", [jsonl]).fetchone()[0] == 0
    corpus_summary(con, paths.sql_dir)  # contracts hold after the removal
    con.close()

    # The CLI removes by the same file under another spelling of its path, in one line per source.
    monkeypatch.chdir(sample_dir)
    result = CliRunner().invoke(app, ["ingest", "--remove", "feeding_america/sample_book.xml", "--db", str(paths.db)])
    assert result.exit_code == 0, result.output
    assert "removed" in result.output and "sample_book.xml" in result.output
    again = CliRunner().invoke(app, ["ingest", "--remove", "feeding_america/sample_book.xml", "--db", str(paths.db)])
    assert again.exit_code == 1 and "not an ingested source" in again.output and "Traceback" not in again.output


@pytest.mark.shared
def test_real_youcook2_and_one_cookbook(con, paths, shared_dir):
    data = shared_dir / "data"
    sources = expand_inputs([data / "youcook2" / "youcookii_annotations_trainval.json"], "youcook2")
    sources += expand_inputs([data / "recipes" / "feeding_america" / "army.xml"], "recipes")
    ingest_sources(con, sources, paths.staging)
    summary = {row["corpus"]: row for row in corpus_summary(con, paths.sql_dir)}
    assert summary["youcook2"]["sentences"] == 13829 and summary["youcook2"]["documents"] == 1790
    assert summary["recipes"]["documents"] == 381
    subsets = dict(
        con.execute("select subset, count(*) from documents where corpus = 'youcook2' group by 1").fetchall()
    )
    assert subsets == {"training": 1333, "validation": 457}
