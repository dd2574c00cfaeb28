"""Every `lmcr sql` / `lmcr query` line of the README runs as written on a store built from the sample
(ingested corpora, frames, ratings): the documented queries cannot rot silently."""

from __future__ import annotations

import shlex

import pytest
from typer.testing import CliRunner

from lmcr.annotate.results import ingest_ratings
from lmcr.cli import app
from lmcr.config import REPO_ROOT
from lmcr.ingest import expand_inputs
from lmcr.ingest.run import ingest_sources
from lmcr.srl.corpus import FrameCorpusConfig, build_frame_corpus

pytestmark = pytest.mark.model


def readme_commands() -> list[list[str]]:
    lines = (REPO_ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    return [shlex.split(line)[1:] for line in lines if line.startswith(("lmcr sql ", "lmcr query "))]


def test_the_readme_documents_queries():
    assert len(readme_commands()) >= 6


def test_every_readme_query_runs(con, paths, sample_dir):
    sources = expand_inputs([sample_dir / "youcook2"], "youcook2") + expand_inputs(
        [sample_dir / "nyc", sample_dir / "recipes_json" / "recipes_sample.jsonl"], "recipes")
    ingest_sources(con, sources, paths.staging, workers=1)
    build_frame_corpus(con, paths.staging, paths.srl_dir, FrameCorpusConfig(), workers=1)
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
    assert unknown.exit_code == 1 and "available: corpus_summary" in unknown.stderr
