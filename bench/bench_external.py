"""Benchmark: the external request sets (IntroPlan, HuRIC, TidyBot, COAT) completed as `lmcr complete` does.

Usage: python bench/bench_external.py [--sets DIR] [--data-dir DIR] [--method M] [--json PATH] [--out-jsonl PATH]
--sets: the folder of `<set>.jsonl` files (default $LMCR_SHARED_DIR/eval/external). The data folder
(--data-dir, else $LMCR_DATA_DIR) gives the store, checkpoints, mixture, context weight and the
calibration `lmcr evaluate` wrote there, as for `lmcr complete`. Per set: right predicate (named with
its particle: `put away`) and missing role, top guess among `expected_any`, questions asked (help rate),
how often the prediction set holds a right object and its mean size (KnowNo's success and help), the
share with no completion and why, and the latency of one completion (p50, p90). Then, per set, the
learned verbs' prediction sets had they been calibrated (`lmcr evaluate --requests`) on the other three
sets' requests: how often they hold a right object, and their mean size. The measures are defined in
lmcr/evaluate/external.py. --out-jsonl writes one line per item: its set, the completion
line (`prediction_set` included, or its error) and its outcome.

--peer [GGUF] adds the peer's rows (lmcr/evaluate/peer.py): the same items put zero-shot to a small
offline LM (Gemma 3 270M from the `peer` extra, or the GGUF file given), under each of its scorings;
--peer-only leaves the product's rows out.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from record import add_json_option, run_or_exit, write_results

from lmcr.evaluate import peer
from lmcr.evaluate.external import cross_calibrated, read_sets, run_set, summarize
from lmcr.files import check_output_file
from lmcr.jsonl import InputError, write_jsonl_atomic
from lmcr.scorers.registry import COMPLETION_METHOD
from lmcr.workspace import Workspace

COLUMNS = (
    ("items", "items", "{:d}"),
    ("pred+role", "right predicate and missing role", "{:.3f}"),
    ("top", "top guess right", "{:.3f}"),
    ("asked", "questions asked", "{:.3f}"),
    ("set holds", "set holds a right object", "{:.3f}"),
    ("set size", "mean set size", "{:.2f}"),
    ("errors", "errors", "{:.3f}"),
    ("p50 ms", "p50 ms", "{:.1f}"),
    ("p90 ms", "p90 ms", "{:.1f}"),
)
CROSS_COLUMNS = (
    ("set holds", "set holds a right object", "{:.3f}"),
    ("set size", "mean set size", "{:.2f}"),
    ("temperature", "temperature", "{:.3g}"),
    ("threshold", "set threshold", "{:.4f}"),
)


def sets_folder(given: Path | None) -> Path:
    """--sets, else $LMCR_SHARED_DIR/eval/external; neither is an InputError."""
    if given is not None:
        return given
    shared = os.environ.get("LMCR_SHARED_DIR")
    if not shared:
        raise InputError("no request sets: give --sets DIR or set LMCR_SHARED_DIR")
    return Path(shared) / "eval" / "external"


def table(summaries: dict[str, dict], columns: tuple = COLUMNS) -> str:
    """The sets' figures, one row per set."""

    def cell(value, form: str) -> str:
        return "-" if value is None else form.format(value)

    rows = [["set", *(head for head, _, _ in columns)]]
    rows += [[name, *(cell(s[key], form) for _, key, form in columns)] for name, s in summaries.items()]
    widths = [max(len(row[k]) for row in rows) for k in range(len(rows[0]))]
    return "\n".join(
        "  ".join(c.rjust(w) if k else c.ljust(w) for k, (c, w) in enumerate(zip(row, widths))) for row in rows
    )


def flat(name: str, summary: dict) -> dict:
    """A set's figures as the results page lists them: `<set>: <figure>`, the errors and wrong predicates
    one figure per reason."""
    figures = {f"{name}: {k}": v for k, v in summary.items() if not isinstance(v, dict)}
    figures |= {f"{name}: {k} (count)": v for k, v in summary["counts"].items()}
    figures |= {f"{name}: error {reason!r}": count for reason, count in summary["error reasons"].items()}
    figures |= {f"{name}: predicate read as {pair}": count for pair, count in summary["wrong predicates"].items()}
    return figures


def outcome_fields(outcome) -> dict:
    """An outcome as its item's output line carries it: what the line does not already say (its id, error)."""
    return {k: round(v, 3) if k == "ms" else v for k, v in outcome.to_json().items() if k not in ("id", "error")}


