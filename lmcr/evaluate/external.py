"""Requests people make of a household robot, from public data sets nobody on this project wrote (the
external sets: one JSONL file per set), scored as the product completes them.

An item is an `lmcr complete` input line (`id`, `instruction`, `objects`) with its gold: `verb` (the
predicate as said, with its particle: `put away`), `missing` (the role whose filler is scored),
`missing_roles` (every role the instruction leaves open; default `[missing]`) and `expected_any` (every
right filler of `missing`). A completion (`Completion.to_json()`, or `{"error": reason}` when there is
none) is scored against it:

- right predicate: the completion's predicate, lowercased with spaces collapsed, is the item's `verb`
  with its particle (`put away`; `put` is wrong). A trailing `of` may be left off (`dispose` for
  `dispose of`): it is a preposition that introduces the Theme, not a particle that changes the act;
- right missing role: the completion leaves the item's `missing` role open and no role the item states
  (its open roles are a subset of `missing_roles`: a pronoun Theme the completion resolved is fine);
- top guess right: the completion chose, for the item's `missing` role left open, an object of
  `expected_any` (with or without a question; the predicate is judged apart);
- question asked: the completion carries a question (KnowNo's help);
- set covers: a candidate of the prediction set fills `missing` with an object of `expected_any`
  (KnowNo's success); the set's size is its number of candidates;
- error: no completion (no known predicate, no usable objects); its reason is the message's first
  clause with the item's own words left out, so reasons can be counted.

Shares are over all of a set's items (an error is right at nothing and asks nothing); the mean set size
is over the items that were completed.
"""

from __future__ import annotations

import math
import re
import time
from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

from lmcr.complete import CompletionConfig, CompletionError, calibrate, complete, softmax
from lmcr.errors import one_line
from lmcr.jsonl import InputError, check_text, read_jsonl
from lmcr.lexicon import normalize_name as normalize
from lmcr.scorers.registry import Scorer
from lmcr.srl.instruction import NoPredicateError
from lmcr.srl.parser import FrameParser

ITEM_FIELDS = {"id": (str, int), "instruction": str, "objects": list, "missing": str, "expected_any": list, "verb": str}
# a preposition that introduces the Theme, which a predicate's name may leave off ("dispose of it")
THEME_PREPOSITIONS = ("of",)


@dataclass(frozen=True)
class ExternalItem:
    """One request with its gold (see the module's docstring)."""

    id: str
    instruction: str
    objects: tuple[str, ...]
    verb: str
    missing: str
    missing_roles: tuple[str, ...]
    expected_any: tuple[str, ...]


def _strings(value: object) -> bool:
    return isinstance(value, list) and all(isinstance(v, str) and v.strip() for v in value)


def _item(record: dict, where: str) -> ExternalItem:
    """The item of a record whose fields have their JSON types; else the InputError for `where`."""
    check_text(record["instruction"], where)
    for key in ("objects", "expected_any"):
        if not _strings(record[key]) or not record[key]:
            raise InputError(f"{where}: field {key!r} must be a non-empty list of non-empty strings")
    if not record["verb"].strip() or not record["missing"].strip():
        raise InputError(f"{where}: fields 'verb' and 'missing' must not be empty")
    missing_roles = record.get("missing_roles", [record["missing"]])
    if not _strings(missing_roles) or record["missing"] not in missing_roles:
        raise InputError(f"{where}: field 'missing_roles' must be a list of roles that holds {record['missing']!r}")
    return ExternalItem(
        id=str(record["id"]),
        instruction=record["instruction"],
        objects=tuple(record["objects"]),
        verb=normalize(record["verb"]),
        missing=record["missing"],
        missing_roles=tuple(missing_roles),
        expected_any=tuple(normalize(o) for o in record["expected_any"]),
    )


def read_items(path: Path) -> list[ExternalItem]:
    """The items of one set's JSONL file; a malformed line (invalid JSON, a field missing or mistyped, a
    repeated id) raises InputError naming file and line."""
    items: list[ExternalItem] = []
    seen: dict[str, int] = {}
    for line, record in read_jsonl(path, ITEM_FIELDS):
        item = _item(record, f"{path}:{line}")
        if item.id in seen:
            raise InputError(f"{path}:{line}: id {item.id!r} repeats line {seen[item.id]}")
        seen[item.id] = line
        items.append(item)
    if not items:
        raise InputError(f"{path}: no items")
    return items


