"""Scoring frames against gold: predicate and role precision/recall/F1, and instruction parsing."""

from __future__ import annotations

from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

from lmcr.jsonl import InputError, check_text, read_jsonl

FRAME_SHAPE = '{"predicate": str, "roles": {role: str or null}}'


@dataclass
class PRF:
    tp: int = 0
    fp: int = 0
    fn: int = 0

    def as_dict(self) -> dict:
        p = self.tp / (self.tp + self.fp) if self.tp + self.fp else 0.0
        r = self.tp / (self.tp + self.fn) if self.tp + self.fn else 0.0
        f = 2 * p * r / (p + r) if p + r else 0.0
        return {"precision": round(p, 4), "recall": round(r, 4), "f1": round(f, 4), "support": self.tp + self.fn}


@dataclass
class SrlScores:
    """Predicate and role counts overall and per predicate."""

    predicates: dict[str, PRF] = field(default_factory=lambda: defaultdict(PRF))
    roles: dict[str, PRF] = field(default_factory=lambda: defaultdict(PRF))

    def table(self) -> list[dict]:
        rows = []
        for name in sorted(set(self.predicates) - {"all"}) + ["all"]:
            p, r = self.predicates[name].as_dict(), self.roles[name].as_dict()
            rows.append(
                {
                    "predicate": name,
                    "pred_p": p["precision"],
                    "pred_r": p["recall"],
                    "pred_f1": p["f1"],
                    "role_p": r["precision"],
                    "role_r": r["recall"],
                    "role_f1": r["f1"],
                    "frames": p["support"],
                }
            )
        return rows


def _by_predicate(frames: list[dict]) -> dict[str, list[dict]]:
    grouped: dict[str, list[dict]] = defaultdict(list)
    for frame in frames:
        grouped[frame["predicate"]].append(frame)
    return grouped


def score_frames(gold: list[list[dict]], predicted: list[list[dict]], known: set[str]) -> SrlScores:
    """Align the i-th gold frame of a predicate with the i-th predicted one in each sentence; a role
    counts when its (non-null) value matches exactly. Only the `known` predicates are scored."""
    scores = SrlScores()
    for gold_frames, pred_frames in zip(gold, predicted, strict=True):
        g = _by_predicate([f for f in gold_frames if f["predicate"] in known])
        p = _by_predicate([f for f in pred_frames if f["predicate"] in known])
        for name in set(g) | set(p):
            matched = min(len(g.get(name, [])), len(p.get(name, [])))
            for key in (name, "all"):
                scores.predicates[key].tp += matched
                scores.predicates[key].fn += len(g.get(name, [])) - matched
                scores.predicates[key].fp += len(p.get(name, [])) - matched
            for i in range(max(len(g.get(name, [])), len(p.get(name, [])))):
                gold_roles = g[name][i]["roles"] if i < len(g.get(name, [])) else {}
                pred_roles = p[name][i]["roles"] if i < len(p.get(name, [])) else {}
                gold_set = Counter((r, v) for r, v in gold_roles.items() if v is not None)
                pred_set = Counter((r, v) for r, v in pred_roles.items() if v is not None)
                hits = sum((gold_set & pred_set).values())
                for key in (name, "all"):
                    scores.roles[key].tp += hits
                    scores.roles[key].fn += sum(gold_set.values()) - hits
                    scores.roles[key].fp += sum(pred_set.values()) - hits
    return scores


def _is_frame(value: object, open_roles: bool = True) -> bool:
    """A frame as the gold files write it; without `open_roles` every role has a value."""
    return (
        isinstance(value, dict)
        and isinstance(value.get("predicate"), str)
        and isinstance(value.get("roles"), dict)
        and all(isinstance(v, str) or open_roles and v is None for v in value["roles"].values())
    )


def read_gold(path: Path) -> list[dict]:
    """The records of an SRL gold file ({text, frames}); a bad line is an InputError naming file and line."""
    records = []
    for line, record in read_jsonl(path, {"text": str, "frames": list}):
        check_text(record["text"], f"{path}:{line}")
        if not all(_is_frame(f) for f in record["frames"]):
            raise InputError(f"{path}:{line}: field 'frames' must be a list of {FRAME_SHAPE}")
        records.append(record)
    return records


