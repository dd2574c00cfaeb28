"""Every `lmcr sql` / `lmcr query` line of the README and of the user's guide (docs/guide/) runs as written
on a store built from the sample (ingested corpora, frames, ratings): the documented queries cannot rot
silently."""

from __future__ import annotations

import shlex

import pytest
from typer.testing import CliRunner

from lmcr.annotate.results import ingest_ratings
from lmcr.checkout import REPO_ROOT
from lmcr.cli import app
from lmcr.frame_corpus.build import build_frame_corpus, process_pool
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.ingest import expand_inputs
from lmcr.ingest.run import ingest_sources

pytestmark = pytest.mark.model


def documented_commands(path) -> list[list[str]]:
    lines = path.read_text(encoding="utf-8").splitlines()
    return [shlex.split(line)[1:] for line in lines if line.startswith(("lmcr sql ", "lmcr query "))]


def readme_commands() -> list[list[str]]:
    """The README's query lines, then the guide's, page by page."""
    pages = [REPO_ROOT / "README.md", *sorted((REPO_ROOT / "docs" / "guide").glob("*.md"))]
    return [args for page in pages for args in documented_commands(page)]


def test_the_readme_and_the_guide_document_queries():
    assert len(documented_commands(REPO_ROOT / "README.md")) >= 6
    assert len(documented_commands(REPO_ROOT / "docs" / "guide" / "store.md")) >= 4


def test_every_readme_query_runs(con, paths, sample_dir):
    sources = expand_inputs([sample_dir / "youcook2"], "youcook2") + expand_inputs(
        [sample_dir / "nyc", sample_dir / "recipes_json" / "recipes_sample.jsonl"], "recipes"
    )
    ingest_sources(con, sources, paths.staging, workers=1)
    build_frame_corpus(con, paths.staging, paths.srl_dir, FrameCorpusConfig(), process_pool(1))
    ingest_ratings(con, sample_dir / "ratings" / "sample_ratings_mturk.csv")
    con.close()  # the commands open the store read-only, as a user's shell would
    runner = CliRunner()
    for args in readme_commands():
        result = runner.invoke(app, [*args, "--db", str(paths.db)])
        assert result.exit_code == 0, (args, result.output)
        assert result.stdout.strip(), args


def test_queries_never_write_and_name_missing_parameters(con, paths):
    con.close()
    runner = CliRunner()
    written = runner.invoke(app, ["sql", "delete from sentences", "--db", str(paths.db)])
    assert written.exit_code == 1 and "read-only" in written.stderr
    missing = runner.invoke(app, ["query", "frame_fillers", "--db", str(paths.db)])
    assert missing.exit_code == 1 and "missing ['corpus']" in missing.stderr
    unknown = runner.invoke(app, ["query", "nope", "--db", str(paths.db)])
    assert unknown.exit_code == 1 and "available: " in unknown.stderr and "corpus_summary" in unknown.stderr


def test_schema_page_is_current_and_every_column_is_described():
    from lmcr.catalog import schema_page

    page = schema_page(REPO_ROOT / "sql")
    assert (REPO_ROOT / "sql" / "SCHEMA.md").read_text(encoding="utf-8") == page, (
        "sql/SCHEMA.md is stale: run `lmcr schema --out sql/SCHEMA.md`"
    )
    assert "(no comment)" not in page
    rows = [line for line in page.splitlines() if line.startswith("| ") and not line.startswith("| column")]
    assert len(rows) > 150 and all(not line.endswith("|  |") for line in rows)


def test_mturk_times_and_rewards_are_typed(con, sample_dir, tmp_path):
    import csv

    source = sample_dir / "ratings" / "sample_ratings_mturk.csv"
    with source.open(encoding="utf-8", newline="") as f:
        rows = list(csv.DictReader(f))
    for row, (time, reward) in zip(rows, [("Tue Nov 17 10:02:00 PST 2026", "$0.30"), ("garbage", "")]):
        row.update({"SubmitTime": time, "Reward": reward})
    path = tmp_path / "typed.csv"
    with path.open("w", encoding="utf-8", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows[:2])
    ingest_ratings(con, path)
    got = con.execute(
        "select a.submit_time::varchar, h.reward::varchar, typeof(a.submit_time), typeof(h.reward) "
        "from assignments a join hits h using (hit_id) order by a.line"
    ).fetchall()
    assert got[0] == ("2026-11-17 18:02:00", "0.30", "TIMESTAMP", "DECIMAL(9,2)")
    assert got[1][0] is None  # unreadable time: NULL, the row itself loads
