"""The evaluation report: Table I and Fig. 4 A-D as Markdown, HTML (plots embedded) and PNG, plus a
JSON of every figure. Everything is written to a temporary folder and renamed into place."""

from __future__ import annotations

import base64
import html
import json
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: reports are built by flows and CI, never shown
import matplotlib.pyplot as plt  # noqa: E402

from lmcr.evaluate.protocol import Results  # noqa: E402
from lmcr.files import atomic_dir  # noqa: E402

FIGURES = {
    "fig4a": ("methods", "vs_lambda", "lambda (rating threshold)", "A: methods vs lambda (k={k})"),
    "fig4b": ("methods", "vs_k", "k (candidates per scenario)", "B: methods vs k (lambda={lam:g})"),
    "fig4c": ("settings", "vs_lambda", "lambda (rating threshold)", "C: LM settings vs lambda (k={k})"),
    "fig4d": ("settings", "vs_k", "k (candidates per scenario)", "D: LM settings vs k (lambda={lam:g})"),
}


# One look per series, so that series with identical values stay visible: nested markers of falling
# size and different dash patterns (no offsets: every point sits at its true x).
STYLES = [
    ("o", "-", 9),
    ("s", "--", 7.5),
    ("^", "-.", 6.5),
    ("D", ":", 5.5),
    ("v", "-", 4.5),
    ("P", "--", 4),
    ("X", "-.", 3.5),
    ("*", ":", 3),
]


def _fmt(x: float | None) -> str:
    return "n/a" if x is None else f"{x:.3f}"


def table1_markdown(results: Results, methods: list[str], paper: dict[str, dict[str, float]]) -> str:
    """Per-verb accuracy of each method; the paper's published figures beside ours for the methods it has."""
    verbs = sorted({v for m in methods for v in results.table1.get(m, {}) if v != "all"}) + ["all"]
    published = [m for m in methods if m in paper]
    head = "| verb | " + " | ".join(methods + [f"paper {m}" for m in published]) + " |"
    rule = "|" + "---|" + "---:|" * (len(methods) + len(published))
    rows = [
        f"| {v} | "
        + " | ".join(
            [_fmt(results.table1.get(m, {}).get(v)) for m in methods] + [_fmt(paper[m].get(v)) for m in published]
        )
        + " |"
        for v in verbs
    ]
    return "\n".join([head, rule] + rows)


def plot(results: Results, series: list[str], key: str, xlabel: str, title: str, out: Path) -> dict:
    """One line per series (PNG and its data); identical series stay distinguishable by their style."""
    data = {m: getattr(results, key).get(m, {}) for m in series}
    fig, ax = plt.subplots(figsize=(7.6, 4.2), dpi=150)
    for i, (m, points) in enumerate(data.items()):
        if points:
            marker, dash, size = STYLES[i % len(STYLES)]
            xs = sorted(points)
            ax.plot(
                xs,
                [points[x] for x in xs],
                marker=marker,
                linestyle=dash,
                markersize=size,
                linewidth=1.4,
                markerfacecolor="none" if i % 2 else None,
                label=m,
            )
    ax.set_xlabel(xlabel)
    ax.set_ylabel("accuracy")
    ax.set_ylim(0, 1.02)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    if any(data.values()):
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)  # never over data
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)
    return {m: {f"{x:g}": a for x, a in points.items()} for m, points in data.items()}


def distinct_settings(results: Results, methods: list[str], settings: list[str]) -> list[str]:
    """The LM settings that add a column to Table I: not a method already there under its own name
    ('sentence_lm/all' when Table I's sentence_lm is the all-corpora model: same figures)."""
    return [
        s
        for s in settings
        if s not in methods and results.table1.get(s) != results.table1.get(s.partition("/")[0], object())
    ]


def _grouped(reasons: dict[str, str]) -> str:
    """'verb: reason' pairs, verbs sharing a reason listed once: 'reason (blend, brush)'."""
    by_reason: dict[str, list[str]] = {}
    for verb, why in reasons.items():
        by_reason.setdefault(why, []).append(verb)
    return "; ".join(f"{why} ({', '.join(verbs)})" for why, verbs in by_reason.items())


def write_report(
    results: Results,
    methods: list[str],
    settings: list[str],
    out_dir: Path,
    notes: list[str],
    provenance: dict | None = None,
    paper: dict[str, dict[str, float]] | None = None,
) -> Path:
    """Write report.md, report.html, fig4{a,b,c,d}.png and figures.json into `out_dir` (replaced whole)."""
    with atomic_dir(out_dir) as tmp:
        _write_files(results, methods, settings, tmp, notes, provenance or {}, paper or {})
    return Path(out_dir)


def sample_banner(provenance: dict) -> list[str]:
    files = provenance.get("sample_files") or []
    if not files:
        return []
    return [
        f"> **Sample data.** This report was built from LMCR's embedded sample ({len(files)} input files, "
        "e.g. `" + files[0] + "`): it shows the report's layout, not LMCR's accuracy. The README's Results "
        "give the figures on the full corpora and ratings.\n"
    ]


