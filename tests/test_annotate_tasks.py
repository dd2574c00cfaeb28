"""Rating tasks out and back in: batch CSV, template placeholders, preview, gold checks, worker quality."""

from __future__ import annotations

import csv
import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from lmcr.annotate.quality import alpha_by_verb, dawid_skene, decisions, worker_table, write_decisions
from lmcr.annotate.results import ingest_ratings
from lmcr.annotate.tasks import TaskConfig, disagreement_frames, generate_tasks, protocol_frames, render
from tests.mturk import write_results


def seed_ratings(con, path):
    """A past batch: 'pour water into cup' rated 5 and 'into scissors' 1 by three workers (gold material)."""
    rows = []
    for i, worker in enumerate(["W1", "W2", "W3"]):
        rows.append(["H0", f"P{i}a", worker, "Approved", "pour", "Theme", "water", "Destination", "cup", "5"])
        rows.append(["H0", f"P{i}b", worker, "Approved", "pour", "Theme", "water", "Destination", "scissors", "1"])
    ingest_ratings(con, write_results(path, rows))


def test_render_and_protocol_frames():
    assert render(("pour", {"Theme": "water", "Destination": "cup"})) == "Pour the water into the cup."
    frames = protocol_frames(seed=0, fixed_per_role=1)
    assert len(frames) == 11 * 2 * 55 and len({(v, tuple(r.items())) for v, r in frames}) == len(frames)


def test_tasks_round_trip_with_gold_checks(con, tmp_path):
    seed_ratings(con, tmp_path / "past.csv")
    meta = generate_tasks(con, tmp_path / "tasks", TaskConfig(per_hit=5, gold_per_hit=1, n_frames=40, seed=1))
    assert meta["frames"] == 40 and meta["hits"] == 10 and meta["gold_available"] == 2
    with open(tmp_path / "tasks" / "batch.csv", newline="") as handle:
        hits = list(csv.DictReader(handle))
    template = (tmp_path / "tasks" / "hit_template.html").read_text()
    placeholders = set(re.findall(r"\$\{([a-z0-9_]+)\}", template))
    assert placeholders == {f"sentence_{k}" for k in range(1, 6)} and placeholders <= set(hits[0])
    assert "crowd-form" in template and 'name="rating_5"' in template
    preview = (tmp_path / "tasks" / "preview.html").read_text()
    assert hits[0]["sentence_1"] in preview and "${" not in preview
    assert sum(v.startswith("gold-") for h in hits for k, v in h.items() if k.startswith("frame_id")) == 10
    # Workers answer: G is careful, S gets the gold checks wrong; their results come back in.
    gold = dict(con.execute("select frame_id, expected_max from gold_items").fetchall())
    with open(tmp_path / "results.csv", "w", newline="") as handle:
        writer = None
        for n, hit in enumerate(hits):
            for worker in ("G", "S"):
                row = {
                    "HITId": f"H{n}",
                    "AssignmentId": f"{worker}{n}",
                    "WorkerId": worker,
                    "AssignmentStatus": "Submitted",
                }
                row |= {f"Input.{k}": v for k, v in hit.items()}
                for k in range(1, 6):
                    fid = hit[f"frame_id_{k}"]
                    right = gold.get(fid, 3)
                    row[f"Answer.rating_{k}"] = str(right if worker == "G" else 6 - right) if fid else ""
                writer = writer or csv.DictWriter(handle, fieldnames=list(row))
                if n == 0 and worker == "G":
                    writer.writeheader()
                writer.writerow(row)
    counts = ingest_ratings(con, tmp_path / "results.csv")
    assert counts["items_loaded"] == 100
    table = worker_table(con).set_index("worker_id")
    assert table.loc["G", "gold_accuracy"] == 1.0 and table.loc["S", "gold_accuracy"] == 0.0
    rows = decisions(con)
    rejected = {r["AssignmentId"] for r in rows if r["Reject"]}
    assert rejected == {f"S{n}" for n in range(10)} and all("gold checks" in r["Reject"] for r in rows if r["Reject"])
    out = write_decisions(tmp_path / "decisions.csv", rows)
    assert out.read_text().splitlines()[0] == "AssignmentId,HITId,WorkerId,AssignmentStatus,Approve,Reject"
    assert con.execute("select count(*) from frame_ratings where arg1 like 'gold%'").fetchone() == (0,)
    assert set(alpha_by_verb(con)) >= {"all", "pour"}
    ds = dawid_skene(con)  # gold items are left out; every rated frame gets a label 1-5 beside its mean
    assert len(ds) == con.execute("select count(*) from frame_ratings").fetchone()[0]
    assert ds["dawid_skene"].between(1, 5).all() and {"mean", "count"} <= set(ds.columns)


