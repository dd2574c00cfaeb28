"""Loading the parsed texts into the store: one transaction that replaces the frame tables (each sentence
gets the frames of its text), learns role priors from the unambiguous frames, resolves the ambiguous ones
and records the build."""

from __future__ import annotations

from pathlib import Path

import duckdb

from lmcr.frame_corpus.shards import FRAME_SCHEMA, ROLE_SCHEMA, parsed_texts
from lmcr.lexicon import load_lexicon
from lmcr.srl.mentions import FrameMention
from lmcr.srl.priors import RolePriors
from lmcr.store import insert_rows, transaction

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
    alternating = [name for name, spec in load_lexicon(learned=False).predicates.items() if spec.alternating]
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
        frame = frames.setdefault(
            (corpus, doc_id, sent_id, frame_no), FrameMention(predicate, {}, True, 0, 0, {}, ambiguous)
        )
        frame.roles[role] = value
    lex = load_lexicon(learned=False)
    flipped = []
    for key, frame in frames.items():
        roles = lex.predicates[frame.predicate].roles
        frame.roles = {r: frame.roles.get(r) for r in roles}
        if priors.resolve(frame).roles != frame.roles:
            flipped.append((*key, frame.ambiguous_object, next(r for r in roles if r != frame.ambiguous_object)))
    if flipped:
        con.execute(
            "create or replace temp table _flipped (corpus varchar, doc_id varchar, sent_id integer, "
            "frame_no integer, default_role varchar, other_role varchar)"
        )
        con.executemany("insert into _flipped values (?, ?, ?, ?, ?, ?)", flipped)
        # Both role rows swap names: the value moves to the other role, the null to the default one.
        con.execute(
            "update frame_roles set role = case when frame_roles.role = x.default_role then x.other_role "
            "else x.default_role end from _flipped x where frame_roles.corpus = x.corpus "
            "and frame_roles.doc_id = x.doc_id and frame_roles.sent_id = x.sent_id "
            "and frame_roles.frame_no = x.frame_no"
        )
        con.execute(
            "update frames set resolved_by_prior = true from _flipped x where frames.corpus = x.corpus "
            "and frames.doc_id = x.doc_id and frames.sent_id = x.sent_id and frames.frame_no = x.frame_no"
        )
        con.execute("drop table _flipped")
    return len(flipped)


def _read_parsed(con: duckdb.DuckDBPyConnection, table: str, files: list[str]) -> None:
    """Insert the rows of every sentence whose text has rows in `files` (keyed by text) into `table`."""
    columns = [name for name in (FRAME_SCHEMA if table == "frames" else ROLE_SCHEMA).names if name != "text_key"]
    con.execute(
        f"insert into {table} (corpus, doc_id, sent_id, {', '.join(columns)}) "
        f"select o.corpus, o.doc_id, o.sent_id, {', '.join('p.' + c for c in columns)} "
        "from read_parquet(?) p join _frame_occurrences o using (text_key)",
        [files],
    )


def load_frames(con: duckdb.DuckDBPyConnection, parsed: Path, build: dict) -> RolePriors:
    """Replace the frame tables with the frames of every sentence of the build's kinds, from the texts
    parsed in the setup's folder `parsed`; resolve ambiguous objects; record the build: one transaction,
    so a failure leaves the previous corpus in place."""
    shards = [Path(path).name.removeprefix("texts-") for path in parsed_texts(parsed)]
    with transaction(con):
        con.execute("delete from frame_roles")
        con.execute("delete from frames")
        if shards:
            con.execute(
                "create or replace temp table _frame_occurrences as select corpus, doc_id, sent_id, "
                "md5(text) as text_key from sentences where list_contains(?, kind)",
                [list(build["kinds"])],
            )
            _read_parsed(con, "frames", [str(parsed / f"frames-{name}") for name in shards])
            _read_parsed(con, "frame_roles", [str(parsed / f"roles-{name}") for name in shards])
            con.execute("drop table _frame_occurrences")
        priors = learn_priors(con)
        resolve_ambiguous(con, priors)
        known = con.execute("select count(*) filter (where known), count(*) from frames").fetchone()
        con.execute("delete from frame_builds where fingerprint = ?", [build["fingerprint"]])
        insert_rows(con, "frame_builds", [_build_row(build, known)])
    return priors


def _build_row(build: dict, known: tuple[int, int]) -> dict:
    names = ("fingerprint", "parser_setup", "resources_reused", "shards", "sentences", "words", "texts")
    names += ("texts_parsed", "words_parsed", "reparsed", "wall_s", "words_per_s")
    return {
        **{name: build[name] for name in names},
        "kinds": ",".join(build["kinds"]),
        "frames": known[1],
        "known_frames": known[0],
        "reparse_kept": build["kept"],
    }


def last_build(con: duckdb.DuckDBPyConnection) -> str | None:
    row = con.execute("select fingerprint from frame_builds order by built_at desc limit 1").fetchone()
    return row[0] if row else None
