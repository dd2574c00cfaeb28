"""Training text for each setting: corpus sentences (sentence LM) or linearised frames (frame LM)."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import duckdb

from lmcr.lexicon import load_lexicon
from lmcr.lm.data import split_by_document
from lmcr.lm.linearize import frame_text, tokens
from lmcr.setting import Setting, check_corpus


@dataclass
class TrainingText:
    """Token sequences split by document into train and validation, plus what they came from;
    `train_docs` is the document of each training sequence (a warm start picks the new ones by it)."""

    train: list[list[str]]
    val: list[list[str]]
    provenance: dict
    train_docs: list[str] = field(default_factory=list)


def _corpus_filter(corpus: str) -> str:
    check_corpus(corpus)  # it becomes part of the SQL text
    return "" if corpus == "all" else f"and s.corpus = '{corpus}'"


def sentence_sequences(
    con: duckdb.DuckDBPyConnection, corpus: str, kinds: tuple[str, ...], articles: bool = True
) -> list[tuple[str, list[str]]]:
    """The tokens of every sentence of `kinds` in `corpus` (`all`: every corpus), with its document."""
    rows = con.execute(
        f"select s.doc_id, s.text from sentences s where list_contains(?, s.kind) {_corpus_filter(corpus)} "
        "order by s.corpus, s.doc_id, s.sent_id",
        [list(kinds)],
    ).fetchall()
    return [(doc, tokens(text, articles)) for doc, text in rows]


def frame_sequences(con: duckdb.DuckDBPyConnection, corpus: str) -> list[tuple[str, list[str]]]:
    """Every frame with at least one role value, linearised: robot predicates in lexicon role order,
    generic frames in the order their arguments appear in the sentence."""
    rows = con.execute(
        "select s.doc_id, s.predicate, list(r.role order by r.span_start), list(r.value order by r.span_start) "
        "from frames s join frame_roles r using (corpus, doc_id, sent_id, frame_no) "
        f"where r.value is not null {_corpus_filter(corpus)} "
        "group by s.corpus, s.doc_id, s.sent_id, s.frame_no, s.predicate "
        "order by s.corpus, s.doc_id, s.sent_id, s.frame_no"
    ).fetchall()
    lex = load_lexicon()
    return [(doc, tokens(frame_text(pred, dict(zip(roles, values)), lex))) for doc, pred, roles, values in rows]


def corpus_hash(con: duckdb.DuckDBPyConnection, linearization: str) -> str:
    """Content hash of what the text came from: the ingested files, and the frame build for frames."""
    files = con.execute("select source_file, sha256 from ingested_files order by all").fetchall()
    build = con.execute("select fingerprint from frame_builds order by built_at desc limit 1").fetchone()
    return hashlib.sha256(repr((files, build if linearization == "frame" else None)).encode()).hexdigest()


def training_text(
    con: duckdb.DuckDBPyConnection, setting: Setting, kinds: tuple[str, ...] = ("instruction",), articles: bool = True
) -> TrainingText:
    """The setting's sequences (its linearisation of its corpus), split by document (5% held out); without
    `articles`, sentences lose a/an/the (frames have none)."""
    linearization = setting.linearization
    pairs = (
        sentence_sequences(con, setting.corpus, kinds, articles)
        if linearization == "sentence"
        else frame_sequences(con, setting.corpus)
    )
    pairs = [(doc, seq) for doc, seq in pairs if len(seq) >= 2]
    held = split_by_document([doc for doc, _ in pairs])
    return TrainingText(
        train=[seq for (_, seq), h in zip(pairs, held) if not h],
        val=[seq for (_, seq), h in zip(pairs, held) if h],
        train_docs=[doc for (doc, _), h in zip(pairs, held) if not h],
        provenance={
            "linearization": linearization,
            "corpus": setting.corpus,
            "kinds": list(kinds) if linearization == "sentence" else "frames",
            "corpus_sha256": corpus_hash(con, linearization),
        },
    )