def test_preview_page_structure(con, tmp_path):
    """What a browser would show, checked by parsing: every slot's sentence and five required radios."""
    from html.parser import HTMLParser

    generate_tasks(con, tmp_path / "tasks", TaskConfig(per_hit=4, gold_per_hit=0, n_frames=8))

    class Page(HTMLParser):
        def __init__(self):
            super().__init__()
            self.radios, self.required, self.sentences, self.in_sentence = {}, set(), [], False

        def handle_starttag(self, tag, attrs):
            attrs = dict(attrs)
            if tag == "input" and attrs.get("type") == "radio":
                self.radios.setdefault(attrs["name"], []).append(attrs["value"])
                if "required" in attrs:
                    self.required.add(attrs["name"])
            self.in_sentence = tag == "p" and attrs.get("class") == "sentence"

        def handle_data(self, data):
            if self.in_sentence and data.strip():
                self.sentences.append(data.strip())

    page = Page()
    page.feed((tmp_path / "tasks" / "preview.html").read_text())
    with open(tmp_path / "tasks" / "batch.csv", newline="") as handle:
        first = next(csv.DictReader(handle))
    assert page.sentences == [first[f"sentence_{k}"] for k in range(1, 5)]
    assert page.radios == {f"rating_{k}": ["1", "2", "3", "4", "5"] for k in range(1, 5)}
    assert page.required == set(page.radios)


BROWSER_DIR = Path(__file__).resolve().parents[1] / "annotation" / "browser"


