"""Benchmark: the external request sets end to end on the simulated Baxter, in scenes of each item's objects.

Usage: python bench/bench_external_robot.py --sets DIR [--seed 0] [--urdf PATH] [--work DIR] [--json PATH]
Each item of each set (`<set>.jsonl` of DIR, as `bench/bench_external.py` reads them) gets a seeded
random scene of its own objects: the stated object on the counter, or in the hand when the counter has
no room for it beside the others. Most of those objects have no body in the simulated world (a sofa, a
closet, a sweater); each such one is built like a known object of the kind its role asks for
(`"like"` in the scene format): the stated Theme like a sponge (moved) or like the surface, food or
pot a tool acts on, and every candidate for the missing role like a basket (a Destination) or like the
tool of the verb's learned class of motion (an Instrument), or a pot for a verb learned as a cook
(`STAND_INS`). The completion sees the
item's own words; the robot moves and checks the bodies.

The robot is asked only the items whose words alone complete right (as `lmcr complete` does them, with
the same objects: the scene's completion is the same one), since the bar is over those; one
`lmcr execute --input IN.jsonl --output OUT.jsonl` process (the published checkpoint and store of
$LMCR_DATA_DIR) runs them all, and its own completion is judged again. Per set it prints: completed
right (the item's predicate, its stated roles, and for the missing role an object of `expected_any`), and
of those, executed successfully (the
bar of issue 50: >= 0.95), executed plans that failed, refused before moving (with the reasons), and
scenes that did not fit the table; then per instruction time (median, max) and the batch's wall clock.
"""

from __future__ import annotations

import argparse
import collections
import json
import sys
import tempfile
from pathlib import Path

from bench_end_to_end import timed_batch, timing
from record import add_json_option, write_results

from lmcr.evaluate.external import complete_line, right_predicate
from lmcr.jsonl import InputError, read_jsonl
from lmcr.lexicon import normalize_name as normalize
from lmcr.partial import SIDECAR
from lmcr.robot.scene import has_shape, scene_from_json
from lmcr.scorers.registry import COMPLETION_METHOD
from lmcr.workspace import Workspace

FIELDS = {"id": (str, int), "instruction": str, "objects": list, "missing": str, "expected": dict, "verb": str}
# what an object without a body is built like, by what the request does with it: (role, the verb's
# learned class of motion) -> a known object; None stands for any class
STAND_INS = {
    ("Theme", None): "sponge",  # moved: put away, brought, thrown out
    ("Destination", None): "basket",  # where it goes
    ("Theme", "wipe"): "cutting board",  # what a cloth wipes
    ("Instrument", "wipe"): "sponge",
    ("Theme", "cut"): "bread",
    ("Instrument", "cut"): "knife",
    ("Theme", "stir"): "batter",
    ("Instrument", "stir"): "whisk",
    ("Theme", "cover"): "pot",
    ("Instrument", "cover"): "lid",
    ("Instrument", "cook"): "pot",  # where a Theme is cooked
    ("Destination", "cook"): "pot",
    ("Instrument", None): "sponge",
}


def stand_in(role: str, motion: str | None) -> str:
    """The known object a label without a body is built like, for its role in the request."""
    return STAND_INS.get((role, motion)) or STAND_INS[(role, None)]


def scene_for(record: dict, motion: str | None, seed: int) -> dict:
    """The item's scene: its objects (each without a body built like its role's stand-in), the stated
    Theme on the table, else in the hand when the table has no room for it."""
    missing, roles = record["missing"], record["expected"]["roles"]
    theme = roles.get("Theme") if missing != "Theme" else None

    def entry(label: str) -> dict:
        role = "Theme" if label == theme else missing
        return {"label": label} if has_shape(label) else {"label": label, "like": stand_in(role, motion)}

    on_table = [entry(label) for label in dict.fromkeys([*record["objects"], *([theme] if theme else [])])]
    scene = {"objects": on_table, "seed": seed}
    try:
        scene_from_json(scene, "scene")
        return scene
    except InputError:
        if theme is None:
            raise
    held = next(o for o in on_table if o["label"] == theme)
    scene = {"objects": [o for o in on_table if o is not held], "seed": seed, "holding": held}
    scene_from_json(scene, "scene")  # the others fit without it, or InputError
    return scene


def completed_right(record: dict, out: dict) -> bool:
    """The item's predicate, each role it states as stated, and an object of `expected_any` for the
    missing role."""
    if "error" in out:
        return False
    frame, expected = out["frame"], record["expected"]["roles"]
    roles = {role: normalize(value) for role, value in frame["roles"].items()}
    stated = {role: normalize(value) for role, value in expected.items() if role != record["missing"]}
    return (
        right_predicate(frame["predicate"], record["verb"])
        and roles.get(record["missing"]) in {normalize(o) for o in record["expected_any"]}
        and all(roles.get(role) == value for role, value in stated.items())
    )


