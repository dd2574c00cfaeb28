"""Rating quality: agreement (Krippendorff's alpha, interval), per-worker quality (leave-one-out
agreement, gold-check accuracy, crowd-kit MACE spam probability), a Dawid-Skene aggregate beside the
mean, and approve/reject decisions in the MTurk re-upload format.

Statistics use the `valid_ratings` view (rejected and conflicting assignments excluded), except the
worker table, which also shows what rejected workers did: that is what a requester reviews.
"""

from __future__ import annotations

import csv
import warnings
from dataclasses import dataclass
from pathlib import Path

import duckdb
import krippendorff
import numpy as np
import pandas as pd

from lmcr.files import atomic_path
from lmcr.frame import FRAME_COLUMNS


@dataclass(frozen=True)
class QualityRules:
    """When an assignment is rejected: a worker MACE calls a spammer with this probability, or an
    assignment failing gold checks at this rate (with at least one gold item)."""

    max_spam: float = 0.5
    min_gold_accuracy: float = 0.5
    min_loo_agreement: float = -1.0  # Pearson r with the others' mean; -1 leaves this rule off


def ratings_frame(con: duckdb.DuckDBPyConnection, include_rejected: bool = False) -> pd.DataFrame:
    source = "ratings r join assignments a using (assignment_id)" + (
        "" if include_rejected else " where a.status <> 'Rejected' and a.conflict is null"
    )
    return con.execute(f"select r.*, a.worker_id, a.status from {source}").df()


def krippendorff_alpha(df: pd.DataFrame) -> float:
    """Interval alpha over the worker x frame reliability matrix (NaN where a worker did not rate)."""
    if df.empty:
        return float("nan")
    table = df.pivot_table(index="worker_id", columns=list(FRAME_COLUMNS), values="rating", aggfunc="mean")
    if table.shape[0] < 2 or df["rating"].nunique() < 2:
        return float("nan")  # alpha is undefined with one rater or one value
    return float(krippendorff.alpha(reliability_data=table.to_numpy(dtype=float), level_of_measurement="interval"))


def alpha_by_verb(con: duckdb.DuckDBPyConnection) -> dict[str, float]:
    """Alpha overall ('all') and per verb, valid ratings only."""
    df = ratings_frame(con)
    out = {"all": krippendorff_alpha(df)}
    for verb, part in df.groupby("verb"):
        out[verb] = krippendorff_alpha(part)
    return out


def _loo(df: pd.DataFrame) -> pd.DataFrame:
    """Per rating, the mean of the other workers' ratings of the same frame."""
    grouped = df.groupby(list(FRAME_COLUMNS))["rating"]
    total, count = grouped.transform("sum"), grouped.transform("count")
    return df.assign(others=(total - df["rating"]) / (count - 1)).query("others == others")  # drop lone ratings


def _mace_spam(df: pd.DataFrame, seed: int = 0) -> dict[str, float]:
    from crowdkit.aggregation import MACE

    data = pd.DataFrame(
        {
            "task": df[list(FRAME_COLUMNS)].astype(str).agg("|".join, axis=1),
            "worker": df["worker_id"],
            "label": df["rating"],
        }
    ).sort_values("worker", kind="stable")
    # One start: crowd-kit seeds every restart with the same random_state, so further restarts repeat the
    # first run exactly (each cost as much; five were most of the pipeline's aggregation time).
    with warnings.catch_warnings():  # crowd-kit uses pandas' deprecated inplace= on every iteration
        warnings.simplefilter("ignore")
        mace = MACE(n_restarts=1, n_iter=50, random_state=seed).fit(data)
    workers = pd.unique(data["worker"])  # MACE numbers workers in order of appearance
    return {w: float(p) for w, p in zip(workers, np.asarray(mace.spamming_)[:, 0])}


def dawid_skene(con: duckdb.DuckDBPyConnection) -> pd.DataFrame:
    """Per frame: the mean rating beside the Dawid-Skene aggregate label (ratings as classes 1-5)."""
    from crowdkit.aggregation import DawidSkene

    df = ratings_frame(con)
    df = df[~df["frame_id"].isin(_gold(con).keys())]
    task = df[list(FRAME_COLUMNS)].astype(str).agg("|".join, axis=1)
    with warnings.catch_warnings():  # crowd-kit's deprecated pandas inplace= calls
        warnings.simplefilter("ignore")
        ds = DawidSkene(n_iter=100).fit_predict(
            pd.DataFrame({"task": task, "worker": df["worker_id"], "label": df["rating"]})
        )
    means = df.assign(task=task).groupby("task")["rating"].agg(["mean", "count"])
    return means.join(ds.rename("dawid_skene")).reset_index()


