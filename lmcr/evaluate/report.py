"""The evaluation report: Table I and Fig. 4 A-D as Markdown, HTML (plots embedded) and PNG, plus a
JSON of every figure. Everything is written to a temporary folder and renamed into place."""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: reports are built by flows and CI, never shown
import matplotlib.pyplot as plt  # noqa: E402

from lmcr.evaluate.protocol import Results  # noqa: E402
from lmcr.files import atomic_dir  # noqa: E402

# The paper's published figures are not in the shared data and cannot be fetched offline; a value
# added here (method -> verb/'all' -> accuracy) is printed beside ours, anything missing as "n/a".
PAPER: dict[str, dict[str, float]] = {}

FIGURES = {
    "fig4a": ("methods", "vs_lambda", "lambda (rating threshold)", "A: methods vs lambda (k={k})"),
    "fig4b": ("methods", "vs_k", "k (candidates per scenario)", "B: methods vs k (lambda={lam:g})"),
    "fig4c": ("settings", "vs_lambda", "lambda (rating threshold)", "C: LM settings vs lambda (k={k})"),
    "fig4d": ("settings", "vs_k", "k (candidates per scenario)", "D: LM settings vs k (lambda={lam:g})"),
}


def _fmt(x: float | None) -> str:
    return "n/a" if x is None else f"{x:.3f}"


def in_paper(method: str) -> bool:
    """The paper has the LMs (each setting) and the baselines, not our count model or sums of methods."""
    return "+" not in method and method.split("/")[0] != "frame_counts"


def table1_markdown(results: Results, methods: list[str]) -> str:
    verbs = sorted({v for m in methods for v in results.table1.get(m, {}) if v != "all"}) + ["all"]
    paper = [m for m in methods if in_paper(m)]
    head = "| verb | " + " | ".join(methods) + " | " + " | ".join(f"paper {m}" for m in paper) + " |"
    rule = "|" + "---|" * (1 + len(methods) + len(paper))
    rows = [f"| {v} | " + " | ".join(_fmt(results.table1.get(m, {}).get(v)) for m in methods) + " | "
            + " | ".join(_fmt(PAPER.get(m, {}).get(v)) for m in paper) + " |" for v in verbs]
    return "\n".join([head, rule] + rows)


def plot(results: Results, series: list[str], key: str, xlabel: str, title: str, out: Path) -> dict:
    """One line per series; returns the plotted data."""
    data = {m: getattr(results, key).get(m, {}) for m in series}
    fig, ax = plt.subplots(figsize=(6, 4), dpi=120)
    for m, points in data.items():
        if points:
            xs = sorted(points)
            ax.plot(xs, [points[x] for x in xs], marker="o", label=m)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("accuracy")
    ax.set_ylim(0, 1)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    if any(data.values()):
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)
    return {m: {f"{x:g}": a for x, a in points.items()} for m, points in data.items()}


def write_report(results: Results, methods: list[str], settings: list[str], out_dir: Path,
                 notes: list[str]) -> Path:
    """Write report.md, report.html, fig4{a,b,c,d}.png and figures.json into `out_dir` (replaced whole)."""
    with atomic_dir(out_dir) as tmp:
        _write_files(results, methods, settings, tmp, notes)
    return Path(out_dir)


def _write_files(results: Results, methods: list[str], settings: list[str], tmp: Path, notes: list[str]) -> None:
    cfg = results.config
    groups = {"methods": methods, "settings": settings}
    figures = {"table1": results.table1, "paper_table1": PAPER, **results.to_json()}
    sections = [f"# LMCR evaluation\n\nScenarios per verb: {cfg.per_verb}, seed {cfg.seed}. Table I at "
                f"lambda={cfg.lam:g}, k={cfg.k}: {results.scenarios.get(f'lambda={cfg.lam:g},k={cfg.k}', 0)} scenarios.\n",
                "## Table I: accuracy per verb\n", table1_markdown(results, methods + [s for s in settings if s not in methods]), ""]
    for name, (group, key, xlabel, title) in FIGURES.items():
        figures[name] = plot(results, groups[group], key, xlabel, title.format(k=cfg.k, lam=cfg.lam), tmp / f"{name}.png")
        sections += [f"## Fig. 4{name[-1].upper()}\n", f"![{name}]({name}.png)\n"]
    skipped = [f"- {point}: " + "; ".join(f"{v}: {why}" for v, why in verbs.items()) for point, verbs in results.skipped.items()]
    skipped += [f"- k={k} left out of the k sweep: {why}" for k, why in results.skipped_k.items()]
    sections += ["## Skipped\n", "\n".join(skipped) or "nothing", "", "## Notes and deviations from the paper\n",
                 "\n".join(f"- {n}" for n in notes), ""]
    markdown = "\n".join(sections)
    (tmp / "report.md").write_text(markdown, encoding="utf-8")
    (tmp / "figures.json").write_text(json.dumps(figures, indent=2, default=str), encoding="utf-8")
    (tmp / "report.html").write_text(_html(markdown, tmp), encoding="utf-8")


def _html(markdown: str, folder: Path) -> str:
    """A self-contained page: tables and lists from the Markdown, plots embedded as data URIs."""
    body, table = [], []
    for line in markdown.splitlines() + [""]:
        if line.startswith("|"):
            if not line.startswith("|---"):
                cells = [html.escape(c.strip()) for c in line.strip("|").split("|")]
                tag = "th" if not table else "td"
                table.append("<tr>" + "".join(f"<{tag}>{c}</{tag}>" for c in cells) + "</tr>")
            continue
        if table:
            body.append("<table>" + "".join(table) + "</table>")
            table = []
        if line.startswith("!["):
            name = line[line.index("(") + 1:line.index(")")]
            data = base64.b64encode((folder / name).read_bytes()).decode()
            body.append(f'<img alt="{name}" src="data:image/png;base64,{data}">')
        elif line.startswith("#"):
            level = len(line) - len(line.lstrip("#"))
            body.append(f"<h{level}>{html.escape(line.lstrip('#').strip())}</h{level}>")
        elif line.startswith("- "):
            body.append(f"<li>{html.escape(line[2:])}</li>")
        elif line.strip():
            body.append(f"<p>{html.escape(line)}</p>")
    style = "body{font-family:sans-serif;max-width:60em;margin:auto}td,th{border:1px solid #ccc;padding:2px 6px}table{border-collapse:collapse}"
    return f"<!doctype html><html><head><meta charset='utf-8'><title>LMCR evaluation</title><style>{style}</style></head><body>{''.join(body)}</body></html>"