def read_sets(folder: Path) -> dict[str, list[ExternalItem]]:
    """Every set of a folder (`<set>.jsonl`), by name in name order; a folder without one raises InputError."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder}: not a folder of request sets")
    files = sorted(folder.glob("*.jsonl"))
    if not files:
        raise InputError(f"{folder}: no request sets (*.jsonl)")
    return {path.stem: read_items(path) for path in files}


def read_requests(path: Path) -> list[ExternalItem]:
    """The items of one set's file, or of every set of a folder (`read_sets`), in order."""
    path = Path(path)
    if path.is_dir():
        return [item for items in read_sets(path).values() for item in items]
    return read_items(path)


def right_predicate(read: str | None, verb: str) -> bool:
    """Whether the predicate `read` names the verb as said (`verb`, with its particle); see the module."""
    if read is None:
        return False
    read, verb = normalize(read), normalize(verb)
    words = verb.split()
    return read == verb or (len(words) > 1 and words[-1] in THEME_PREPOSITIONS and read == " ".join(words[:-1]))


def error_reason(message: str) -> str:
    """What kind of error a one-line message is, without the item's own words: its first clause (up to
    ': ' or a quoted instruction) with quoted text as '…' and numbers as N ("no known predicate")."""
    head = re.split(r": | in ['\"]", one_line(message), maxsplit=1)[0]
    head = re.sub(r"'[^']*'|\"[^\"]*\"", "…", head)
    return re.sub(r"\d[\d,.]*", "N", head).strip() or "error"


@dataclass(frozen=True)
class Outcome:
    """One item's completion scored (see the module's docstring); `ms` the time it took."""

    id: str
    error: str | None
    predicate: str | None
    right_predicate: bool
    right_role: bool
    chosen: str | None
    top_right: bool
    asked: bool
    covered: bool
    set_size: int
    ms: float

    def to_json(self) -> dict:
        return asdict(self)


def score(item: ExternalItem, line: dict, ms: float = 0.0) -> Outcome:
    """`line` (a completion's JSON, or {"error": reason}) scored against `item`."""
    if line.get("error") is not None:
        return Outcome(item.id, one_line(line["error"]), None, False, False, None, False, False, False, 0, ms)
    predicate = line["frame"]["predicate"]
    open_roles = list(line.get("missing_roles") or ([line["missing"]] if line.get("missing") else []))
    scored = item.missing in open_roles
    chosen = line["frame"]["roles"].get(item.missing) if scored else None
    in_set = line["candidates"][: len(line["prediction_set"])]  # the set is the best candidates
    fillers = {normalize(c["objects"].get(item.missing) or "") for c in in_set} if scored else set()
    return Outcome(
        id=item.id,
        error=None,
        predicate=predicate,
        right_predicate=right_predicate(predicate, item.verb),
        right_role=scored and set(open_roles) <= set(item.missing_roles),
        chosen=chosen,
        top_right=chosen is not None and normalize(chosen) in item.expected_any,
        asked=line.get("question") is not None,
        covered=bool(fillers & set(item.expected_any)),
        set_size=len(line["prediction_set"]),
        ms=ms,
    )


def complete_item(
    parser: FrameParser, scorer: Scorer, config: CompletionConfig, item: ExternalItem
) -> tuple[dict, float]:
    """The item completed as `lmcr complete` completes an input line (its output line, `{"error": reason}`
    where there is no completion) and the milliseconds it took."""
    started = time.perf_counter()
    line = complete_line(parser, scorer, config, item.instruction, list(item.objects))
    return {"id": item.id, **line}, 1000 * (time.perf_counter() - started)


def complete_line(
    parser: FrameParser, scorer: Scorer, config: CompletionConfig, instruction: str, objects: list[str]
) -> dict:
    """The instruction completed with the objects as `lmcr complete` writes its output line (without the
    id), or `{"error": reason}` where there is no completion."""
    try:
        return complete(parser, scorer, instruction, objects, config).to_json()
    except (NoPredicateError, CompletionError, InputError) as exc:  # what `lmcr complete` reports per line
        return {"error": one_line(exc)}


