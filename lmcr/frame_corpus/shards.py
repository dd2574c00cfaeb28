"""Frame shards: the ingested sentences cut into Parquet shards, each parsed to frame rows by a worker.

Workers never open the store: they read a shard of distinct sentence texts (with every occurrence)
and write frame and role Parquet, named by the shard's content and the parsing code, so an
unchanged shard is never parsed twice.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

import duckdb
import pyarrow as pa
import pyarrow.parquet as pq

from lmcr.files import atomic_path, cached_json
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.ingest.stage import write_parquet_atomic
from lmcr.lexicon import LEXICON_FILES
from lmcr.srl.compounds import Compounds
from lmcr.srl.mentions import FrameMention
from lmcr.srl.parser import FrameParser, is_first_word_table, load_nlp, read_first_words

SRL_CODE = Path(__file__).parent.parent / "srl"
FRAME_SCHEMA = pa.schema(
    [
        ("corpus", pa.string()),
        ("doc_id", pa.string()),
        ("sent_id", pa.int32()),
        ("frame_no", pa.int32()),
        ("predicate", pa.string()),
        ("known", pa.bool_()),
        ("pred_start", pa.int32()),
        ("pred_end", pa.int32()),
        ("ambiguous_role", pa.string()),
        ("resolved_by_prior", pa.bool_()),
    ]
)
ROLE_SCHEMA = pa.schema(
    [
        ("corpus", pa.string()),
        ("doc_id", pa.string()),
        ("sent_id", pa.int32()),
        ("frame_no", pa.int32()),
        ("role", pa.string()),
        ("value", pa.string()),
        ("span_start", pa.int32()),
        ("span_end", pa.int32()),
    ]
)


@dataclass(frozen=True)
class Shard:
    """Distinct sentence texts to parse; `sentences` and `words` count every occurrence."""

    number: int
    path: str
    fingerprint: str
    sentences: int
    words: int


@dataclass(frozen=True)
class ShardJob:
    """What every worker of one build shares: where to write, which model, which learned compounds, and
    the first-word table every shard starts from (`learn_first_words`; "" for none)."""

    out_dir: str
    model: str | None
    compounds: str
    first_words: str = ""


@dataclass(frozen=True)
class ShardResult:
    shard: Shard
    frames_path: str
    roles_path: str
    frames: int
    reparsed: int
    kept: int
    cached: bool


def _file_hash(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest() if Path(path).exists() else ""


def code_fingerprint() -> str:
    """Hash of the SRL code and lexicon: a change to either re-parses every shard."""
    digest = hashlib.sha256()
    for path in sorted(SRL_CODE.glob("*.py")) + [Path(__file__)] + list(LEXICON_FILES):
        digest.update(path.name.encode() + path.read_bytes())
    return digest.hexdigest()


def _parser_setup(job: ShardJob) -> str:
    """What a worker's parser is made of: the SRL code, the spaCy model, the learned compounds."""
    return f"{code_fingerprint()}|{job.model}|{_file_hash(job.compounds)}"


def build_fingerprint(con: duckdb.DuckDBPyConnection, config: FrameCorpusConfig, compounds_path: Path) -> str:
    """Everything a frame corpus depends on: ingested files, settings, SRL code, learned compounds."""
    files = con.execute("select source_file, sha256, corpus from ingested_files order by all").fetchall()
    digest = hashlib.sha256(
        repr((files, config.kinds, config.shard_size, config.model, config.first_word_sample)).encode()
    )
    digest.update(code_fingerprint().encode())
    digest.update(_file_hash(compounds_path).encode())
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
        "from sentences where list_contains(?, kind) group by text",
        [list(config.kinds)],
    )
    con.execute(
        "create or replace temp table _frame_input as select *, "
        "(row_number() over (order by first_key, text) - 1) // ? as shard from _frame_texts",
        [config.shard_size],
    )
    stats = con.execute(
        "select shard, sum(len(occurrences)), sum(words), md5(string_agg(first_key || '#' || text, '\n' "
        "order by first_key, text)) from _frame_input group by shard order by shard"
    ).fetchall()
    shards = []
    for number, count, words, md5 in stats:
        path = out_dir / f"texts-{md5}.parquet"
        if not path.exists():
            with atomic_path(path) as tmp:
                con.execute(
                    f"copy (select text, occurrences from _frame_input where shard = {int(number)} "
                    f"order by first_key, text) to '{tmp}' (format parquet)"
                )
        shards.append(Shard(int(number), str(path), md5, int(count), int(words)))
    con.execute("drop table _frame_input")
    con.execute("drop table _frame_texts")
    return shards


