"""Rating tasks out: choose complete frames, render them as sentences, group them into HITs with gold
checks, and write an MTurk batch input CSV, the HIT template and a local preview page.

Frame selection modes:
- `protocol` (the paper's): per verb and role, a few seeded values of that role stay fixed while the
  other role runs over the robot's object vocabulary;
- `corpus`: complete frames of the robot predicates sampled from the frame corpus;
- `disagreement` (active selection): among the protocol frames, those whose rank percentiles under the
  given scorers differ most.
Frames already rated are left out. Gold checks are frames the crowd already rated with near-unanimous
agreement (mean >= 4.67 or <= 1.33 over >= 3 ratings): their answers come from people, not from us.
"""

from __future__ import annotations

import csv
import html
import json
import random
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import duckdb
import numpy as np

from lmcr.annotate.hits import HitSettings
from lmcr.errors import LMCRError
from lmcr.files import atomic_dir, check_output_dir
from lmcr.frame import FRAME_COLUMNS, Frame
from lmcr.lexicon import load_lexicon
from lmcr.lm.linearize import sentence_text

MODES = ("protocol", "corpus", "disagreement")
FIELDS = ("frame_id", *FRAME_COLUMNS, "sentence")
TEMPLATE_DIR = Path(__file__).resolve().parents[2] / "annotation"


class HitBatchError(LMCRError, ValueError):
    """A HIT batch the options cannot build (an unknown mode, no room for items, nothing to ask about)."""


@dataclass(frozen=True)
class TaskConfig:
    mode: str = "protocol"
    per_hit: int = 10
    gold_per_hit: int = 1
    fixed_per_role: int = 1  # protocol: fixed values per verb and role
    n_frames: int | None = None  # corpus / disagreement: how many frames (default: all protocol frames)
    seed: int = 0
    batch: str = "batch"
    # the predicates asked about: the hand-written eleven by default, or any learned ones ("put away")
    verbs: tuple[str, ...] = ()


def render(frame: Frame) -> str:
    """'Pour the water into the cup.': the sentence-LM template with articles, for people."""
    verb, roles = frame
    text = sentence_text(verb, {r: f"\x00{v}" for r, v in roles.items()})
    text = re.sub(r"(?:\bthe )?\x00", "the ", text)
    return text[0].upper() + text[1:] + "."


def task_verbs(verbs: tuple[str, ...] = ()) -> list[str]:
    """The predicates a batch asks about: `verbs` (each a hand-written or learned predicate, else
    HitBatchError naming it), or the hand-written eleven."""
    lex = load_lexicon()
    unknown = [v for v in verbs if v not in lex.predicates]
    if unknown:
        raise HitBatchError(f"unknown predicate {unknown[0]!r}: not hand-written, and not learned (`lmcr predicates`)")
    return sorted(verbs) or lex.hand_written


def protocol_frames(seed: int, fixed_per_role: int, verbs: tuple[str, ...] = ()) -> list[Frame]:
    lex = load_lexicon()
    rng = random.Random(seed)
    frames = []
    for verb, spec in ((v, lex.predicates[v]) for v in task_verbs(verbs)):
        for role in spec.roles:
            for fixed in rng.sample(lex.objects, fixed_per_role):
                frames += [Frame.of(verb, {role: fixed, spec.other(role): o}) for o in lex.objects if o != fixed]
    return frames


def corpus_frames(con: duckdb.DuckDBPyConnection, n: int, seed: int, verbs: tuple[str, ...] = ()) -> list[Frame]:
    lex = load_lexicon()
    # robot_fillers names a learned predicate's slots by role, as a rating names them
    rows = con.execute(
        "select predicate, list(role order by role), list(value order by role) from robot_fillers "
        "where predicate in (select unnest(?)) group by corpus, doc_id, sent_id, frame_no, predicate "
        "having count(value) = 2 and count(distinct role) = 2 and bool_and(value not in (select unnest(?)))",
        [task_verbs(verbs), sorted(lex.object_pronouns)],
    ).fetchall()
    distinct = sorted({(p, tuple(zip(roles, values))) for p, roles, values in rows})
    picked = random.Random(seed).sample(distinct, min(n, len(distinct)))
    return [Frame(p, pairs) for p, pairs in picked]


