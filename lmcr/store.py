"""The DuckDB store: connecting, numbered append-only migrations, and table contracts that run as queries."""

from __future__ import annotations

import hashlib
import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import duckdb
import pyarrow as pa

from lmcr.errors import LMCRError, one_line
from lmcr.files import check_output_file

MIGRATION_NAME = re.compile(r"^(\d{3})_[a-z0-9_]+\.sql$")
# What a user's query runs under (`lmcr sql`, `lmcr query`): the store alone. No file outside it is read or
# written (COPY, EXPORT DATABASE, read_csv, read_text, glob, ATTACH all refused), no extension is
# installed or loaded, and the configuration is locked once set, so a query cannot SET any of it back.
QUERY_STATEMENTS = ("SELECT", "EXPLAIN", "PRAGMA", "CALL")  # what a query may be: no ATTACH, COPY, LOAD, SET
QUERY_CONFIG = {
    "enable_external_access": False,
    "allow_community_extensions": False,
    "autoload_known_extensions": False,
    "autoinstall_known_extensions": False,
}
# What every open of the store runs under: no extension is ever downloaded. Replaying a WAL that holds
# migration 010's macros, DuckDB 2.0 tries to install ICU although it is built in, and offline that fails.
STORE_CONFIG = {"autoinstall_known_extensions": False}


class MigrationError(LMCRError, RuntimeError):
    """A migration failed (it was rolled back and stays pending) or an applied one was edited."""


class ContractViolation(LMCRError, RuntimeError):
    """A table contract query returned offending rows."""


class StoreBusyError(LMCRError, RuntimeError):
    """Another process holds the store's write lock."""


class QueryError(LMCRError, ValueError):
    """A user's SQL query that is refused or fails (a write, a missing parameter, a DuckDB error)."""


def _open(db: str | Path, read_only: bool, config: dict | None = None) -> duckdb.DuckDBPyConnection:
    """duckdb.connect, with a held lock as StoreBusyError and an unreadable file as MigrationError."""
    try:
        return duckdb.connect(str(db), read_only=read_only, config={**STORE_CONFIG, **(config or {})})
    except duckdb.ConnectionException:  # open in this process in the other mode: `read_connection` decides
        raise
    except duckdb.Error as exc:  # a held lock; not a DuckDB file, a newer storage version, ...
        if isinstance(exc, duckdb.IOException) and "lock" in str(exc).lower():
            raise StoreBusyError(
                f"store busy: another lmcr process is writing {db}; try again when it finishes"
            ) from exc
        raise MigrationError(f"{db}: cannot open the store: {one_line(exc, 200)}") from exc


@contextmanager
def transaction(con: duckdb.DuckDBPyConnection) -> Iterator[duckdb.DuckDBPyConnection]:
    """One all-or-nothing unit of writes (as sqlite-utils' `db.atomic()`): committed when the block
    ends, rolled back when it raises anything, KeyboardInterrupt included."""
    con.execute("begin transaction")
    try:
        yield con
    except BaseException:
        con.execute("rollback")
        raise
    con.execute("commit")


def insert_rows(
    con: duckdb.DuckDBPyConnection,
    table: str,
    rows: list[dict],
    key: str | None = None,
    convert: dict[str, str] | None = None,
) -> None:
    """Insert dict rows by column name (as sqlite-utils' `insert_all`): columns the rows lack take their
    defaults; with `key`, rows whose key is already in the table are left as they are; `convert` maps a
    column to the SQL expression that converts its value on the way in (e.g. `mturk_time(submit_time)`)."""
    if not rows:
        return
    names = [d[0] for d in con.execute(f"select * from {table} limit 0").description]
    names = [n for n in names if n in rows[0]]
    con.register("_insert_batch", pa.Table.from_pylist([{n: r.get(n) for n in names} for r in rows]))
    try:
        values = ", ".join((convert or {}).get(n, n) for n in names)
        where = f" where {key} not in (select {key} from {table})" if key else ""
        con.execute(f"insert into {table} ({', '.join(names)}) select {values} from _insert_batch{where}")
    finally:
        con.unregister("_insert_batch")


