"""Benchmark: SRL accuracy on the dev sets, what the imperative repair is worth, parser throughput.

Usage: python bench/bench_srl.py [--shared DIR] [--db STORE] [--resources DIR] [--sample N] [--json PATH]
Prints dev-set role F1 / predicate recall / instruction accuracy with and without the repair; on
600 corpus sentences that start with a robot predicate, how often the parser finds that predicate
with and without the build's first-word table; words/s of the parser on N corpus instruction
sentences with 1 and 2 processes, and the last full frame-corpus build recorded in the store (wall
time, words/s).
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import duckdb
from record import add_json_option, add_shared_option, write_results

from lmcr.jsonl import read_jsonl
from lmcr.srl.evaluate import instruction_correct, score_frames
from lmcr.srl.instruction import NoPredicateError, parse_instruction
from lmcr.srl.parser import load_parser
from lmcr.store import read_connection
from lmcr.workspace import Workspace


def dev_scores(parser, eval_dir: Path) -> dict:
    """Role F1 and predicate recall on the SRL dev set, and the instructions parsed right."""
    gold = [r for _, r in read_jsonl(eval_dir / "srl_dev.jsonl", {"text": str, "frames": list})]
    predicted = [[f.to_json() for f in found] for found in parser.pipe(r["text"] for r in gold)]
    overall = score_frames([r["frames"] for r in gold], predicted, set(parser.lex.hand_written)).table()[-1]
    tasks = [r for _, r in read_jsonl(eval_dir / "instructions_dev.jsonl", {"instruction": str})]
    right = 0
    for task in tasks:
        try:
            right += instruction_correct(
                parse_instruction(parser, task["instruction"]).to_json(), task["expected"], task["missing"]
            )
        except NoPredicateError:
            pass
    return {
        "role F1": round(overall["role_f1"], 3),
        "predicate recall": round(overall["pred_r"], 3),
        "instructions parsed right": f"{right}/{len(tasks)}",
    }


def first_predicates(con: duckdb.DuckDBPyConnection, resources: Path, n: int = 600) -> dict:
    """Of `n` corpus sentences that start with a robot predicate ("Heat oven to 425 degrees F."), how many
    the parser gives that predicate's frame, without and with the first-word table of `resources`."""
    parser = load_parser(resources=resources)
    predicates = parser.lex.hand_written  # the eleven: the table is about their imperatives
    texts = [
        r[0]
        for r in con.execute(
            "select text from sentences where kind = 'instruction' and lower(split_part(text, ' ', 1)) in "
            "(select unnest(?)) order by hash(text) limit ?",
            [predicates, n],
        ).fetchall()
    ]

    def found(table: dict) -> int:
        parser.forget_first_words(table)
        return sum(
            any(f.predicate == t.split()[0].lower() for f in frames) for t, frames in zip(texts, parser.pipe(texts))
        )

    with_table = found(parser.first_words)
    return {"without the first-word table": f"{found({})}/{len(texts)}", "with it": f"{with_table}/{len(texts)}"}


def _throughput(texts: list[str], resources: str) -> tuple[int, float]:
    parser = load_parser(resources=Path(resources))
    parser.learn_first_words = True  # as the frame build's workers parse
    started = time.perf_counter()
    for _ in parser.pipe(texts):
        pass
    return sum(len(t.split()) for t in texts), time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_shared_option(parser)
    parser.add_argument("--db", type=Path, default=None)
    parser.add_argument("--resources", type=Path, default=None)
    parser.add_argument("--sample", type=int, default=40_000)
    add_json_option(parser, "bench_srl")
    args = parser.parse_args()
    figures = {}
    paths = Workspace.from_env(db=args.db)
    resources = args.resources or paths.srl_dir
    for repair in (False, True):
        srl = load_parser(resources=resources)
        srl.repair = repair
        scores = dev_scores(srl, args.shared / "eval")
        print(f"dev, repair={'on ' if repair else 'off'}: " + " ".join(f"{k}={v}" for k, v in scores.items()))
        figures |= {f"dev set, imperative repair {'on' if repair else 'off'}: {k}": v for k, v in scores.items()}
    con = read_connection(paths.db)
    found = first_predicates(con, resources)
    print(
        "corpus sentences starting with a robot predicate, the predicate found: "
        + ", ".join(f"{k} {v}" for k, v in found.items())
    )
    figures |= {f"corpus sentences starting with a robot predicate, found {k}": v for k, v in found.items()}
    texts = [
        r[0]
        for r in con.execute(
            "select text from sentences where kind = 'instruction' order by hash(doc_id || sent_id) limit ?",
            [args.sample],
        ).fetchall()
    ]
    halves = [texts[: len(texts) // 2], texts[len(texts) // 2 :]]
    words, wall = _throughput(texts[: len(texts) // 4], str(resources))
    print(f"1 process: {words / wall:,.0f} words/s ({words:,} words)")
    figures["parser words/s, 1 process"] = round(words / wall)
    started = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        results = list(pool.map(_throughput, halves, [str(resources)] * 2))
    wall = time.perf_counter() - started
    words = sum(w for w, _ in results)
    print(f"2 processes: {words / wall:,.0f} words/s ({words:,} words, {wall:.1f}s incl. model load)")
    figures["parser words/s, 2 processes"] = round(words / wall)
    build = con.execute(
        "select sentences, words, wall_s, words_per_s, reparsed, reparse_kept, frames, known_frames "
        "from frame_builds order by built_at desc limit 1"
    ).fetchone()
    if build:
        print(
            f"last full build: {build[0]:,} sentences, {build[1]:,} words in {build[2]:.0f}s = {build[3]:,.0f} "
            f"words/s; re-parsed {build[4]:,} (kept {build[5]:,}); {build[6]:,} frames, "
            f"{build[7]:,} of robot predicates"
        )
        names = ("sentences", "words", "wall s", "words/s", "frames", "frames of robot predicates")
        values = (build[0], build[1], round(build[2]), round(build[3]), build[6], build[7])
        figures |= {f"the store's last frame build: {k}": v for k, v in zip(names, values)}
    write_results(args.json, "bench_srl", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
