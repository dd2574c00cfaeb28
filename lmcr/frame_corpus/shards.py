"""Frame shards: the distinct sentence texts not yet parsed, cut into Parquet shards, each parsed by a worker.

Parse results are kept per text, not per sentence. A worker writes the frames and roles of each text,
keyed by `text_key` (the md5 of the text), into the folder of its parser setup, with the list of the
texts it parsed (`parsed_dir`); the load joins them with the sentences of the moment. So a build parses
only the texts no earlier build parsed under the same setup, and workers never open the store.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

import duckdb
import pyarrow as pa
import pyarrow.parquet as pq

from lmcr.files import atomic_path, cached_json, file_sha256
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.ingest.stage import write_parquet_atomic
from lmcr.lexicon import LEXICON_FILES
from lmcr.srl.compounds import Compounds
from lmcr.srl.mentions import FrameMention
from lmcr.srl.parser import FrameParser, is_first_word_table, load_nlp, read_first_words

SRL_CODE = Path(__file__).parent.parent / "srl"
FRAME_SCHEMA = pa.schema(
    [
        ("text_key", pa.string()),
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
        ("text_key", pa.string()),
        ("frame_no", pa.int32()),
        ("role", pa.string()),
        ("value", pa.string()),
        ("span_start", pa.int32()),
        ("span_end", pa.int32()),
    ]
)
TEXT_SCHEMA = pa.schema([("text_key", pa.string())])
# Texts per `FrameParser.pipe` batch. Within one batch the first-word table only decides, at its start,
# which texts are parsed as requests at once; so a batch that starts from the job's table gives each text
# the frames that table and the text alone decide, whichever texts the worker parsed before.
PARSE_CHUNK = 2048


@dataclass(frozen=True)
class Shard:
    """Distinct sentence texts to parse, and their words (each text counted once)."""

    number: int
    path: str
    fingerprint: str
    texts: int
    words: int


@dataclass(frozen=True)
class ShardJob:
    """What every worker of one build shares: the folder of its parser setup (`parsed_dir`), which model,
    which learned compounds, and the first-word table every text starts from (`learn_first_words`; ""
    for none)."""

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


@dataclass(frozen=True)
class CorpusSize:
    """The frame corpus of the configured kinds: its sentences and words (every occurrence), and its
    distinct texts (what is parsed)."""

    sentences: int
    words: int
    texts: int


def _file_hash(path: str | Path) -> str:
    return file_sha256(Path(path)) if path and Path(path).is_file() else ""


def code_fingerprint() -> str:
    """Hash of the SRL code and lexicon: a change to either re-parses every text."""
    digest = hashlib.sha256()
    for path in sorted(SRL_CODE.glob("*.py")) + [Path(__file__)] + list(LEXICON_FILES):
        digest.update(path.name.encode() + path.read_bytes())
    return digest.hexdigest()


def _parser_setup(job: ShardJob) -> str:
    """What a parser is made of before its first-word table: the SRL code, the spaCy model, the compounds."""
    return f"{code_fingerprint()}|{job.model}|{_file_hash(job.compounds)}"


def parser_setup(config: FrameCorpusConfig, compounds: Path, first_words: Path) -> str:
    """Hash of everything a text's frames depend on (SRL code, spaCy model, learned compounds, first-word
    table) and of the settings the two resources were learned under (kinds, first-word sample)."""
    job = ShardJob("", config.model, str(compounds))
    recipe = repr((config.kinds, config.first_word_sample))
    return hashlib.sha256(f"{_parser_setup(job)}|{_file_hash(first_words)}|{recipe}".encode()).hexdigest()


def parsed_dir(staging: Path, setup: str) -> Path:
    """The folder of a parser setup: its resources and every text parsed under it."""
    return staging / "frames" / "parsed" / setup[:16]


def build_fingerprint(con: duckdb.DuckDBPyConnection, config: FrameCorpusConfig, setup: str) -> str:
    """Everything a frame corpus depends on: ingested files, settings, SRL code, the parser setup."""
    files = con.execute("select source_file, sha256, corpus from ingested_files order by all").fetchall()
    digest = hashlib.sha256(
        repr((files, config.kinds, config.shard_size, config.model, config.first_word_sample)).encode()
    )
    digest.update(code_fingerprint().encode())
    digest.update(setup.encode())
    return digest.hexdigest()


@contextmanager
def frame_texts(con: duckdb.DuckDBPyConnection, config: FrameCorpusConfig) -> Iterator[CorpusSize]:
    """The distinct texts of the configured kinds as the temp table `_frame_texts` while the block runs,
    in a deterministic order (`first_key`, then the text): recipe text repeats ("Serve.", "Preheat oven to
    350 F."), and each text is parsed once."""
    con.execute(
        "create or replace temp table _frame_texts as "
        "select md5(text) as text_key, text, "
        "       min(corpus || '/' || doc_id || '/' || lpad(sent_id::varchar, 6, '0')) as first_key, "
        "       any_value(n_words)::bigint as words, count(*)::bigint as sentences, "
        "       sum(n_words)::bigint as all_words "
        "from sentences where list_contains(?, kind) group by text",
        [list(config.kinds)],
    )
    try:
        sentences, words, texts = con.execute(
            "select coalesce(sum(sentences), 0), coalesce(sum(all_words), 0), count(*) from _frame_texts"
        ).fetchone()
        yield CorpusSize(int(sentences), int(words), int(texts))
    finally:
        con.execute("drop table if exists _frame_texts")


def parsed_texts(folder: Path) -> list[str]:
    """The text lists of the shards parsed in a setup's folder: a shard counts once its list is written."""
    return [str(p) for p in sorted(folder.glob("texts-*.parquet"))]


def _unparsed(folder: Path) -> str:
    """`_frame_texts` less the texts parsed in `folder`, as SQL."""
    done = parsed_texts(folder)
    if not done:
        return "select * from _frame_texts"
    files = ", ".join("'" + path.replace("'", "''") + "'" for path in done)
    return f"select * from _frame_texts anti join read_parquet([{files}]) using (text_key)"


def unparsed_count(con: duckdb.DuckDBPyConnection, folder: Path) -> int:
    """Distinct texts of `_frame_texts` not yet parsed under the setup of `folder`."""
    return int(con.execute(f"select count(*) from ({_unparsed(folder)})").fetchone()[0])


def export_shards(
    con: duckdb.DuckDBPyConnection, config: FrameCorpusConfig, folder: Path, out_dir: Path
) -> list[Shard]:
    """Write the texts of `_frame_texts` not yet parsed under the setup of `folder` as numbered Parquet
    shards of `shard_size` texts, in the deterministic order, each named by its texts."""
    out_dir.mkdir(parents=True, exist_ok=True)
    con.execute(
        "create or replace temp table _frame_input as select *, "
        f"(row_number() over (order by first_key, text) - 1) // ? as shard from ({_unparsed(folder)})",
        [config.shard_size],
    )
    try:
        stats = con.execute(
            "select shard, count(*), sum(words), md5(string_agg(text_key, ',' order by first_key, text)) "
            "from _frame_input group by shard order by shard"
        ).fetchall()
        shards = []
        for number, count, words, md5 in stats:
            path = out_dir / f"input-{md5}.parquet"
            if not path.exists():
                with atomic_path(path) as tmp:
                    con.execute(
                        f"copy (select text_key, text from _frame_input where shard = {int(number)} "
                        f"order by first_key, text) to '{tmp}' (format parquet)"
                    )
            shards.append(Shard(int(number), str(path), md5, int(count), int(words)))
        return shards
    finally:
        con.execute("drop table _frame_input")


def first_word_sample(con: duckdb.DuckDBPyConnection, sample: int) -> list[str]:
    """Every k-th text of `_frame_texts` in its order, about `sample` texts spread over the corpus."""
    total = con.execute("select count(*) from _frame_texts").fetchone()[0]
    step = max(1, -(-total // max(1, sample)))
    return [
        text
        for (text,) in con.execute(
            "select text from (select text, row_number() over (order by first_key, text) - 1 as i "
            "from _frame_texts) where i % ? = 0 order by i",
            [step],
        ).fetchall()
    ]


@lru_cache(maxsize=2)
def _worker_parser(model: str | None, compounds_path: str, compounds_hash: str) -> FrameParser:
    # Workers parse without role priors: those are learned from this very corpus at load time. The hash
    # keys the cache, so a process that outlives a build never parses with stale compounds.
    compounds = Compounds.load(Path(compounds_path)) if compounds_hash else None
    return FrameParser(load_nlp(model), compounds=compounds, learn_first_words=True)


def _parser(job: ShardJob) -> FrameParser:
    return _worker_parser(job.model, job.compounds, _file_hash(job.compounds))


def learn_first_words(texts: list[str], job: ShardJob) -> ShardJob:
    """`job` with the first-word table every text starts from: which words start texts as commands,
    learned by one parser from `texts` (a sample spread over the corpus, `first_word_sample`) and kept as
    JSON in `job.out_dir`, named by the texts and the parsing setup, so it is not learned twice. Learned
    once, up front, because a worker that carried its table from text to text made each text's frames
    depend on the texts it happened to parse before."""
    key = hashlib.sha256("\n".join([_parser_setup(job), *texts]).encode())
    path = Path(job.out_dir) / f"first-words-{key.hexdigest()[:24]}.json"

    def learn() -> dict[str, tuple[int, int, int]]:
        parser = _parser(job)
        parser.forget_first_words()
        for _ in parser.pipe(texts):
            pass
        return dict(sorted(parser.first_words.items()))

    cached_json(path, is_first_word_table, learn)  # a damaged file is learned again, not trusted
    return replace(job, first_words=str(path))


def frame_rows(text_key: str, frames: list[FrameMention]) -> tuple[list[dict], list[dict]]:
    """Frame and role rows of one text's frames."""
    frame_rows, role_rows = [], []
    for number, frame in enumerate(frames):
        key = {"text_key": text_key, "frame_no": number}
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


def shard_outputs(shard: Shard, job: ShardJob) -> tuple[Path, Path, Path]:
    """Where a shard's frames, roles and text list go: the setup's folder, named by the shard's texts."""
    out = Path(job.out_dir)
    return tuple(out / f"{kind}-{shard.fingerprint}.parquet" for kind in ("frames", "roles", "texts"))


def parse_shard(shard: Shard, job: ShardJob) -> ShardResult:
    """Parse one shard into frame and role Parquet keyed by text, then write the list of its texts (which
    marks the shard parsed); a shard whose list exists is not parsed again."""
    frames_path, roles_path, texts_path = shard_outputs(shard, job)
    if texts_path.exists():
        n = pq.read_metadata(frames_path).num_rows
        return ShardResult(shard, str(frames_path), str(roles_path), n, 0, 0, cached=True)
    parser = _parser(job)
    start = read_first_words(Path(job.first_words)) if job.first_words else None
    before = (parser.stats.reparsed, parser.stats.accepted)
    table = pq.read_table(shard.path)
    keys, texts = table.column("text_key").to_pylist(), table.column("text").to_pylist()
    all_frames, all_roles = [], []
    for i in range(0, len(texts), PARSE_CHUNK):
        parser.forget_first_words(start)  # each batch from the job's table: frames that depend on the text alone
        for key, found in zip(keys[i : i + PARSE_CHUNK], parser.pipe(texts[i : i + PARSE_CHUNK], PARSE_CHUNK)):
            f_rows, r_rows = frame_rows(key, found)
            all_frames += f_rows
            all_roles += r_rows
    write_parquet_atomic(all_roles, ROLE_SCHEMA, roles_path)
    write_parquet_atomic(all_frames, FRAME_SCHEMA, frames_path)
    write_parquet_atomic([{"text_key": key} for key in keys], TEXT_SCHEMA, texts_path)
    return ShardResult(
        shard,
        str(frames_path),
        str(roles_path),
        len(all_frames),
        parser.stats.reparsed - before[0],
        parser.stats.accepted - before[1],
        cached=False,
    )