@dataclass(frozen=True)
class Migration:
    version: int
    name: str
    path: Path

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.path.read_bytes()).hexdigest()


def connect(db: str | Path, sql_dir: Path, read_only: bool = False) -> duckdb.DuckDBPyConnection:
    """Open the store (creating its folder) and bring its schema up to date unless read-only.

    A writer's commits stay in DuckDB's write-ahead log (`<db>.wal`) when it closes, instead of being
    checkpointed into the file as DuckDB does by default: a checkpoint rewrites the file's metadata blocks
    in place, and a writer killed (SIGKILL, the OOM killer) while it checkpointed on close has left a store
    whose first block failed its checksum, a store that no longer opens. A WAL cut short by a kill loses
    only its uncommitted tail when it is replayed. DuckDB still checkpoints by itself, when the log passes
    `checkpoint_threshold` or a commit is large, and schema changes are checkpointed at once, so that any
    DuckDB client can replay what the log holds."""
    if str(db) != ":memory:":
        check_output_file(Path(db))  # a data folder that is a file: one line naming it, not mkdir's errno
        Path(db).parent.mkdir(parents=True, exist_ok=True)
    con = _open(db, read_only)
    con.execute("set enable_progress_bar = false")  # library calls report progress their own way
    if not read_only:
        con.execute("pragma disable_checkpoint_on_shutdown")
        if migrate(con, sql_dir):
            con.execute("checkpoint")
    return con


def read_connection(db: str | Path) -> duckdb.DuckDBPyConnection:
    """A connection for reading: read-only, unless this process already has the file open read-write
    (DuckDB refuses a second configuration of one file within a process; then share its mode)."""
    try:
        con = _open(db, read_only=True)
    except duckdb.ConnectionException:  # only then: never open a file that is not a store read-write
        con = _open(db, read_only=False)
    con.execute("set enable_progress_bar = false")
    return con


def list_migrations(sql_dir: Path) -> list[Migration]:
    """The `NNN_name.sql` files of `sql_dir`, in version order; duplicate versions are an error."""
    found: dict[int, Migration] = {}
    for path in sorted(sql_dir.glob("*.sql")):
        match = MIGRATION_NAME.match(path.name)
        if not match:
            continue
        version = int(match.group(1))
        if version in found:
            raise MigrationError(f"{path}: version {version:03d} also used by {found[version].path.name}")
        found[version] = Migration(version, path.stem, path)
    return [found[v] for v in sorted(found)]


def applied_migrations(con: duckdb.DuckDBPyConnection) -> dict[int, str]:
    """Version -> sha256 of every migration recorded as applied."""
    con.execute(
        "create table if not exists schema_migrations ("
        " version integer primary key, name varchar not null, sha256 varchar not null,"
        " applied_at timestamp not null default current_timestamp)"
    )
    return dict(con.execute("select version, sha256 from schema_migrations").fetchall())


def migrate(con: duckdb.DuckDBPyConnection, sql_dir: Path) -> list[str]:
    """Apply pending migrations in order, each in its own transaction; return the names applied.

    A failing migration is rolled back (none of its statements stay) and remains pending, so fixing
    the file and re-running applies it. An applied migration whose file changed is refused: migrations
    are append-only and a changed one would leave stores built before and after the edit different.
    """
    applied = applied_migrations(con)
    done: list[str] = []
    for mig in list_migrations(sql_dir):
        if mig.version in applied:
            if applied[mig.version] != mig.sha256:
                raise MigrationError(f"{mig.path}: edited after it was applied; add a new migration instead")
            continue
        try:
            with transaction(con):
                con.execute(mig.path.read_text(encoding="utf-8"))
                con.execute(
                    "insert into schema_migrations (version, name, sha256) values (?, ?, ?)",
                    [mig.version, mig.name, mig.sha256],
                )
        except duckdb.Error as exc:
            raise MigrationError(f"{mig.path}: {one_line(exc)}; rolled back, still pending") from exc
        done.append(mig.name)
    return done


