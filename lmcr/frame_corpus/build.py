"""The frames stage: choose the parsing resources, export the texts not yet parsed as shards, parse them on
some worker pool, load the store.

The resources are the learned compounds and first-word table. A build keeps the ones the last build
published while the texts they have not parsed are at most `config.reuse_share` of the corpus; otherwise
it learns both anew, which makes a new parser setup under which every text is parsed. Either way only the
texts not yet parsed under the build's setup are parsed (`shards`), and the load joins every text parsed
under it with the current sentences, so a removed file's frames go and a returning text is not parsed
again.

`build_frame_corpus` runs the steps once; what differs between the CLI (a process pool with a progress
bar) and the Prefect flow (a task per shard on its task runner) is only `parse_all`, the function that
parses a list of shards. A build is skipped when its fingerprint (ingested files, settings, SRL code,
published resources) matches the last one.
"""

from __future__ import annotations

import shutil
import time
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

import duckdb

from lmcr.files import ResourceError, atomic_path, file_sha256
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.frame_corpus.load import last_build, load_frames
from lmcr.frame_corpus.predicates import refresh_predicates
from lmcr.frame_corpus.shards import (
    CorpusSize,
    Shard,
    ShardJob,
    ShardResult,
    build_fingerprint,
    export_shards,
    first_word_sample,
    frame_texts,
    learn_first_words,
    parse_shard,
    parsed_dir,
    parser_setup,
    unparsed_count,
)
from lmcr.lexicon import Lexicon, load_lexicon
from lmcr.srl.compounds import Compounds, learn_compounds
from lmcr.srl.parser import COMPOUNDS_FILE, FIRST_WORDS_FILE, PRIORS_FILE, read_first_words

# Parses every shard of a build (in any order), each with `parse_shard(shard, job)`.
ParseAll = Callable[[list[Shard], ShardJob], Iterable[ShardResult]]


@dataclass(frozen=True)
class PreparedBuild:
    """A build ready to parse: its fingerprint and parser setup, the workers' job, the shards of texts not
    yet parsed under that setup, whether the last build's resources were kept, and the corpus's size."""

    fingerprint: str
    setup: str
    job: ShardJob
    shards: list[Shard]
    reused: bool
    corpus: CorpusSize


def published_setup(srl_dir: Path, config: FrameCorpusConfig) -> str | None:
    """The parser setup of the compounds and first-word table the last build published; None when either
    is missing or cannot be read."""
    compounds, first_words = srl_dir / COMPOUNDS_FILE, srl_dir / FIRST_WORDS_FILE
    try:
        Compounds.load(compounds)
        read_first_words(first_words)
    except ResourceError:
        return None
    return parser_setup(config, compounds, first_words)


def learn_resources(con: duckdb.DuckDBPyConnection, staging: Path, config: FrameCorpusConfig) -> tuple[Path, Path]:
    """Learn the compounds from the ingested sentences and the first-word table from a sample of the texts
    of `_frame_texts`; return their files."""
    folder = staging / "frames" / "resources"
    compounds = folder / COMPOUNDS_FILE
    learn_compounds(con).save(compounds)
    job = learn_first_words(
        first_word_sample(con, config.first_word_sample), ShardJob(str(folder), config.model, str(compounds))
    )
    return compounds, Path(job.first_words)


def setup_job(staging: Path, config: FrameCorpusConfig, compounds: Path, first_words: Path) -> tuple[str, ShardJob]:
    """The parser setup of these resources and the workers' job: its folder (`parsed_dir`) holds a copy of
    both, so the folder alone says how its texts were parsed."""
    setup = parser_setup(config, compounds, first_words)
    folder = parsed_dir(staging, setup)
    for source, name in ((compounds, COMPOUNDS_FILE), (first_words, FIRST_WORDS_FILE)):
        if not (folder / name).exists() or file_sha256(folder / name) != file_sha256(source):
            with atomic_path(folder / name) as tmp:
                shutil.copyfile(source, tmp)
    return setup, ShardJob(str(folder), config.model, str(folder / COMPOUNDS_FILE), str(folder / FIRST_WORDS_FILE))


def prepare_build(
    con: duckdb.DuckDBPyConnection,
    staging: Path,
    srl_dir: Path,
    config: FrameCorpusConfig,
    log: Callable[[str], None] = lambda message: None,
) -> PreparedBuild | None:
    """Choose the resources, then export the texts not yet parsed with them; None when nothing changed."""
    published = published_setup(srl_dir, config)
    if last_build(con) == build_fingerprint(con, config, published or ""):
        return None
    with frame_texts(con, config) as corpus:
        new = unparsed_count(con, parsed_dir(staging, published)) if published else corpus.texts
        reused = published is not None and new <= config.reuse_share * corpus.texts
        if reused:
            log(f"keeping the last build's compounds and first words: {new:,} of {corpus.texts:,} texts are new")
            resources = srl_dir / COMPOUNDS_FILE, srl_dir / FIRST_WORDS_FILE
        else:
            log(f"learning compounds, and first words from up to {config.first_word_sample:,} texts")
            resources = learn_resources(con, staging, config)
        setup, job = setup_job(staging, config, *resources)
        shards = export_shards(con, config, Path(job.out_dir), staging / "frames" / "input")
    return PreparedBuild(build_fingerprint(con, config, setup), setup, job, shards, reused, corpus)


