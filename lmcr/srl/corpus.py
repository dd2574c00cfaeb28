"""Frame corpora: the ingested sentences parsed into frames, sharded over worker processes.

Stages: learn compounds from the sentences; export sentence shards to Parquet (workers never open
the store); parse each shard to frame Parquet (cached by shard content and SRL code); then one
writer loads all shards in a transaction, learns role priors from the unambiguous frames and
resolves the ambiguous ones. A build is skipped when its fingerprint (corpus files, settings,
SRL code, compounds) matches the last one.
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import duckdb
import pyarrow as pa
import pyarrow.parquet as pq

from lmcr.files import atomic_path
from lmcr.ingest.stage import write_parquet_atomic
from lmcr.lexicon import LEXICON_FILES, load_lexicon
from lmcr.srl.compounds import Compounds, learn_compounds
from lmcr.srl.frames import FrameMention
from lmcr.srl.parser import COMPOUNDS_FILE, PRIORS_FILE, FrameParser, load_nlp
from lmcr.srl.priors import RolePriors
from lmcr.store import transaction

SRL_CODE = Path(__file__).parent
FRAME_SCHEMA = pa.schema([
    ("corpus", pa.string()), ("doc_id", pa.string()), ("sent_id", pa.int32()), ("frame_no", pa.int32()),
    ("predicate", pa.string()), ("known", pa.bool_()), ("pred_start", pa.int32()), ("pred_end", pa.int32()),
    ("ambiguous_role", pa.string()), ("resolved_by_prior", pa.bool_()),
])
ROLE_SCHEMA = pa.schema([
    ("corpus", pa.string()), ("doc_id", pa.string()), ("sent_id", pa.int32()), ("frame_no", pa.int32()),
    ("role", pa.string()), ("value", pa.string()), ("span_start", pa.int32()), ("span_end", pa.int32()),
])


@dataclass(frozen=True)
class FrameCorpusConfig:
    """Which sentences become frames and how the work is cut."""

    kinds: tuple[str, ...] = ("instruction", "comment")
    shard_size: int = 20_000
    model: str | None = None


@dataclass(frozen=True)
class Shard:
    """Distinct sentence texts to parse; `sentences` and `words` count every occurrence."""

    number: int
    path: str
    fingerprint: str
    sentences: int
    words: int


@dataclass(frozen=True)
class ShardResult:
    shard: Shard
    frames_path: str
    roles_path: str
    frames: int
    reparsed: int
    kept: int
    cached: bool


def code_fingerprint() -> str:
    """Hash of the SRL code and lexicon: a change to either re-parses every shard."""
    digest = hashlib.sha256()
    for path in sorted(SRL_CODE.glob("*.py")) + list(LEXICON_FILES):
        digest.update(path.name.encode() + path.read_bytes())
    return digest.hexdigest()


def build_fingerprint(con: duckdb.DuckDBPyConnection, config: FrameCorpusConfig, compounds_path: Path) -> str:
    """Everything a frame corpus depends on: ingested files, settings, SRL code, learned compounds."""
    files = con.execute("select source_file, sha256, corpus from ingested_files order by all").fetchall()
    digest = hashlib.sha256(repr((files, config.kinds, config.shard_size, config.model)).encode())
    digest.update(code_fingerprint().encode())
    digest.update(compounds_path.read_bytes() if compounds_path.exists() else b"")
    return digest.hexdigest()


def export_shards(con: duckdb.DuckDBPyConnection, config: FrameCorpusConfig, out_dir: Path) -> list[Shard]:
    """Write the distinct sentence texts to parse, each with all its occurrences, as numbered Parquet
    shards in a deterministic order (recipe text repeats: "Serve.", "Preheat oven to 350 F.")."""
    out_dir.mkdir(parents=True, exist_ok=True)
    con.execute(
        "create or replace temp table _frame_texts as "
        "select text, list({'corpus': corpus, 'doc_id': doc_id, 'sent_id': sent_id} "
        "                  order by corpus, doc_id, sent_id) as occurrences, "
        "       min(corpus || '/' || doc_id || '/' || lpad(sent_id::varchar, 6, '0')) as first_key, "
        "       sum(n_words)::bigint as words "
        "from sentences where list_contains(?, kind) group by text", [list(config.kinds)],
    )
    con.execute("create or replace temp table _frame_input as select *, "
                "(row_number() over (order by first_key, text) - 1) // ? as shard from _frame_texts",
                [config.shard_size])
    stats = con.execute(
        "select shard, sum(len(occurrences)), sum(words), md5(string_agg(first_key || '#' || text, '\n' "
        "order by first_key, text)) from _frame_input group by shard order by shard"
    ).fetchall()
    shards = []
    for number, count, words, md5 in stats:
        path = out_dir / f"texts-{md5}.parquet"
        if not path.exists():
            with atomic_path(path) as tmp:
                con.execute(f"copy (select text, occurrences from _frame_input where shard = {int(number)} "
                            f"order by first_key, text) to '{tmp}' (format parquet)")
        shards.append(Shard(int(number), str(path), md5, int(count), int(words)))
    con.execute("drop table _frame_input")
    con.execute("drop table _frame_texts")
    return shards


@lru_cache(maxsize=2)
def _worker_parser(model: str | None, compounds_path: str) -> FrameParser:
    # Workers parse without role priors: those are learned from this very corpus at load time.
    compounds = Compounds.load(Path(compounds_path)) if Path(compounds_path).exists() else None
    return FrameParser(load_nlp(model), compounds=compounds)


def frame_rows(corpus: str, doc_id: str, sent_id: int, frames: list[FrameMention]) -> tuple[list[dict], list[dict]]:
    """Table rows for the frames of one sentence."""
    frame_rows, role_rows = [], []
    for number, frame in enumerate(frames):
        key = {"corpus": corpus, "doc_id": doc_id, "sent_id": sent_id, "frame_no": number}
        frame_rows.append({**key, "predicate": frame.predicate, "known": frame.known, "pred_start": frame.start,
                           "pred_end": frame.end, "ambiguous_role": frame.ambiguous_object,
                           "resolved_by_prior": False})
        for role, value in frame.roles.items():
            start, end = frame.spans.get(role, (None, None))
            role_rows.append({**key, "role": role, "value": value, "span_start": start, "span_end": end})
    return frame_rows, role_rows


def parse_shard(shard: Shard, out_dir: str, model: str | None, compounds_path: str) -> ShardResult:
    """Parse one shard into frame and role Parquet files (reused when already parsed by this code)."""
    tag = f"{shard.fingerprint}-{code_fingerprint()[:12]}"
    frames_path, roles_path = Path(out_dir) / f"frames-{tag}.parquet", Path(out_dir) / f"roles-{tag}.parquet"
    if frames_path.exists() and roles_path.exists():
        n = pq.read_metadata(frames_path).num_rows
        return ShardResult(shard, str(frames_path), str(roles_path), n, 0, 0, cached=True)
    parser = _worker_parser(model, compounds_path)
    before = (parser.stats.reparsed, parser.stats.accepted)
    table = pq.read_table(shard.path).to_pylist()
    all_frames, all_roles = [], []
    for row, found in zip(table, parser.pipe(r["text"] for r in table)):
        for where in row["occurrences"]:  # one parse, frames for every sentence with this text
            f_rows, r_rows = frame_rows(where["corpus"], where["doc_id"], where["sent_id"], found)
            all_frames += f_rows
            all_roles += r_rows
    write_parquet_atomic(all_roles, ROLE_SCHEMA, roles_path)
    write_parquet_atomic(all_frames, FRAME_SCHEMA, frames_path)
    return ShardResult(shard, str(frames_path), str(roles_path), len(all_frames),
                       parser.stats.reparsed - before[0], parser.stats.accepted - before[1], cached=False)


_PRIOR_COUNTS = """
select f.predicate, r.value, r.role, count(*)
from frames f join frame_roles r using (corpus, doc_id, sent_id, frame_no)
where f.known and list_contains(?, f.predicate) and f.ambiguous_role is null
  and not exists (select 1 from frame_roles m
                  where m.corpus = f.corpus and m.doc_id = f.doc_id and m.sent_id = f.sent_id
                    and m.frame_no = f.frame_no and m.value is null)