def named_query(sql_dir: Path, name: str) -> str:
    """The text of `sql/queries/<name>.sql`."""
    path = sql_dir / "queries" / f"{name}.sql"
    if not path.is_file():
        available = ", ".join(sorted(p.stem for p in (sql_dir / "queries").glob("*.sql")))
        raise FileNotFoundError(f"no named query {name!r} (available: {available})")
    return path.read_text(encoding="utf-8")


def query_params(sql: str) -> list[str]:
    """The `$name` parameters a query binds."""
    return sorted(set(re.findall(r"\$([A-Za-z_][A-Za-z0-9_]*)", sql)))


def query_connection(db: str | Path) -> duckdb.DuckDBPyConnection:
    """A connection for a user's SQL: read-only, the store and nothing else (QUERY_CONFIG), locked.
    The store open in this process under another configuration is a one-line QueryError."""
    try:
        con = _open(db, read_only=True, config=QUERY_CONFIG)
    except duckdb.ConnectionException as exc:
        raise QueryError(f"{db}: {one_line(exc)}") from exc
    con.execute("set enable_progress_bar = false")  # a session setting: set before the lock
    con.execute("set lock_configuration = true")
    return con


def run_query(db: str | Path, sql: str, params: dict[str, str] | None = None) -> tuple[list[str], list[tuple]]:
    """(column names, rows) of one statement on a `query_connection`: a query never writes, and reads
    nothing but the store. Statements other than QUERY_STATEMENTS are refused before they run (the
    connection's configuration refuses a file access in any case); they, missing or unknown `$name`
    parameters and SQL errors raise QueryError with a one-line reason."""
    if not Path(db).is_file():
        raise QueryError(f"no store at {db}: run `lmcr ingest` (or `make demo`) first")
    params = dict(params or {})
    wanted = query_params(sql)
    missing, unknown = sorted(set(wanted) - set(params)), sorted(set(params) - set(wanted))
    if missing or unknown:
        raise QueryError(
            f"query parameters: missing {missing or 'none'}, unknown {unknown or 'none'} "
            f"(this query takes {wanted or 'none'}; give --param NAME=VALUE)"
        )
    con = query_connection(db)
    try:
        kinds = [s.type.name for s in con.extract_statements(sql)]
        if not kinds:
            raise QueryError("no SQL statement given")
        refused = [kind for kind in kinds if kind not in QUERY_STATEMENTS]
        if refused:
            raise QueryError(
                f"a query reads the store (read-only) and nothing else: {', '.join(QUERY_STATEMENTS)}, not {refused[0]}"
            )
        cursor = con.execute(sql, params or None)
        if cursor.description is None:
            return [], []
        return [d[0] for d in cursor.description], cursor.fetchall()
    except duckdb.Error as exc:
        raise QueryError(one_line(exc)) from exc
    finally:
        con.close()


def query_dicts(con: duckdb.DuckDBPyConnection, sql: str, params: list | None = None) -> list[dict]:
    """Rows of a query as dicts keyed by column name."""
    cursor = con.execute(sql, params or [])
    names = [d[0] for d in cursor.description]
    return [dict(zip(names, row)) for row in cursor.fetchall()]


def check_contracts(con: duckdb.DuckDBPyConnection, sql_dir: Path, prefix: str = "") -> dict[str, int]:
    """Run every `sql/contracts/<prefix>*.sql` query; each returns offending rows, so any row is a violation."""
    results: dict[str, int] = {}
    for path in sorted((sql_dir / "contracts").glob(f"{prefix}*.sql")):
        results[path.stem] = len(con.execute(path.read_text(encoding="utf-8")).fetchall())
    bad = {name: n for name, n in results.items() if n}
    if bad:
        raise ContractViolation(f"table contracts violated: {bad}")
    return results