def check_expected(record: dict, where: str) -> dict:
    """An instruction record whose `expected` frame names every role's object and whose `missing`
    (when given) is null or one of those roles; else the InputError for `where` (file:line)."""
    if not _is_frame(record["expected"], open_roles=False):
        raise InputError(f'{where}: field \'expected\' must be {{"predicate": str, "roles": {{role: object}}}}')
    missing = record.get("missing")
    if missing is not None and (not isinstance(missing, str) or missing not in record["expected"]["roles"]):
        raise InputError(
            f"{where}: field 'missing' must be null or one of the expected roles {sorted(record['expected']['roles'])}"
        )
    return record


def read_instruction_tasks(path: Path) -> list[dict]:
    """Instruction records ({instruction, expected, missing}) to score instruction parsing."""
    return [check_expected(r, f"{path}:{line}") for line, r in read_jsonl(path, {"instruction": str, "expected": dict})]


def instruction_correct(
    frame: dict | None, expected: dict, missing: str | None, pronouns: frozenset[str] = frozenset()
) -> bool:
    """Right predicate, every stated role right, and the right role (or none) marked missing. A role
    said with a pronoun of `pronouns` is right as the pronoun ("I'd love some wine, could you pour it?":
    what "it" refers to is completion's to find, not the parse's)."""
    if frame is None or frame["predicate"] != expected["predicate"]:
        return False
    for role, value in expected["roles"].items():
        want = None if role == missing else value
        got = frame["roles"].get(role)
        if got != want and not (got in pronouns and role != missing):
            return False
    return True


# Error classes a regression is reported under (`classify_errors`), in the order `lmcr srl-eval` prints them.
ERROR_CLASSES = (
    "missed predicate",
    "extra predicate",
    "boundary",
    "lemma",
    "role",
    "missed role",
    "extra role",
    "wrong filler",
)


def _value_error(gold: str, pred: str) -> str:
    """How a predicted filler differs from the gold one: the span's edges, the head's lemma, or the word."""
    g, p = gold.split(), pred.split()
    if g[-1] == p[-1]:
        return "boundary"  # same head, modifiers kept or lost ("leftover pizza", "butter" for "peanut butter")
    if len(g) == len(p) and g[:-1] == p[:-1] and g[-1][:3] == p[-1][:3]:
        return "lemma"  # "cooky" for "cookie", "leave" for "leaf"
    return "wrong filler"


def frame_errors(gold: dict, pred: dict | None) -> list[tuple[str, str]]:
    """(class, role) for each way a predicted frame of the same predicate misses its gold frame."""
    if pred is None:
        return [("missed predicate", "")]
    errors = []
    g_roles, p_roles = gold["roles"], pred["roles"]
    for role, want in g_roles.items():
        got = p_roles.get(role)
        if want == got:
            continue
        swapped = got is not None and got in [v for r, v in g_roles.items() if r != role]
        if swapped or want is not None and want in [v for r, v in p_roles.items() if r != role]:
            errors.append(("role", role))
        elif want is None:
            errors.append(("extra role", role))
        elif got is None:
            errors.append(("missed role", role))
        else:
            errors.append((_value_error(want, got), role))
    return errors


def classify_errors(
    gold: list[list[dict]], predicted: list[list[dict]], known: set[str]
) -> list[list[tuple[str, str]]]:
    """For each sentence, its errors as (class, detail): gold and predicted frames of a predicate aligned
    in order as `score_frames` does; extra predicted frames are "extra predicate"."""
    out = []
    for gold_frames, pred_frames in zip(gold, predicted, strict=True):
        g = _by_predicate([f for f in gold_frames if f["predicate"] in known])
        p = _by_predicate([f for f in pred_frames if f["predicate"] in known])
        errors = []
        for name in sorted(set(g) | set(p)):
            gs, ps = g.get(name, []), p.get(name, [])
            for i, frame in enumerate(gs):
                errors += [
                    (c, f"{name}.{r}" if r else name) for c, r in frame_errors(frame, ps[i] if i < len(ps) else None)
                ]
            errors += [("extra predicate", name)] * max(0, len(ps) - len(gs))
        out.append(errors)
    return out
