"""Scheduled retraining's decision: is anything new, and is the new checkpoint at least as good?

The inputs of a setting are the ingested corpus files (and, for the frame LM, the frame build) plus
the rating files, each known by its sha256. When they match the last decision's, nothing is trained.
Otherwise a candidate is trained without promotion, both it and the current checkpoint are scored on
the rated frames with the evaluation protocol (overall accuracy at lambda, k), and the candidate
becomes LATEST only if it is not worse. Every decision and both scores go to `retrain_decisions`.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import duckdb

from lmcr.errors import one_line
from lmcr.evaluate.protocol import EvalConfig, score_rated
from lmcr.evaluate.ratings import RatedFrame
from lmcr.evaluate.run import calibrate_completion
from lmcr.evaluate.scenarios import ScenarioError, accuracy, build_scenarios
from lmcr.lm import checkpoint as ckpt
from lmcr.lm.corpus import corpus_hash
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


def last_inputs(con: duckdb.DuckDBPyConnection, setting: Setting) -> str | None:
    """The inputs hash of the setting's last retrain decision, None before the first."""
    row = con.execute(
        "select inputs_sha256 from retrain_decisions where setting = ? order by decided_at desc limit 1", [setting.name]
    ).fetchone()
    return row[0] if row else None


def checkpoint_accuracy(version: Path, rated: list[RatedFrame], config: RetrainConfig) -> float:
    """Overall accuracy of one checkpoint version on the rated frames' scenarios."""
    method = METHOD_OF[config.linearization]
    scores = score_rated(rated, {method: make_scorer(method, MethodResources(checkpoints=version))})
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
    candidate: Path,
    rated: list[RatedFrame],
    config: RetrainConfig,
    inputs: str,
    db: Path | None = None,
    calibration_dir: Path | None = None,
) -> dict:
    """Promote `candidate` if it scores at least as well as the current LATEST; record the decision.
    With `db` and `calibration_dir`, a promoted candidate is first calibrated for completion on the
    same rated frames, so completion never falls back to uncalibrated defaults after a promotion."""
    setting_dir = checkpoints / config.setting.name
    current = ckpt.resolve(setting_dir) if (setting_dir / "LATEST").exists() else None
    cand_acc = checkpoint_accuracy(candidate, rated, config)
    cur_acc = checkpoint_accuracy(current, rated, config) if current and current != candidate else None
    if cur_acc is None or cand_acc >= cur_acc:
        decision = "promoted"
        reason = "no current checkpoint" if cur_acc is None else f"not worse: {cand_acc:.3f} >= {cur_acc:.3f}"
    else:
        decision, reason = "kept", f"candidate worse: {cand_acc:.3f} < {cur_acc:.3f}"
    row = {
        "setting": config.setting.name,
        "inputs_sha256": inputs,
        "decision": decision,
        "reason": reason,
        "candidate": str(candidate),
        "current": str(current) if current else None,
        "candidate_accuracy": cand_acc,
        "current_accuracy": cur_acc,
    }
    if decision == "promoted" and db is not None and calibration_dir is not None:
        row["calibration"] = json.dumps(recalibrate(candidate, rated, config, db, calibration_dir), sort_keys=True)
    record(con, row)  # recorded first: LATEST never moves without its decision on record
    if decision == "promoted":
        ckpt.set_latest(checkpoints, config.setting, candidate.name)
    return row


def record(con: duckdb.DuckDBPyConnection, row: dict) -> None:
    cols = [
        "setting",
        "inputs_sha256",
        "decision",
        "reason",
        "candidate",
        "current",
        "candidate_accuracy",
        "current_accuracy",
        "calibration",
    ]
    insert_rows(con, "retrain_decisions", [{c: row.get(c) for c in cols}])