def main() -> None:
    parser_ = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser_.add_argument("--sets", type=Path, default=None, help="folder of <set>.jsonl request sets")
    parser_.add_argument("--data-dir", type=Path, default=None, help="data folder (default $LMCR_DATA_DIR)")
    parser_.add_argument("--method", default=COMPLETION_METHOD, help=f"completion method (default {COMPLETION_METHOD})")
    parser_.add_argument("--out-jsonl", type=Path, default=None, help="one line per item: completion and outcome")
    parser_.add_argument("--peer", nargs="?", const="", default=None, metavar="GGUF", help="add the offline LM peer")
    parser_.add_argument("--peer-only", action="store_true", help="only the peer's rows")
    add_json_option(parser_, "bench_external")
    args = parser_.parse_args()
    run_or_exit(run, args)


def run(args: argparse.Namespace) -> None:
    sets = read_sets(sets_folder(args.sets))
    if args.out_jsonl is not None:
        check_output_file(args.out_jsonl)
    ws = Workspace.from_env(data_dir=args.data_dir)
    figures, lines = {"sets": ", ".join(sets)}, []
    if not args.peer_only:
        figures |= product_rows(ws, args.method, sets, lines)
    if args.peer is not None or args.peer_only:
        figures |= peer_table(ws, args.peer or None, sets, lines)
    if args.out_jsonl is not None:
        write_jsonl_atomic(args.out_jsonl, lines)
        print(f"{len(lines)} items written to {args.out_jsonl}")
    write_results(args.json, "bench_external", __doc__.splitlines()[0], figures)


def product_rows(ws: Workspace, method: str, sets: dict, lines: list) -> dict:
    """The product's figures per set (printed as a table), its lines appended to `lines`."""
    scorer, config = ws.completion_scorer(method)
    parser = ws.parser()
    print(f"{method}; {config.source}")
    summaries, completed = {}, {}
    for name, items in sets.items():
        done = run_set(parser, scorer, config, items)
        summaries[name] = summarize(items, [outcome for _, outcome in done])
        completed[name] = [line for line, _ in done]
        lines += [{"set": name, **line, "outcome": outcome_fields(outcome)} for line, outcome in done]
    print(table(summaries))
    for name, summary in summaries.items():
        reasons = ", ".join(f"{reason} {count}" for reason, count in summary["error reasons"].items())
        print(f"{name}: errors: {reasons or 'none'}")
    figures = {"method": method, "calibration": config.source, "learned verbs' calibration": learned_source(config)}
    for name, summary in summaries.items():
        figures |= flat(name, summary)
    cross = cross_calibrated(sets, completed, parser.lex.learned)
    print("the learned verbs' prediction sets calibrated on the other sets' requests (lmcr evaluate --requests):")
    print(table(cross, CROSS_COLUMNS))
    for name, row in cross.items():
        figures |= {f"cross-calibrated: {name}: {k}": v for k, v in row.items()}
    return figures


def learned_source(config) -> str:
    """Where the learned verbs' temperature and threshold came from."""
    return config.learned_source or "as the eleven's (no `lmcr evaluate --requests` calibration)"


def peer_table(ws: Workspace, gguf: str | None, sets: dict, lines: list) -> dict:
    """The peer's figures per set and scoring (printed as a table), its answers appended to `lines`."""
    model_file = Path(gguf) if gguf else peer.gguf_model_file(ws.data_dir / "baselines")
    print(f"peer: {model_file.name}, loading (a minute or two)", flush=True)
    lm = peer.load_peer(model_file)
    answers = {}
    for name, items in sets.items():
        answers[name] = [peer.answer(lm.logprob, item) for item in items]
        lines += [{"set": name, "peer": a.to_json()} for a in answers[name]]
        print(f"peer: {name} answered", flush=True)
    figures = {"peer": f"{model_file.name}, zero-shot, told the missing role"}
    for scoring in peer.SCORINGS:
        rows = peer.peer_rows(sets, answers, scoring)
        print(f"peer ({scoring} log-probability of the answer)")
        print(table({name: {**dict.fromkeys(key for _, key, _ in COLUMNS), **row} for name, row in rows.items()}))
        for name, row in rows.items():
            figures |= {f"peer {scoring}: {name}: {k}": v for k, v in row.items()}
    return figures


if __name__ == "__main__":
    main()