def disagreement_frames(pool: list[Frame], scorers: dict[str, Callable], n: int) -> list[Frame]:
    """The `n` frames whose percentile ranks under the scorers have the largest spread."""
    if len(scorers) < 2:
        raise HitBatchError("disagreement selection needs at least two scoring methods")
    ranks = []
    for fn in scorers.values():
        scores = np.asarray(fn(pool))
        ranks.append(scores.argsort().argsort() / max(len(pool) - 1, 1))
    spread = np.std(np.vstack(ranks), axis=0)
    return [pool[i] for i in np.argsort(-spread, kind="stable")[:n]]


def gold_candidates(con: duckdb.DuckDBPyConnection) -> list[tuple[Frame, int, int]]:
    rows = con.execute(
        "select verb, role1, arg1, role2, arg2, mean from frame_ratings "
        "where n >= 3 and (mean >= 4.67 or mean <= 1.34) order by all"
    ).fetchall()
    return [
        (Frame(v, ((r1, a1), (r2, a2))), 4 if m >= 4.5 else 1, 5 if m >= 4.5 else 2) for v, r1, a1, r2, a2, m in rows
    ]


def already_rated(con: duckdb.DuckDBPyConnection) -> set[str]:
    rows = con.execute("select verb, role1, arg1, role2, arg2 from frame_ratings").fetchall()
    return {Frame(v, ((r1, a1), (r2, a2))).id for v, r1, a1, r2, a2 in rows}


def build_hits(
    frames: list[Frame], gold: list[tuple[Frame, int, int]], config: TaskConfig
) -> tuple[list[dict], list[dict]]:
    """CSV rows (one per HIT, slots `_1.._N`, gold mixed in at random slots) and the gold items used."""
    rng = random.Random(config.seed)
    frames = frames[:]
    rng.shuffle(frames)
    real_per_hit = config.per_hit - (config.gold_per_hit if gold else 0)
    if real_per_hit < 1:
        raise HitBatchError(f"{config.per_hit} items per HIT leave no room beside {config.gold_per_hit} gold checks")
    rows, used = [], {}
    for start in range(0, len(frames), real_per_hit):
        items = [(f, None) for f in frames[start : start + real_per_hit]]
        for g in rng.sample(gold, min(config.gold_per_hit, len(gold))) if gold else []:
            items.insert(rng.randrange(len(items) + 1), (g[0], g))
        _fill_short_hit(items, frames, gold, config.per_hit, rng)
        row = {}
        for k, (frame, g) in enumerate(items, 1):
            verb, roles = frame
            (role1, arg1), (role2, arg2) = list(roles.items())
            fid = ("gold-" + frame.id[2:]) if g else frame.id
            if g:
                used[fid] = {"frame_id": fid, "expected_min": g[1], "expected_max": g[2], "batch": config.batch}
            row.update(
                {
                    f"{name}_{k}": value
                    for name, value in zip(FIELDS, (fid, verb, role1, arg1, role2, arg2, render(frame)))
                }
            )
        rows.append(row)
    return rows, list(used.values())


def _fill_short_hit(items: list, frames: list[Frame], gold: list, per_hit: int, rng: random.Random) -> None:
    """Fill the free slots of a short (last) HIT, as every slot of the form must be rated: first with
    more gold checks, then with frames of the earlier HITs (extra ratings from other workers), never
    repeating an item of this HIT. The caller sizes the form so that enough distinct items exist."""
    free = per_hit - len(items)
    if free <= 0:
        return
    present = {f.id for f, _ in items}
    spare_gold = [g for g in gold if g[0].id not in present]
    extra = [(g[0], g) for g in rng.sample(spare_gold, min(free, len(spare_gold)))]
    spare = [f for f in frames if f.id not in present]
    extra += [(f, None) for f in rng.sample(spare, min(free - len(extra), len(spare)))]
    for item in extra:
        items.insert(rng.randrange(len(items) + 1), item)