group by all
"""


def learn_priors(con: duckdb.DuckDBPyConnection) -> RolePriors:
    """Role preferences from fully specified, syntactically unambiguous alternating-verb frames."""
    alternating = [name for name, spec in load_lexicon().predicates.items() if spec.alternating]
    priors = RolePriors()
    for verb, value, role, n in con.execute(_PRIOR_COUNTS, [alternating]).fetchall():
        priors.by_verb[(verb, value, role)] += n
        priors.pooled[(value, role)] += n
    return priors


def resolve_ambiguous(con: duckdb.DuckDBPyConnection, priors: RolePriors) -> int:
    """Move lone objects of alternating verbs to the role the priors prefer; return how many moved."""
    rows = con.execute(
        "select f.corpus, f.doc_id, f.sent_id, f.frame_no, f.predicate, f.ambiguous_role, r.role, r.value "
        "from frames f join frame_roles r using (corpus, doc_id, sent_id, frame_no) "
        "where f.known and f.ambiguous_role is not null order by all"
    ).fetchall()
    frames: dict[tuple, FrameMention] = {}
    for corpus, doc_id, sent_id, frame_no, predicate, ambiguous, role, value in rows:
        frame = frames.setdefault((corpus, doc_id, sent_id, frame_no), FrameMention(predicate, {}, True, 0, 0, {}, ambiguous))
        frame.roles[role] = value
    lex = load_lexicon()
    flipped = []
    for key, frame in frames.items():
        roles = lex.predicates[frame.predicate].roles
        frame.roles = {r: frame.roles.get(r) for r in roles}
        if priors.resolve(frame).roles != frame.roles:
            flipped.append((*key, frame.ambiguous_object, next(r for r in roles if r != frame.ambiguous_object)))
    if flipped:
        con.execute("create or replace temp table _flipped (corpus varchar, doc_id varchar, sent_id integer, "
                    "frame_no integer, default_role varchar, other_role varchar)")
        con.executemany("insert into _flipped values (?, ?, ?, ?, ?, ?)", flipped)
        # Both role rows swap names: the value moves to the other role, the null to the default one.
        con.execute(
            "update frame_roles set role = case when frame_roles.role = x.default_role then x.other_role "
            "else x.default_role end from _flipped x where frame_roles.corpus = x.corpus "
            "and frame_roles.doc_id = x.doc_id and frame_roles.sent_id = x.sent_id and frame_roles.frame_no = x.frame_no"
        )
        con.execute("update frames set resolved_by_prior = true from _flipped x where frames.corpus = x.corpus "
                    "and frames.doc_id = x.doc_id and frames.sent_id = x.sent_id and frames.frame_no = x.frame_no")
        con.execute("drop table _flipped")
    return len(flipped)


def load_frames(con: duckdb.DuckDBPyConnection, results: list[ShardResult], build: dict) -> RolePriors:
    """Replace the frame tables with the parsed shards, resolve ambiguous objects, record the build:
    one transaction, so a failure leaves the previous corpus in place."""
    with transaction(con):
        con.execute("delete from frame_roles")
        con.execute("delete from frames")
        if results:
            con.execute("insert into frames select * from read_parquet(?)", [[r.frames_path for r in results]])
            con.execute("insert into frame_roles select * from read_parquet(?)", [[r.roles_path for r in results]])
        priors = learn_priors(con)
        resolve_ambiguous(con, priors)
        known = con.execute("select count(*) filter (where known), count(*) from frames").fetchone()
        con.execute("delete from frame_builds where fingerprint = ?", [build["fingerprint"]])
        con.execute(
            "insert into frame_builds (fingerprint, kinds, shards, sentences, words, frames, known_frames, reparsed,"
            " reparse_kept, wall_s, words_per_s) values (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            [build["fingerprint"], ",".join(build["kinds"]), len(results), build["sentences"], build["words"],
             known[1], known[0], build["reparsed"], build["kept"], build["wall_s"], build["words_per_s"]],
        )
    return priors


def last_build(con: duckdb.DuckDBPyConnection) -> str | None:
    row = con.execute("select fingerprint from frame_builds order by built_at desc limit 1").fetchone()
    return row[0] if row else None


def prepare_build(
    con: duckdb.DuckDBPyConnection, staging: Path, srl_dir: Path, config: FrameCorpusConfig
) -> tuple[str, list[Shard]] | None:
    """Learn compounds, fingerprint the build, and export shards; None when the corpus is unchanged."""
    compounds_path = srl_dir / COMPOUNDS_FILE
    learn_compounds(con).save(compounds_path)
    fingerprint = build_fingerprint(con, config, compounds_path)
    if last_build(con) == fingerprint:
        return None
    return fingerprint, export_shards(con, config, staging / "frames" / "input")


def shard_output_dir(staging: Path) -> str:
    path = staging / "frames" / "output"
    path.mkdir(parents=True, exist_ok=True)
    return str(path)


def summarize_build(fingerprint: str, config: FrameCorpusConfig, results: list[ShardResult], wall: float) -> dict:
    """The build record: sizes, re-parse counts, and words/s over the shards parsed (not cached)."""
    parsed_words = sum(r.shard.words for r in results if not r.cached)
    return {"fingerprint": fingerprint, "kinds": config.kinds, "sentences": sum(r.shard.sentences for r in results),
            "words": sum(r.shard.words for r in results), "reparsed": sum(r.reparsed for r in results),
            "kept": sum(r.kept for r in results), "wall_s": round(wall, 2),
            "words_per_s": round(parsed_words / wall, 1) if parsed_words else 0.0}


def finish_build(con: duckdb.DuckDBPyConnection, srl_dir: Path, results: list[ShardResult], build: dict) -> None:
    """Load the shards (one transaction) and publish the learned role priors beside the compounds."""
    results = sorted(results, key=lambda r: r.shard.number)
    load_frames(con, results, build).save(srl_dir / PRIORS_FILE)


def build_frame_corpus(
    con: duckdb.DuckDBPyConnection,
    staging: Path,
    srl_dir: Path,
    config: FrameCorpusConfig = FrameCorpusConfig(),
    workers: int = 2,
    on_shard: Callable[[ShardResult], None] | None = None,
) -> dict | None:
    """Build (or skip, when unchanged) the frame corpus; return the build record, None if skipped."""
    prepared = prepare_build(con, staging, srl_dir, config)
    if prepared is None:
        return None
    fingerprint, shards = prepared
    out_dir, compounds = shard_output_dir(staging), str(srl_dir / COMPOUNDS_FILE)
    started = time.perf_counter()
    results = []
    with ProcessPoolExecutor(max_workers=max(1, workers)) as pool:
        futures = [pool.submit(parse_shard, s, out_dir, config.model, compounds) for s in shards]
        for future in as_completed(futures):
            results.append(future.result())
            if on_shard:
                on_shard(results[-1])
    build = summarize_build(fingerprint, config, results, time.perf_counter() - started)
    finish_build(con, srl_dir, results, build)
    return build