@pytest.mark.skipif(
    not (shutil.which("node") and (BROWSER_DIR / "node_modules" / "@sparticuz" / "chromium").exists()),
    reason="headless Chromium not installed (make browser)",
)
def test_preview_in_headless_browser(con, tmp_path):
    """The preview as Chromium renders it offline: every sentence visible with five clickable radios,
    no unfilled placeholder, and a screenshot that is not blank."""
    from PIL import Image

    generate_tasks(con, tmp_path / "tasks", TaskConfig(per_hit=4, gold_per_hit=0, n_frames=8))
    shot = tmp_path / "preview.png"
    run = subprocess.run(
        ["node", str(BROWSER_DIR / "check_preview.mjs"), str(tmp_path / "tasks" / "preview.html"), str(shot)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    seen = json.loads(run.stdout.strip().splitlines()[-1])
    with open(tmp_path / "tasks" / "batch.csv", newline="") as handle:
        first = next(csv.DictReader(handle))
    assert [i["sentence"] for i in seen["items"]] == [first[f"sentence_{k}"] for k in range(1, 5)]
    assert all(i["visible"] and i["required"] for i in seen["items"])
    assert [i["radios"] for i in seen["items"]] == [[f"rating_{k}={v}" for v in range(1, 6)] for k in range(1, 5)]
    assert seen["checked"] == [f"rating_{k}" for k in range(1, 5)] and not seen["unfilled"]
    image = Image.open(shot).convert("L")
    low, high = image.getextrema()
    assert image.width >= 800 and high - low > 100  # text on a background, not an empty page


def test_disagreement_picks_frames_the_scorers_rank_differently():
    pool = [("pour", {"Theme": "water", "Destination": o}) for o in ["cup", "glass", "bowl", "sink"]]
    a = lambda frames: [1.0, 2.0, 3.0, 4.0]  # noqa: E731
    b = lambda frames: [4.0, 2.1, 2.9, 1.0]  # noqa: E731 - agrees on glass and bowl
    picked = disagreement_frames(pool, {"a": a, "b": b}, 2)
    assert {f[1]["Destination"] for f in picked} == {"cup", "sink"}


def _slots(hit: dict) -> list[str]:
    return [hit[k] for k in sorted(hit, key=lambda k: int(k.rsplit("_", 1)[1])) if k.startswith("frame_id_")]


@pytest.mark.parametrize("n_frames, gold_ratings", [(13, True), (13, False), (3, False)])
def test_no_hit_has_blank_or_repeated_slots(con, tmp_path, n_frames, gold_ratings):
    if gold_ratings:
        seed_ratings(con, tmp_path / "past.csv")
    meta = generate_tasks(con, tmp_path / "tasks", TaskConfig(per_hit=5, gold_per_hit=1, n_frames=n_frames, seed=2))
    with open(tmp_path / "tasks" / "batch.csv", newline="") as handle:
        hits = list(csv.DictReader(handle))
    for hit in hits:
        slots = _slots(hit)
        assert all(value for value in hit.values()), hit  # nothing a worker would have to rate blank
        assert len({s.removeprefix("gold-").removeprefix("f-") for s in slots}) == len(slots)
    width = len(_slots(hits[0]))
    assert width == min(5, n_frames + (2 if gold_ratings else 0))
    asked = {s for hit in hits for s in _slots(hit) if s.startswith("f-")}
    assert len(asked) == n_frames and meta["frames"] == n_frames  # every frame asked, the fill re-asks some


def test_tasks_json_carries_the_hit_settings(con, tmp_path):
    from typer.testing import CliRunner

    from lmcr.cli import app

    con.close()
    db = tmp_path / "lmcr.duckdb"
    args = [
        "annotate",
        "tasks",
        "--out",
        str(tmp_path / "t"),
        "--n-frames",
        "12",
        "--db",
        str(db),
        "--reward",
        "0.45",
        "--assignments",
        "5",
        "--title",
        "Rate kitchen sentences",
        "--min-approved-hits",
        "0",
        "--locale",
        "GB",
    ]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    hit = json.loads((tmp_path / "t" / "tasks.json").read_text())["hit"]
    assert hit["Reward"] == "0.45" and hit["MaxAssignments"] == 5 and hit["Title"] == "Rate kitchen sentences"
    assert hit["AssignmentDurationInSeconds"] == 1800 and hit["LifetimeInSeconds"] == 7 * 24 * 3600
    quals = {q["QualificationTypeId"]: q for q in hit["QualificationRequirements"]}
    assert quals["000000000000000000L0"]["IntegerValues"] == [95]
    assert quals["00000000000000000071"]["LocaleValues"] == [{"Country": "GB"}]
    assert "00000000000000000040" not in quals  # 0 approved HITs: no requirement
    bad = CliRunner().invoke(app, args[:-6] + ["--reward", "$1", "--out", str(tmp_path / "u")])
    assert bad.exit_code == 1 and "reward must be dollars and cents" in bad.output and not (tmp_path / "u").exists()


def test_one_mace_start_is_what_five_would_give():
    """The worker table runs MACE once because crowd-kit seeds every restart alike: were a later crowd-kit
    to vary its restarts, five starts would differ from one here, and the single start would need review."""
    import warnings

    import numpy as np
    import pandas as pd
    from crowdkit.aggregation import MACE

    rng = np.random.default_rng(3)
    data = pd.DataFrame(
        {
            "task": [f"t{i}" for i in range(40) for _ in range(4)],
            "worker": [f"w{k}" for _ in range(40) for k in rng.choice(8, size=4, replace=False)],
            "label": rng.integers(1, 6, size=160),
        }
    ).sort_values("worker", kind="stable")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one, five = (MACE(n_restarts=n, n_iter=10, random_state=0).fit(data).spamming_ for n in (1, 5))
    assert np.array_equal(np.asarray(one), np.asarray(five))