def batch_lines(sets: Path, seed: int) -> tuple[list[dict], list[dict], collections.Counter, collections.Counter]:
    """The items completed right from their words alone, each with its batch line (its scene); per set,
    how many were completed wrong and how many scenes did not fit."""
    ws = Workspace.from_env()
    parser, (scorer, config) = ws.parser(), ws.completion_scorer(COMPLETION_METHOD)
    records, lines, unfit, wrong = [], [], collections.Counter(), collections.Counter()
    for path in sorted(sets.glob("*.jsonl")):
        for k, (_, record) in enumerate(read_jsonl(path, FIELDS)):
            said = complete_line(parser, scorer, config, record["instruction"], record["objects"])
            if not completed_right(record, said):
                wrong[path.stem] += 1
                continue
            spec = parser.lex.predicates.get(normalize(record["verb"]).removesuffix(" of"))
            try:
                scene = scene_for(record, spec.motion if spec else None, seed * 1000 + k)
            except InputError:
                unfit[path.stem] += 1
                continue
            records.append({**record, "set": path.stem})
            lines.append({"id": str(record["id"]), "instruction": record["instruction"], "scene": scene})
    return records, lines, wrong, unfit


def tally(records: list[dict], outs: dict[str, dict]) -> tuple[dict, collections.Counter]:
    """Per set: items run, those the scene's completion got right (an error counts: the words completed
    right, and the robot had no motion for them), executed successfully, failed, refused (an error is a
    refusal); and the refusals' reasons."""
    per, reasons = collections.defaultdict(collections.Counter), collections.Counter()
    for record in records:
        out, c = outs[str(record["id"])], per[record["set"]]
        c["n"] += 1
        if "error" not in out and not completed_right(record, out):
            print(f"  completed otherwise {record['id']} {record['instruction']!r}: {out['frame']}")
            continue
        c["right"] += 1
        c["success"] += out.get("success", False)
        c["failed"] += out.get("feasible", False) and not out["success"]
        if "error" in out or not out["feasible"]:
            c["refused"] += 1
            why = out.get("error") or out.get("reason")
            reasons[f"{record['verb']}: {str(why).split(' (it can ')[0][:90]}"] += 1
            print(f"  refused {record['id']} {record['instruction']!r}: {why}")
        elif not out["success"]:
            print(f"  FAILED {record['id']} {record['instruction']!r}: {out['checks']}")
    return per, reasons


def main() -> None:
    args_ = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args_.add_argument("--sets", type=Path, required=True, help="folder of <set>.jsonl request sets")
    args_.add_argument("--seed", type=int, default=0)
    args_.add_argument("--urdf", help="the official Baxter URDF instead of the built-in one")
    args_.add_argument("--work", type=Path, help="folder for IN.jsonl / OUT.jsonl (default: a temporary one)")
    add_json_option(args_, "bench_external_robot")
    args = args_.parse_args()
    records, lines, wrong, unfit = batch_lines(args.sets, args.seed)
    work = args.work or Path(tempfile.mkdtemp(prefix="lmcr-external-robot-"))
    work.mkdir(parents=True, exist_ok=True)
    inp, outp = work / "in.jsonl", work / "out.jsonl"
    inp.write_text("".join(json.dumps(line) + "\n" for line in lines))
    outp.unlink(missing_ok=True)
    outp.with_name(outp.name + SIDECAR).unlink(missing_ok=True)  # a killed run's: this one starts afresh
    command = [sys.executable, "-m", "lmcr.cli", "execute", "--input", str(inp), "--output", str(outp)]
    command += ["--urdf", args.urdf] if args.urdf else []
    wall, times = timed_batch(command, outp)
    outs = {o["id"]: o for o in map(json.loads, outp.read_text().splitlines())}
    per, reasons = tally(records, outs)
    figures = {"seed": args.seed, "items run": len(records)}
    for name in sorted({*per, *wrong, *unfit}):
        c, items = per[name], per[name]["n"] + wrong[name] + unfit[name]
        share = c["success"] / c["right"] if c["right"] else 0.0
        print(
            f"{name:10s} {items} items: completed right {c['right'] + unfit[name]} ({unfit[name]} in scenes that "
            f"did not fit the table); of the {c['right']} run, executed successfully {c['success']} = {share:.3f}, "
            f"executed plans that failed {c['failed']}, refused before moving {c['refused']}"
        )
        figures |= {
            f"{name}: completed right": f"{c['right'] + unfit[name]}/{items}",
            f"{name}: scenes that did not fit": unfit[name],
            f"{name}: executed successfully, of those run": f"{c['success']}/{c['right']}",
            f"{name}: executed successfully, share": round(share, 3),
            f"{name}: executed plans that failed": c["failed"],
            f"{name}: refused before moving": c["refused"],
        }
    total = sum(per.values(), collections.Counter())
    print("refused:", json.dumps(dict(reasons.most_common()), indent=1))
    timed, timed_figures = timing(times, list(outs.values()))
    print(
        f"all: of {total['right']} completed right and run, {total['success']} executed successfully "
        f"({total['success'] / max(total['right'], 1):.3f}); {sum(unfit.values())} more did not fit; batch of "
        f"{len(records)}: {wall:.0f} s; {timed}"
    )
    figures |= {
        "all: executed successfully, of those run": f"{total['success']}/{total['right']}",
        "all: scenes that did not fit": sum(unfit.values()),
        "all: executed plans that failed": total["failed"],
        "batch wall seconds": round(wall, 1),
        **timed_figures,
    }
    write_results(args.json, "bench_external_robot", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