def summarize_build(
    prepared: PreparedBuild, config: FrameCorpusConfig, results: list[ShardResult], wall: float
) -> dict:
    """The build record: the corpus's size, what this build parsed, and words/s over the words parsed."""
    parsed = [r for r in results if not r.cached]
    words_parsed = sum(r.shard.words for r in parsed)
    return {
        "fingerprint": prepared.fingerprint,
        "parser_setup": prepared.setup,
        "resources_reused": prepared.reused,
        "kinds": config.kinds,
        "shards": len(results),
        "sentences": prepared.corpus.sentences,
        "words": prepared.corpus.words,
        "texts": prepared.corpus.texts,
        "texts_parsed": sum(r.shard.texts for r in parsed),
        "words_parsed": words_parsed,
        "reparsed": sum(r.reparsed for r in results),
        "kept": sum(r.kept for r in results),
        "wall_s": round(wall, 2),
        "words_per_s": round(words_parsed / wall, 1) if words_parsed else 0.0,
    }


def finish_build(con: duckdb.DuckDBPyConnection, srl_dir: Path, job: ShardJob, build: dict) -> None:
    """Load every text parsed under the build's setup (one transaction), then publish the learned role
    priors and the compounds and first-word table the texts were parsed with (`load_parser` reads all
    three; the next build starts from the last two)."""
    load_frames(con, Path(job.out_dir), build).save(srl_dir / PRIORS_FILE)
    for source, name in ((job.compounds, COMPOUNDS_FILE), (job.first_words, FIRST_WORDS_FILE)):
        with atomic_path(srl_dir / name) as tmp:
            shutil.copyfile(source, tmp)


def process_pool(
    workers: int = 2,
    on_shard: Callable[[ShardResult], None] | None = None,
    on_start: Callable[[int], None] | None = None,
) -> ParseAll:
    """Parse shards on `workers` local processes, calling `on_start` with the number of shards first and
    `on_shard` as each one finishes."""

    def parse_all(shards: list[Shard], job: ShardJob) -> Iterable[ShardResult]:
        if on_start:
            on_start(len(shards))
        if not shards:
            return
        with ProcessPoolExecutor(max_workers=max(1, workers)) as pool:
            for future in as_completed([pool.submit(parse_shard, s, job) for s in shards]):
                if on_shard:
                    on_shard(future.result())
                yield future.result()

    return parse_all


def build_frame_corpus(
    con: duckdb.DuckDBPyConnection,
    staging: Path,
    srl_dir: Path,
    config: FrameCorpusConfig = FrameCorpusConfig(),
    parse_all: ParseAll | None = None,
    log: Callable[[str], None] = lambda message: None,
) -> dict | None:
    """Build (or skip, when unchanged) the frame corpus; return the build record, None if skipped.
    Shards are parsed by `parse_all` (default: two local processes)."""
    started = time.perf_counter()  # the wall time and words/s include learning the resources
    prepared = prepare_build(con, staging, srl_dir, config, log)
    if prepared is None:
        log("frame corpus unchanged: skipped")
        _learn(con, srl_dir, last_build(con), log)
        return None
    shards = prepared.shards
    log(f"parsing {len(shards)} shards of {sum(s.texts for s in shards):,} new texts")
    results = list((parse_all or process_pool())(shards, prepared.job))
    build = summarize_build(prepared, config, results, time.perf_counter() - started)
    log(f"{build['words_parsed']:,} words parsed at {build['words_per_s']:,.0f} words/s")
    finish_build(con, srl_dir, prepared.job, build)
    _learn(con, srl_dir, prepared.fingerprint, log)
    return build


def _learn(con: duckdb.DuckDBPyConnection, srl_dir: Path, build: str | None, log: Callable[[str], None]) -> None:
    """Learn the predicates of the build when it has no table yet (`frame_corpus.predicates`)."""
    table = refresh_predicates(con, load_lexicon(learned=False), srl_dir, build)
    if table is not None:
        refused = f"{len(table.refused):,} verbs refused ({Lexicon.REFUSED_BECAUSE})"
        log(f"learned {len(table.predicates):,} predicates; {refused}")