def _gold(con: duckdb.DuckDBPyConnection) -> dict[str, tuple[int, int]]:
    return {
        f: (lo, hi)
        for f, lo, hi in con.execute("select frame_id, expected_min, expected_max from gold_items").fetchall()
    }


def worker_table(con: duckdb.DuckDBPyConnection, seed: int = 0) -> pd.DataFrame:
    """One row per worker: ratings, assignments, rejected, leave-one-out agreement (Pearson r and
    mean absolute difference to the others' mean), gold accuracy, MACE spam probability."""
    everything = ratings_frame(con, include_rejected=True)
    if everything.empty:
        return pd.DataFrame(columns=["worker_id"])
    gold = _gold(con)
    everything["gold_ok"] = [
        (gold[f][0] <= r <= gold[f][1]) if f in gold else np.nan
        for f, r in zip(everything["frame_id"], everything["rating"])
    ]
    loo = _loo(everything[everything["frame_id"].map(lambda f: f not in gold)])
    rows = []
    spam = _mace_spam(everything, seed)
    for worker, part in everything.groupby("worker_id"):
        mine = loo[loo["worker_id"] == worker]
        r = (
            float(np.corrcoef(mine["rating"], mine["others"])[0, 1])
            if len(mine) > 2 and mine["rating"].std() > 0
            else float("nan")
        )
        rows.append(
            {
                "worker_id": worker,
                "ratings": len(part),
                "assignments": part["assignment_id"].nunique(),
                "rejected": int(part.loc[part["status"] == "Rejected", "assignment_id"].nunique()),
                "loo_r": round(r, 3),
                "loo_mad": round(float((mine["rating"] - mine["others"]).abs().mean()), 3)
                if len(mine)
                else float("nan"),
                "gold_accuracy": round(float(part["gold_ok"].mean()), 3)
                if part["gold_ok"].notna().any()
                else float("nan"),
                "mace_spam": round(spam.get(worker, float("nan")), 3),
            }
        )
    return pd.DataFrame(rows).sort_values("worker_id").reset_index(drop=True)


def decisions(
    con: duckdb.DuckDBPyConnection,
    rules: QualityRules = QualityRules(),
    seed: int = 0,
    workers: pd.DataFrame | None = None,
) -> list[dict]:
    """Approve/Reject per submitted or approved assignment, with the reason (rejected ones are final).
    `workers` is the `worker_table` when the caller has it already (MACE takes seconds)."""
    workers = (worker_table(con, seed) if workers is None else workers).set_index("worker_id")
    gold = _gold(con)
    out = []
    rows = con.execute(
        "select a.assignment_id, a.hit_id, a.worker_id, a.status, list(r.frame_id), list(r.rating) "
        "from assignments a join ratings r using (assignment_id) where a.status <> 'Rejected' "
        "group by all order by a.assignment_id"
    ).fetchall()
    for aid, hit, worker, status, frame_ids, ratings in rows:
        checks = [gold[f][0] <= r <= gold[f][1] for f, r in zip(frame_ids, ratings) if f in gold]
        w = workers.loc[worker]
        reason = None
        if checks and sum(checks) / len(checks) < rules.min_gold_accuracy:
            reason = f"failed {len(checks) - sum(checks)} of {len(checks)} gold checks"
        elif w["mace_spam"] >= rules.max_spam:
            reason = f"answers look random (MACE spam probability {w['mace_spam']:.2f})"
        elif w["loo_r"] == w["loo_r"] and w["loo_r"] < rules.min_loo_agreement:
            reason = f"disagrees with the other raters (r = {w['loo_r']:.2f})"
        out.append(
            {
                "AssignmentId": aid,
                "HITId": hit,
                "WorkerId": worker,
                "AssignmentStatus": status,
                "Approve": "" if reason else "x",
                "Reject": reason or "",
            }
        )
    return out


def write_decisions(path: Path, rows: list[dict]) -> Path:
    """The MTurk re-upload CSV: one row per assignment, an `x` under Approve or a reason under Reject."""
    with atomic_path(Path(path)) as tmp, open(tmp, "w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(
            handle, fieldnames=["AssignmentId", "HITId", "WorkerId", "AssignmentStatus", "Approve", "Reject"]
        )
        writer.writeheader()
        writer.writerows(rows)
    return Path(path)
