"""The workspace: one reader of the environment, every folder derived from the data folder."""

from __future__ import annotations

from pathlib import Path

import duckdb
import pytest

from lmcr.store import insert_rows
from lmcr.workspace import SPACY_MODEL, Workspace

ENV = ("LMCR_DATA_DIR", "LMCR_DB", "LMCR_SQL_DIR", "LMCR_SPACY_MODEL", "LMCR_VECTORS", "LMCR_CONCEPTNET", "LMCR_PAPER")


@pytest.fixture
def clean_env(monkeypatch):
    for name in ENV:
        monkeypatch.delenv(name, raising=False)
    return monkeypatch


def test_defaults_without_environment(clean_env):
    ws = Workspace.from_env()
    assert ws.data_dir == Path("data") and ws.db == Path("data/lmcr.duckdb")
    assert ws.spacy_model == SPACY_MODEL and ws.vectors is None and ws.conceptnet is None and ws.paper is None
    assert (ws.srl_dir, ws.checkpoints, ws.calibration, ws.report, ws.robot, ws.baselines, ws.staging) == tuple(
        Path("data") / name for name in ("srl", "checkpoints", "calibration", "report", "robot", "baselines", "staging")
    )


def test_environment_then_arguments(clean_env, tmp_path):
    clean_env.setenv("LMCR_DATA_DIR", str(tmp_path / "env"))
    clean_env.setenv("LMCR_SPACY_MODEL", "my_model")
    clean_env.setenv("LMCR_PAPER", str(tmp_path / "paper.tex"))
    clean_env.setenv("LMCR_VECTORS", str(tmp_path / "glove.txt"))
    ws = Workspace.from_env()
    assert ws.db == tmp_path / "env" / "lmcr.duckdb" and ws.spacy_model == "my_model"
    assert ws.paper == tmp_path / "paper.tex"
    explicit = Workspace.from_env(data_dir=tmp_path / "arg", db=tmp_path / "other.duckdb")
    assert explicit.data_dir == tmp_path / "arg" and explicit.db == tmp_path / "other.duckdb"
    clean_env.setenv("LMCR_DB", str(tmp_path / "envdb.duckdb"))
    assert Workspace.from_env(data_dir=tmp_path / "arg").db == tmp_path / "envdb.duckdb"


def test_resources_take_the_workspace_inputs_unless_given(clean_env, tmp_path):
    clean_env.setenv("LMCR_VECTORS", str(tmp_path / "glove.txt"))
    ws = Workspace.from_env(data_dir=tmp_path)
    res = ws.resources(corpus="recipes", seed=3)
    assert (res.checkpoints, res.db, res.sql_dir, res.cache_dir) == (ws.checkpoints, ws.db, ws.sql_dir, ws.baselines)
    assert res.vectors == tmp_path / "glove.txt" and res.corpus == "recipes" and res.seed == 3
    assert ws.resources(vectors=tmp_path / "w2v.bin").vectors == tmp_path / "w2v.bin"


def test_connect_migrates_and_closes(clean_env, tmp_path):
    ws = Workspace.from_env(data_dir=tmp_path)
    with ws.connect() as con:
        assert con.execute("select count(*) from schema_migrations").fetchone()[0] >= 10
    with ws.read() as con:
        assert con.execute("select count(*) from sentences").fetchone()[0] == 0


def test_insert_rows_by_name_with_key_and_conversion():
    con = duckdb.connect()
    con.execute("create table t (id varchar primary key, n integer default 7, ts timestamp)")
    insert_rows(con, "t", [{"id": "a", "ts": "2026-01-02 03:04:05", "extra": 1}])
    insert_rows(
        con,
        "t",
        [{"id": "a", "ts": None}, {"id": "b", "ts": "x"}],
        key="id",
        convert={"ts": "try_cast(ts as timestamp)"},
    )
    insert_rows(con, "t", [])
    assert con.execute("select id, n, ts::varchar from t order by id").fetchall() == [
        ("a", 7, "2026-01-02 03:04:05"),
        ("b", 7, None),
    ]