def hit_template(per_hit: int) -> str:
    """The crowd-form HIT for `per_hit` sentences, `${sentence_k}` placeholders matching the CSV."""
    base = (TEMPLATE_DIR / "hit_template.html").read_text(encoding="utf-8")
    item = (TEMPLATE_DIR / "hit_item.html").read_text(encoding="utf-8")
    items = "\n".join(item.replace("${k}", str(k)).replace("_K}", f"_{k}}}") for k in range(1, per_hit + 1))
    return base.replace("<!-- ITEMS -->", items)


def preview(template: str, row: dict) -> str:
    """A page showing the HIT with one CSV row's values filled in, as MTurk substitutes them; the
    rating inputs are native radios, so it works in any browser even when the crowd script is offline."""
    filled = re.sub(r"\$\{([A-Za-z0-9_]+)\}", lambda m: html.escape(row.get(m.group(1), "")), template)
    head = "<meta charset='utf-8'><title>HIT preview</title>"
    return f"<!doctype html><html><head>{head}</head><body>{filled}</body></html>"


def write_tasks(
    out_dir: Path, rows: list[dict], config: TaskConfig, meta: dict, settings: HitSettings = HitSettings()
) -> Path:
    """batch.csv, hit_template.html, preview.html and tasks.json, published as one folder."""
    columns = [f"{name}_{k}" for k in range(1, config.per_hit + 1) for name in FIELDS]
    template = hit_template(config.per_hit)
    with atomic_dir(out_dir) as tmp:
        with open(tmp / "batch.csv", "w", newline="", encoding="utf-8") as handle:
            writer = csv.DictWriter(handle, fieldnames=columns)
            writer.writeheader()
            writer.writerows(rows)
        (tmp / "hit_template.html").write_text(template, encoding="utf-8")
        (tmp / "preview.html").write_text(preview(template, rows[0] if rows else {}), encoding="utf-8")
        (tmp / "tasks.json").write_text(
            json.dumps({**meta, "config": config.__dict__, "hit": settings.to_json()}, indent=2), encoding="utf-8"
        )
    return Path(out_dir)


def generate_tasks(
    con: duckdb.DuckDBPyConnection,
    out_dir: Path,
    config: TaskConfig,
    scorers: dict[str, Callable] | None = None,
    settings: HitSettings = HitSettings(),
) -> dict:
    """Choose frames, build HITs, record the gold items in the store, write the batch folder."""
    if config.mode not in MODES:
        raise HitBatchError(f"mode must be one of {MODES}, not {config.mode!r}")
    check_output_dir(out_dir)  # before the gold items are recorded: a refused folder changes nothing
    pool = protocol_frames(config.seed, config.fixed_per_role, config.verbs)
    if config.mode == "corpus":
        pool = corpus_frames(con, config.n_frames or len(pool), config.seed, config.verbs)
    rated = already_rated(con)
    pool = [f for f in dict.fromkeys(pool) if f.id not in rated]
    if config.mode == "disagreement":
        pool = disagreement_frames(pool, scorers or {}, config.n_frames or len(pool) // 10)
    elif config.n_frames:
        pool = pool[: config.n_frames]
    if not pool:
        raise HitBatchError("no unrated frames to ask about")
    gold = gold_candidates(con) if config.gold_per_hit else []
    # A batch smaller than one HIT gets a shorter form: no slot may be left blank or repeat an item.
    config = replace(config, per_hit=min(config.per_hit, len(pool) + len(gold)))
    rows, used = build_hits(pool, gold, config)
    if used:  # gold answers live in the store, never in the CSV the workers' page could read
        con.executemany(
            "insert or replace into gold_items values (?, ?, ?, ?)",
            [[g["frame_id"], g["expected_min"], g["expected_max"], g["batch"]] for g in used],
        )
    meta = {
        "batch": config.batch,
        "mode": config.mode,
        "frames": len(pool),
        "hits": len(rows),
        "gold_items": len(used),
        "gold_available": len(gold),
    }
    write_tasks(out_dir, rows, config, meta, settings)
    return meta
