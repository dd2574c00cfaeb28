"""Scheduled retraining: what changed, what that costs, and is the new checkpoint at least as good?

The inputs of a setting are the ingested corpus files (and, for the frame LM, the frame build) plus
the rating files, each known by its sha256, and recorded with every decision. What changed since the
last decision decides what is done (`Change.action`):

- nothing: nothing;
- only the ratings: no training (ratings do not enter an LM): the current checkpoint is judged on them
  and completion is calibrated again;
- corpus files added or changed: the current LM continues on the new text with a replay of the old
  (`lm.run.continue_setting`), or trains from scratch when its vocabulary would change too much;
- corpus files removed (or the frame build redone for the frame LM): a full training, since a warm start
  cannot unlearn text.

A candidate is scored with the current checkpoint on the rated frames by the evaluation protocol
(overall accuracy at lambda, k, of the default completion built on each: what users get) and becomes
LATEST only if it is not worse. Every decision, both scores,
the change, the action and its cost (seconds, tokens trained) go to `retrain_decisions`.
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import duckdb

from lmcr.errors import one_line
from lmcr.evaluate.protocol import EvalConfig, score_rated
from lmcr.evaluate.ratings import RatedFrame
from lmcr.evaluate.run import calibrate_completion
from lmcr.evaluate.scenarios import ScenarioError, accuracy, build_scenarios
from lmcr.frame_corpus.load import last_build
from lmcr.lm import checkpoint as ckpt
from lmcr.lm.corpus import corpus_hash
from lmcr.lm.hyperparams import LMConfig, TrainConfig, WarmStartConfig
from lmcr.lm.run import continue_setting, tokens_trained, train_setting
from lmcr.scorers.registry import COMPLETION_METHOD, make_scorer
from lmcr.scorers.resources import MethodResources
from lmcr.setting import METHOD_OF, Setting
from lmcr.store import insert_rows


@dataclass(frozen=True)
class RetrainConfig:
    """What the retrain flow trains (`setting`: a Setting, or any spelling `Setting.parse` reads, parsed
    here once: the flow's parameters are JSON) and how a candidate is judged (lambda, k, per verb, seed)."""

    setting: Setting | str = Setting("sentence")  # a Setting once constructed; str for the flow's JSON
    lam: float = 1.0
    k: int = 6
    per_verb: int = 50
    seed: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.setting, Setting):
            object.__setattr__(self, "setting", Setting.parse(str(self.setting)))

    @property
    def linearization(self) -> str:
        return self.setting.linearization


def inputs_sha256(con: duckdb.DuckDBPyConnection, linearization: str) -> str:
    """One hash over what a setting is trained and judged on: corpus content and rating files."""
    ratings = con.execute("select sha256 from rating_files order by 1").fetchall()
    return hashlib.sha256(repr((corpus_hash(con, linearization), ratings)).encode()).hexdigest()


