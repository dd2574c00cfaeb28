"""Migrations: applied once, in order, recorded; a failing one rolls back and stays pending."""

from __future__ import annotations

import shutil

import duckdb
import pytest

from lmcr.checkout import REPO_ROOT
from lmcr.store import ContractViolation, MigrationError, check_contracts, connect, list_migrations, migrate


@pytest.fixture
def sql_dir(tmp_path):
    target = tmp_path / "sql"
    shutil.copytree(REPO_ROOT / "sql", target)
    return target


def test_real_migrations_apply_once(sql_dir):
    con = duckdb.connect(":memory:")
    names = migrate(con, sql_dir)
    assert names == [m.name for m in list_migrations(sql_dir)] and names[0] == "001_ingest"
    assert migrate(con, sql_dir) == []
    assert con.execute("select count(*) from schema_migrations").fetchone()[0] == len(names)
    assert check_contracts(con, sql_dir)  # empty tables satisfy every contract


def test_failing_migration_rolls_back_and_stays_pending(sql_dir):
    con = duckdb.connect(":memory:")
    migrate(con, sql_dir)
    bad = sql_dir / "900_broken.sql"
    bad.write_text("create table half_done (x integer);\ninsert into no_such_table values (1);\n")
    with pytest.raises(MigrationError, match="900_broken.sql.*rolled back, still pending"):
        migrate(con, sql_dir)
    tables = {r[0] for r in con.execute("select table_name from information_schema.tables").fetchall()}
    assert "half_done" not in tables
    assert 900 not in dict(con.execute("select version, name from schema_migrations").fetchall())
    bad.write_text("create table half_done (x integer);\n")
    assert migrate(con, sql_dir) == ["900_broken"]


def test_edited_migration_is_refused(sql_dir, tmp_path):
    con = connect(tmp_path / "s.duckdb", sql_dir)
    first = list_migrations(sql_dir)[0].path
    first.write_text(first.read_text() + "\n-- edited\n")
    with pytest.raises(MigrationError, match="edited after it was applied"):
        migrate(con, sql_dir)


def test_duplicate_version_is_refused(sql_dir):
    (sql_dir / "001_again.sql").write_text("select 1;")
    with pytest.raises(MigrationError, match="version 001 also used"):
        list_migrations(sql_dir)


def test_contract_violation_is_reported(sql_dir):
    con = duckdb.connect(":memory:")
    migrate(con, sql_dir)
    con.execute(
        "insert into documents values ('recipes','s','d1',null,null,null,null,'f',1),"
        "('recipes','s','d1',null,null,null,null,'g',1)"
    )
    with pytest.raises(ContractViolation, match="ingest_documents_unique"):
        check_contracts(con, sql_dir, prefix="ingest_")


def test_a_writer_leaves_its_commits_in_the_log_and_the_schema_in_the_file(tmp_path):
    """Closing a write connection does not checkpoint (a checkpoint rewrites metadata blocks in place,
    which a kill can tear), yet the next reader sees the commit; the schema itself is in the file."""
    db = tmp_path / "lmcr.duckdb"
    connect(db, REPO_ROOT / "sql").close()
    wal = tmp_path / "lmcr.duckdb.wal"
    assert not wal.exists() or wal.stat().st_size == 0  # migrations were checkpointed
    before = db.read_bytes()
    with connect(db, REPO_ROOT / "sql") as con:
        con.execute("insert into quarantine (stage, source_file, reason) values ('ingest', 'f.jsonl', 'test')")
    assert db.read_bytes() == before and wal.stat().st_size > 0
    for open_store in (lambda: duckdb.connect(str(db), read_only=True), lambda: connect(db, REPO_ROOT / "sql")):
        with open_store() as con:
            assert con.execute("select reason from quarantine").fetchall() == [("test",)]


def test_a_log_holding_the_schema_replays_offline(tmp_path):
    """A writer killed between a migration's commit and its checkpoint leaves the schema in the WAL;
    replaying migration 010's macros must not try to download ICU (DuckDB 2.0 does unless told not to)."""
    db = tmp_path / "lmcr.duckdb"
    con = duckdb.connect(str(db))
    con.execute("pragma disable_checkpoint_on_shutdown")  # as a kill before the checkpoint would leave it
    migrate(con, REPO_ROOT / "sql")
    con.close()
    assert (tmp_path / "lmcr.duckdb.wal").stat().st_size > 0
    with connect(db, REPO_ROOT / "sql") as con:
        assert con.execute("select count(*) from schema_migrations").fetchone()[0] == len(
            list_migrations(REPO_ROOT / "sql")
        )