def provenance_markdown(provenance: dict) -> list[str]:
    if not provenance:
        return []
    lines = [
        f"- Built {provenance['date']} by lmcr {provenance['lmcr']}, commit `{provenance['git_commit']}`, "
        f"on {provenance['machine']}."
    ]
    lines += [f"- Ratings `{f['file']}` sha256 `{f['sha256'][:16]}`" for f in provenance["ratings"]]
    if "mixture" in provenance:
        lines.append(
            f"- Corpus mixture of the bare method names: {provenance['mixture']}; weight of the context term "
            f"in completion: {provenance.get('context_weight', 1):g} (`lmcr mixture`; the rated frames have "
            "no context)"
        )
    lines += [
        f"- Checkpoint {c['setting']}: `{c['version']}`, manifest sha256 `{c['manifest_sha256'][:16]}`"
        for c in provenance["checkpoints"]
    ]
    corpus = provenance["corpus"]
    lines += [f"- Corpus file `{f['file']}` sha256 `{f['sha256'][:16]}`" for f in corpus[:20]]
    if len(corpus) > 20:
        lines.append(f"- ... and {len(corpus) - 20} more corpus files (all in figures.json)")
    return ["## Provenance\n", "\n".join(lines), ""]


def _write_files(
    results: Results,
    methods: list[str],
    settings: list[str],
    tmp: Path,
    notes: list[str],
    provenance: dict,
    paper: dict[str, dict[str, float]],
) -> None:
    cfg = results.config
    groups = {"methods": methods, "settings": settings}
    figures = {"table1": results.table1, "paper_table1": paper, **results.to_json(), "provenance": provenance}
    sections = [
        "# LMCR evaluation\n",
        *sample_banner(provenance),
        f"Scenarios per verb: {cfg.per_verb}, seed {cfg.seed}. Table I at "
        f"lambda={cfg.lam:g}, k={cfg.k}: {results.scenarios.get(f'lambda={cfg.lam:g},k={cfg.k}', 0)} scenarios.\n",
        "## Table I: accuracy per verb\n",
        table1_markdown(results, methods + distinct_settings(results, methods, settings), paper),
        "",
    ]
    if paper:
        sections += ["Columns *paper X* are the paper's published Table I (its LMCR column beside our sentence_lm).\n"]
    for name, (group, key, xlabel, title) in FIGURES.items():
        figures[name] = plot(
            results, groups[group], key, xlabel, title.format(k=cfg.k, lam=cfg.lam), tmp / f"{name}.png"
        )
        sections += [f"## Fig. 4{name[-1].upper()}\n", f"![{name}]({name}.png)\n"]
    skipped = [f"- {point}: {_grouped(verbs)}" for point, verbs in results.skipped.items()]
    skipped += [f"- k={k} left out of the k sweep: {why}" for k, why in results.skipped_k.items()]
    sections += [
        "## Skipped\n",
        "\n".join(skipped) or "nothing",
        "",
        "## Notes and deviations from the paper\n",
        "\n".join(f"- {n}" for n in notes),
        "",
        *provenance_markdown(provenance),
    ]
    markdown = "\n".join(sections)
    (tmp / "report.md").write_text(markdown, encoding="utf-8")
    (tmp / "figures.json").write_text(json.dumps(figures, indent=2, default=str), encoding="utf-8")
    (tmp / "report.html").write_text(render_html(markdown, tmp), encoding="utf-8")


STYLE = (
    "body{font-family:sans-serif;max-width:62em;margin:auto;padding:0 1em}"
    ".scroll{overflow-x:auto;max-width:100%;border:1px solid #eee}"
    "table{border-collapse:collapse;font-variant-numeric:tabular-nums}td,th{border:1px solid #ccc;padding:2px 6px}"
    "blockquote{background:#fff4d6;border-left:4px solid #e0a800;margin:1em 0;padding:.5em 1em}"
    "img{max-width:100%}"
)


def render_html(markdown: str, folder: Path) -> str:
    """A self-contained page rendered by markdown-it-py (CommonMark + tables): wide tables scroll in
    their own box, plots are embedded as data URIs."""
    from markdown_it import MarkdownIt

    body = MarkdownIt("commonmark", {"html": False}).enable("table").render(markdown)
    body = body.replace("<table>", '<div class="scroll"><table>').replace("</table>", "</table></div>")

    def embed(match: re.Match) -> str:
        data = base64.b64encode((folder / html.unescape(match.group(1))).read_bytes()).decode()
        return f'src="data:image/png;base64,{data}"'

    body = re.sub(r'src="(fig4[a-d]\.png)"', embed, body)
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>LMCR evaluation</title>"
        f"<style>{STYLE}</style></head><body>{body}</body></html>"
    )