@lru_cache(maxsize=2)
def _worker_parser(model: str | None, compounds_path: str) -> FrameParser:
    # Workers parse without role priors: those are learned from this very corpus at load time.
    compounds = Compounds.load(Path(compounds_path)) if Path(compounds_path).exists() else None
    return FrameParser(load_nlp(model), compounds=compounds, learn_first_words=True)


def learn_first_words(shards: list[Shard], job: ShardJob, sample: int) -> ShardJob:
    """`job` with the first-word table its shards start from: which words start texts as commands,
    learned by one parser from every k-th text of the build (about `sample` texts, spread over the
    corpus) and kept as JSON beside the shard outputs, named by the sample and the parsing setup, so an
    unchanged build does not learn it again. Learned once, up front, because a worker that carried its
    table from shard to shard made each shard's frames depend on the shards it happened to parse before
    (two builds of the same corpus differed by about 55 frames)."""
    texts = [t for shard in shards for t in pq.read_table(shard.path, columns=["text"]).column("text").to_pylist()]
    chosen = texts[:: max(1, -(-len(texts) // max(1, sample)))]
    key = hashlib.sha256("\n".join([_parser_setup(job), *chosen]).encode())
    path = Path(job.out_dir) / f"first-words-{key.hexdigest()[:24]}.json"

    def learn() -> dict[str, tuple[int, int, int]]:
        parser = _worker_parser(job.model, job.compounds)
        parser.forget_first_words()
        for _ in parser.pipe(chosen):
            pass
        return dict(sorted(parser.first_words.items()))

    cached_json(path, is_first_word_table, learn)  # a damaged file is learned again, not trusted
    return replace(job, first_words=str(path))


def frame_rows(corpus: str, doc_id: str, sent_id: int, frames: list[FrameMention]) -> tuple[list[dict], list[dict]]:
    """Table rows for the frames of one sentence."""
    frame_rows, role_rows = [], []
    for number, frame in enumerate(frames):
        key = {"corpus": corpus, "doc_id": doc_id, "sent_id": sent_id, "frame_no": number}
        frame_rows.append(
            {
                **key,
                "predicate": frame.predicate,
                "known": frame.known,
                "pred_start": frame.start,
                "pred_end": frame.end,
                "ambiguous_role": frame.ambiguous_object,
                "resolved_by_prior": False,
            }
        )
        for role, value in frame.roles.items():
            start, end = frame.spans.get(role, (None, None))
            role_rows.append({**key, "role": role, "value": value, "span_start": start, "span_end": end})
    return frame_rows, role_rows


def parse_shard(shard: Shard, job: ShardJob) -> ShardResult:
    """Parse one shard into frame and role Parquet files (reused when already parsed by this code, model
    and compounds)."""
    first_words = _file_hash(job.first_words) if job.first_words else ""
    setup = hashlib.sha256(f"{_parser_setup(job)}|{first_words}".encode()).hexdigest()
    tag = f"{shard.fingerprint}-{setup[:12]}"
    out = Path(job.out_dir)
    frames_path, roles_path = out / f"frames-{tag}.parquet", out / f"roles-{tag}.parquet"
    if frames_path.exists() and roles_path.exists():
        n = pq.read_metadata(frames_path).num_rows
        return ShardResult(shard, str(frames_path), str(roles_path), n, 0, 0, cached=True)
    parser = _worker_parser(job.model, job.compounds)
    # Every shard starts from the same table: its frames must not depend on which shards this worker parsed before.
    parser.forget_first_words(read_first_words(Path(job.first_words)) if job.first_words else None)
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
    return ShardResult(
        shard,
        str(frames_path),
        str(roles_path),
        len(all_frames),
        parser.stats.reparsed - before[0],
        parser.stats.accepted - before[1],
        cached=False,
    )