def right_first(item: ExternalItem, line: dict) -> list[float] | None:
    """A completion line's candidate scores with its best right candidate first and the other right ones
    left out (what `complete.calibrate` reads): a right candidate fills the item's `missing` role with an
    object of `expected_any`. None for an error, a wrong predicate or no right candidate: no threshold
    puts in a set what is not among the candidates. (Two open roles list the best `max_listed` pairs
    only; the rest hold next to no probability.)"""
    if line.get("error") is not None or not right_predicate(line["frame"]["predicate"], item.verb):
        return None
    candidates = line["candidates"]
    right = [normalize(c["objects"].get(item.missing) or "") in item.expected_any for c in candidates]
    if not any(right):
        return None
    best = max(c["score"] for c, is_right in zip(candidates, right) if is_right)
    return [best, *(c["score"] for c, is_right in zip(candidates, right) if not is_right)]


def calibrate_requests(
    parser: FrameParser, scorer: Scorer, config: CompletionConfig, items: list[ExternalItem], alpha: float = 0.1
) -> CompletionConfig:
    """The learned verbs' temperature and prediction-set threshold, calibrated on household requests as
    `complete.calibrate` calibrates the eleven's on the dev scenarios: each item completed as `lmcr
    complete` does, and read by `right_first`. Items whose predicate is one of the eleven, or whose
    completion holds no right candidate, are left out; CompletionError when none is left."""
    lines = [complete_line(parser, scorer, config, item.instruction, list(item.objects)) for item in items]
    lists = learned_right_first(items, lines, parser.lex.learned)
    if not lists:
        raise CompletionError(f"none of {len(items)} requests was completed with a right candidate to calibrate on")
    return calibrate(lists, alpha, what=f"of {len(items)} household requests")


def calibrate_learned_verbs(
    ws, res, methods: list[str], items: list[ExternalItem], log: Callable[[str], None] = print
) -> dict[str, str]:
    """Calibrate the learned verbs' completion on the requests (`calibrate_requests`) for each method the
    ratings calibrated in the workspace `ws` (`lmcr evaluate`), and save it beside that calibration under
    the same fingerprint (`complete.requests_calibration_file`); method -> what was done, as logged."""
    from lmcr.complete import calibration_file, load_config, requests_calibration_file, save_config
    from lmcr.scorers.registry import make_scorer

    parser, done = ws.parser(), {}
    for method in methods:
        path, fingerprint = calibration_file(method, res, ws.calibration)
        config = load_config(path, fingerprint) if fingerprint else None
        if config is None:
            continue  # not calibrated on the ratings: there is nothing to put it beside
        try:
            learned = calibrate_requests(parser, make_scorer(method, res), config, items)
        except CompletionError as exc:  # the ratings' calibration stands: the learned verbs keep using it
            done[method] = f"learned verbs not calibrated: {one_line(exc)}"
        else:
            save_config(learned, requests_calibration_file(path), fingerprint)
            done[method] = (
                f"learned verbs: temperature {learned.temperature:.3g}, prediction-set threshold "
                f"p >= {learned.set_threshold:.3f} ({learned.source})"
            )
        log(f"{method} {done[method]}")
    return done


def cross_calibrated(
    items_by_set: dict[str, list[ExternalItem]], lines_by_set: dict[str, list[dict]], learned: frozenset[str]
) -> dict[str, dict]:
    """Each set's prediction sets had the learned verbs been calibrated (`calibrate_requests`) on the
    other sets' completion lines, so that no set is calibrated on its own items (on its own when it is the
    only set): how often the set holds a right object and its mean size (`score`'s), with the temperature
    and threshold used. A line of one of the eleven keeps its own set."""

    calibration = {name: learned_right_first(items_by_set[name], lines_by_set[name], learned) for name in items_by_set}
    rows = {}
    for name, items in items_by_set.items():
        others = [x for other, found in calibration.items() if other != name for x in found] or calibration[name]
        if not others:  # no learned verb completed with a right candidate anywhere: nothing to calibrate on
            rows[name] = dict.fromkeys(("set holds a right object", "mean set size", "temperature", "set threshold"))
            continue
        config = calibrate(others, what="requests of the other sets")
        outcomes = [score(item, _reset(line, config, learned)) for item, line in zip(items, lines_by_set[name])]
        completed = [o for o in outcomes if o.error is None]
        rows[name] = {
            "set holds a right object": round(sum(o.covered for o in outcomes) / len(outcomes), 3),
            "mean set size": round(sum(o.set_size for o in completed) / len(completed), 2) if completed else None,
            "temperature": round(config.temperature, 3),
            "set threshold": round(config.set_threshold, 4),
        }
    return rows