@dataclass(frozen=True)
class Inputs:
    """What a decision saw: corpus files (path -> sha256), rating file hashes, and for the frame LM the
    frame build; `sha256` is `inputs_sha256` of the same store."""

    sha256: str
    files: dict[str, str] = field(default_factory=dict)
    ratings: tuple[str, ...] = ()
    frames: str | None = None
    corpus: str = ""  # `corpus_hash`: what a checkpoint's provenance records of its text

    @classmethod
    def read(cls, con: duckdb.DuckDBPyConnection, linearization: str) -> Inputs:
        files = dict(con.execute("select source_file, sha256 from ingested_files order by all").fetchall())
        ratings = tuple(r for (r,) in con.execute("select sha256 from rating_files order by 1").fetchall())
        frames = last_build(con) if linearization == "frame" else None
        return cls(inputs_sha256(con, linearization), files, ratings, frames, corpus_hash(con, linearization))

    @classmethod
    def of_checkpoint(cls, version: Path) -> Inputs:
        """What a checkpoint trained outside the retrain flow (`lmcr train`, the pipeline) is known to have
        seen: the hash of its corpus, no ratings."""
        provenance = json.loads((version / "provenance.json").read_text(encoding="utf-8"))
        return cls("", corpus=provenance.get("corpus_sha256", ""))

    def to_json(self) -> str:
        return json.dumps({**asdict(self), "ratings": list(self.ratings)}, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> Inputs:
        data = json.loads(text)
        files, ratings = dict(data["files"]), tuple(data["ratings"])
        return cls(data["sha256"], files, ratings, data.get("frames"), data.get("corpus", ""))


@dataclass(frozen=True)
class Change:
    """What changed between two decisions' inputs; `kind` is the strongest change (see the module)."""

    kind: str  # first | unchanged | ratings | corpus_added | corpus_changed | corpus_removed | frames_rebuilt
    added: tuple[str, ...] = ()
    changed: tuple[str, ...] = ()
    removed: tuple[str, ...] = ()
    new_ratings: bool = False

    @property
    def new_sources(self) -> list[str]:
        """The corpus files whose text is new: added or changed."""
        return [*self.added, *self.changed]

    def action(self, has_checkpoint: bool) -> str:
        """none | recalibrate | warm_start | full (see the module docstring)."""
        if self.kind == "unchanged":
            return "none"
        if not has_checkpoint or self.kind in ("first", "corpus_removed", "frames_rebuilt"):
            return "full"
        return "recalibrate" if self.kind == "ratings" else "warm_start"

    def describe(self) -> str:
        """The change in words, for the decision's reason."""
        parts = [
            f"{len(files)} corpus file{'s' if len(files) != 1 else ''} {verb} ({_names(files)})"
            for verb, files in (("added", self.added), ("changed", self.changed), ("removed", self.removed))
            if files
        ]
        if self.kind == "frames_rebuilt":
            parts.append("the frame corpus was rebuilt")
        if self.new_ratings:
            parts.append("new ratings")
        return {"first": "no earlier decision", "unchanged": "nothing changed"}.get(self.kind, "; ".join(parts))


def _names(files: tuple[str, ...], shown: int = 3) -> str:
    names = [Path(f).name for f in files[:shown]]
    return ", ".join(names + (["..."] if len(files) > shown else []))


def classify(previous: Inputs | None, current: Inputs) -> Change:
    """The change from the last decision's inputs to the current ones (None before the first decision,
    or when that decision recorded only a hash). Before the first decision, the current checkpoint's
    inputs (`Inputs.of_checkpoint`) stand for the last decision's: a checkpoint trained on the current
    corpus is judged and calibrated, not trained again."""
    if previous is not None and previous.sha256 == current.sha256:
        return Change("unchanged")
    if previous is not None and not previous.files and previous.corpus and previous.corpus == current.corpus:
        return Change("ratings", new_ratings=True)  # a checkpoint trained on this very corpus, not yet judged
    if previous is None or not previous.files and not previous.ratings:
        return Change("first")
    old, new = previous.files, current.files
    added = tuple(sorted(f for f in new if f not in old))
    changed = tuple(sorted(f for f in new if f in old and old[f] != new[f]))
    removed = tuple(sorted(f for f in old if f not in new))
    new_ratings = previous.ratings != current.ratings
    if removed:
        kind = "corpus_removed"
    elif changed:
        kind = "corpus_changed"
    elif added:
        kind = "corpus_added"
    elif previous.frames != current.frames:
        kind = "frames_rebuilt"
    else:
        kind = "ratings"
    return Change(kind, added, changed, removed, new_ratings)


def last_inputs(con: duckdb.DuckDBPyConnection, setting: Setting) -> Inputs | None:
    """The inputs of the setting's last retrain decision (only their hash for decisions recorded before
    the inputs were), None before the first."""
    row = con.execute(
        "select inputs_sha256, inputs_json from retrain_decisions where setting = ? order by decided_at desc limit 1",
        [setting.name],
    ).fetchone()
    if not row:
        return None
    return Inputs.from_json(row[1]) if row[1] else Inputs(row[0])


@dataclass(frozen=True)
class Candidate:
    """A trained, unpromoted checkpoint and what making it cost."""

    path: Path
    action: str  # warm_start | full
    reason: str
    seconds: float
    tokens_trained: int


def train_candidate(
    open_store: Callable[[], duckdb.DuckDBPyConnection],
    checkpoints: Path,
    setting: Setting,
    change: Change,
    model_config: LMConfig,
    train_config: TrainConfig,
    warm: WarmStartConfig = WarmStartConfig(),
    on_epoch: Callable[[dict], None] | None = None,
) -> Candidate:
    """Train a candidate for `change`: a warm start where its action is one and the start is not refused,
    else a full training; published without promotion."""
    started = time.perf_counter()
    why = change.describe()
    if change.action(has_checkpoint=current_checkpoint(checkpoints, setting) is not None) == "warm_start":
        warm_start = continue_setting(open_store, checkpoints, setting, change.new_sources, warm, on_epoch)
        if warm_start.path is not None:
            return _candidate(warm_start.path, "warm_start", f"{why}: {warm_start.reason}", started)
        why = f"{why}: trained from scratch, {warm_start.reason}"
    else:
        why = f"{why}: trained from scratch"
    path = train_setting(open_store, checkpoints, setting, model_config, train_config, on_epoch=on_epoch, promote=False)
    return _candidate(path, "full", why, started)


def _candidate(path: Path, action: str, reason: str, started: float) -> Candidate:
    metrics = json.loads((path / "metrics.json").read_text(encoding="utf-8"))
    return Candidate(path, action, reason, time.perf_counter() - started, tokens_trained(metrics["history"]))


def checkpoint_accuracy(version: Path, rated: list[RatedFrame], config: RetrainConfig, db: Path | None = None) -> float:
    """Overall accuracy on the rated frames' scenarios of what completion answers with this checkpoint
    version: the default completion method when it is built on the setting's LM and `db` holds what its
    other scorers need (frame counts), else the LM alone. Two LMs of the same perplexity differ by up to
    0.03 alone (on the full corpora: 0.814, 0.832, 0.840) where the completion users get differs by
    under 0.01 (0.928, 0.924, 0.922), so judging the LM alone kept candidates as good as a full retrain."""
    resources = MethodResources(checkpoints=version, corpus=config.setting.corpus, db=db)
    method = completion_methods(config.linearization)[-1] if db is not None else METHOD_OF[config.linearization]
    try:
        scorer = make_scorer(method, resources)
    except ValueError:  # e.g. frame_counts before any frame corpus was built: the LM alone, for both
        method = METHOD_OF[config.linearization]
        scorer = make_scorer(method, resources)
    scores = score_rated(rated, {method: scorer})
    scenarios, _ = build_scenarios(rated, config.lam, config.k, config.per_verb, config.seed)
    if not scenarios:
        raise ScenarioError(f"the ratings give no scenarios at lambda={config.lam:g}, k={config.k}")
    return accuracy(scenarios, scores[method])["all"]


def completion_methods(linearization: str) -> list[str]:
    """The calibrated completion methods built on a linearisation's LM: the LM alone and the default
    completion method when it includes that LM."""
    method = METHOD_OF[linearization]
    return [method] + ([COMPLETION_METHOD] if method in COMPLETION_METHOD.split("+") else [])


def recalibrate(
    candidate: Path, rated: list[RatedFrame], config: RetrainConfig, db: Path, calibration_dir: Path
) -> dict:
    """Calibrate completion with `candidate` as the setting's LM, as `lmcr evaluate` does, and save it
    under the candidate's fingerprint (the current checkpoint's calibration stays); method -> summary."""
    res = MethodResources(checkpoints=candidate, corpus=config.setting.corpus, db=db)
    scorers, summary = {}, {}
    for method in completion_methods(config.linearization):
        try:
            scorers[method] = make_scorer(method, res)
        except ValueError as exc:  # e.g. frame_counts before any frame corpus was built
            summary[method] = {"not_calibrated": one_line(exc)}
    scores = score_rated(rated, scorers)
    eval_config = EvalConfig(lam=config.lam, k=config.k, per_verb=config.per_verb, seed=config.seed)
    saved = calibrate_completion(
        rated, scores, list(scorers), res, eval_config, calibration_dir, log=lambda message: None
    )
    for method, (path, fingerprint, cal) in saved.items():
        summary[method] = {
            "temperature": cal.temperature,
            "set_threshold": cal.set_threshold,
            "fingerprint": fingerprint,
            "file": path.name,
        }
    return summary


def decide(
    con: duckdb.DuckDBPyConnection,
    checkpoints: Path,
    candidate: Candidate,
    rated: list[RatedFrame],
    config: RetrainConfig,
    inputs: Inputs,
    change: Change,
    db: Path | None = None,
    calibration_dir: Path | None = None,
) -> dict:
    """Promote the candidate if it scores at least as well as the current LATEST; record the decision
    with its change, action and cost. With `db` and `calibration_dir`, a promoted candidate is first
    calibrated for completion on the same rated frames, so completion never falls back to uncalibrated
    defaults after a promotion."""
    started = time.perf_counter()
    current = current_checkpoint(checkpoints, config.setting)
    cand_acc = checkpoint_accuracy(candidate.path, rated, config, db)
    cur_acc = checkpoint_accuracy(current, rated, config, db) if current and current != candidate.path else None
    if cur_acc is None or cand_acc >= cur_acc:
        decision = "promoted"
        reason = "no current checkpoint" if cur_acc is None else f"not worse: {cand_acc:.3f} >= {cur_acc:.3f}"
    else:
        decision, reason = "kept", f"candidate worse: {cand_acc:.3f} < {cur_acc:.3f}"
    row = {
        **_decision_row(config, inputs, change, candidate.action),
        "decision": decision,
        "reason": f"{reason}; {candidate.reason}",
        "candidate": str(candidate.path),
        "current": str(current) if current else None,
        "candidate_accuracy": cand_acc,
        "current_accuracy": cur_acc,
        "tokens_trained": candidate.tokens_trained,
    }
    if decision == "promoted" and db is not None and calibration_dir is not None:
        calibration = recalibrate(candidate.path, rated, config, db, calibration_dir)
        row["calibration"] = json.dumps(calibration, sort_keys=True)
    row["seconds"] = candidate.seconds + time.perf_counter() - started
    record(con, row)  # recorded first: LATEST never moves without its decision on record
    if decision == "promoted":
        ckpt.set_latest(checkpoints, config.setting, candidate.path.name)
    return row


def rejudge(
    con: duckdb.DuckDBPyConnection,
    checkpoints: Path,
    rated: list[RatedFrame],
    config: RetrainConfig,
    inputs: Inputs,
    change: Change,
    db: Path,
    calibration_dir: Path,
) -> dict:
    """New ratings only: judge the current checkpoint on them and calibrate completion again; nothing is
    trained and LATEST stays. Recorded as `recalibrated`."""
    started = time.perf_counter()
    current = current_checkpoint(checkpoints, config.setting)
    accuracy_now = checkpoint_accuracy(current, rated, config, db)
    calibration = recalibrate(current, rated, config, db, calibration_dir)
    row = {
        **_decision_row(config, inputs, change, "recalibrate"),
        "decision": "recalibrated",
        "reason": f"{change.describe()}: ratings do not enter LM training; {current.name} judged "
        f"({accuracy_now:.3f}) and completion calibrated again",
        "current": str(current),
        "current_accuracy": accuracy_now,
        "calibration": json.dumps(calibration, sort_keys=True),
        "tokens_trained": 0,
        "seconds": time.perf_counter() - started,
    }
    record(con, row)
    return row


def record_unchanged(con: duckdb.DuckDBPyConnection, config: RetrainConfig, inputs: Inputs) -> dict:
    """Record that nothing changed since the last decision."""
    row = {
        **_decision_row(config, inputs, Change("unchanged"), "none"),
        "decision": "unchanged",
        "reason": "corpus and ratings unchanged since the last decision",
        "tokens_trained": 0,
        "seconds": 0.0,
    }
    record(con, row)
    return row


def current_checkpoint(checkpoints: Path, setting: Setting) -> Path | None:
    """The version LATEST names for the setting, None before the first."""
    setting_dir = checkpoints / setting.name
    return ckpt.resolve(setting_dir) if (setting_dir / "LATEST").exists() else None


def _decision_row(config: RetrainConfig, inputs: Inputs, change: Change, action: str) -> dict:
    return {
        "setting": config.setting.name,
        "inputs_sha256": inputs.sha256,
        "inputs_json": inputs.to_json(),
        "change": change.kind,
        "action": action,
    }


DECISION_COLUMNS = (
    "setting",
    "inputs_sha256",
    "decision",
    "reason",
    "candidate",
    "current",
    "candidate_accuracy",
    "current_accuracy",
    "calibration",
    "change",
    "action",
    "seconds",
    "tokens_trained",
    "inputs_json",
)


def record(con: duckdb.DuckDBPyConnection, row: dict) -> None:
    """One retrain_decisions row (columns the row lacks stay null)."""
    insert_rows(con, "retrain_decisions", [{c: row.get(c) for c in DECISION_COLUMNS}])