def learned_right_first(items: list[ExternalItem], lines: list[dict], learned: frozenset[str]) -> list[list[float]]:
    """`right_first` of each completion line of a learned predicate that has a right candidate: what the
    learned verbs are calibrated on."""
    return [found for item, line in zip(items, lines) if _learned(line, learned) and (found := right_first(item, line))]


def _learned(line: dict, learned: frozenset[str]) -> bool:
    return line.get("error") is None and line["frame"]["predicate"] in learned


def _reset(line: dict, config: CompletionConfig, learned: frozenset[str]) -> dict:
    """A learned verb's completion line with the prediction set `config` gives its candidates (the best
    ones, as `complete` forms it); any other line as it is."""
    if not _learned(line, learned):
        return line
    probs = softmax([c["score"] for c in line["candidates"]], config.temperature)
    return {
        **line,
        "prediction_set": [c["object"] for c, p in zip(line["candidates"], probs) if p >= config.set_threshold],
    }


def run_set(
    parser: FrameParser, scorer: Scorer, config: CompletionConfig, items: list[ExternalItem]
) -> list[tuple[dict, Outcome]]:
    """Each item's completion line and its outcome, in order. The first item is completed once untimed
    first, so the timings leave out what the first completion loads."""
    complete_item(parser, scorer, config, items[0])
    done = []
    for item in items:
        line, ms = complete_item(parser, scorer, config, item)
        done.append((line, score(item, line, ms)))
    return done


def percentile(values: list[float], q: float) -> float:
    """The nearest-rank percentile (q in 0..1) of a non-empty list."""
    ordered = sorted(values)
    return ordered[max(0, math.ceil(q * len(ordered)) - 1)]


def summarize(items: Iterable[ExternalItem], outcomes: Iterable[Outcome]) -> dict:
    """A set's figures: counts and shares over its items (see the module's docstring), the mean prediction
    set size over the completed ones, the error reasons counted, the predicates read for a wrong one
    ('verb -> predicate'), and the completion latency (p50, p90 ms over all items)."""
    items, outcomes = list(items), list(outcomes)
    n = len(outcomes)
    completed = [o for o in outcomes if o.error is None]
    verbs = {i.id: i.verb for i in items}

    def share(count: int) -> float:
        return round(count / n, 3) if n else 0.0

    counts = {
        "right predicate": sum(o.right_predicate for o in outcomes),
        "right predicate and missing role": sum(o.right_predicate and o.right_role for o in outcomes),
        "top guess right": sum(o.top_right for o in outcomes),
        "questions asked": sum(o.asked for o in outcomes),
        "set holds a right object": sum(o.covered for o in outcomes),
        "errors": n - len(completed),
    }
    ms = [o.ms for o in outcomes]
    return {
        "items": n,
        **{name: share(count) for name, count in counts.items()},
        "counts": counts,
        "completed": len(completed),
        "mean set size": round(sum(o.set_size for o in completed) / len(completed), 2) if completed else None,
        "error reasons": dict(Counter(error_reason(o.error) for o in outcomes if o.error).most_common()),
        "wrong predicates": dict(
            Counter(f"{verbs[o.id]} -> {o.predicate}" for o in completed if not o.right_predicate).most_common()
        ),
        "p50 ms": round(percentile(ms, 0.5), 2) if ms else None,
        "p90 ms": round(percentile(ms, 0.9), 2) if ms else None,
    }
