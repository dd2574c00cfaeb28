"""MkDocs hook: the pages made from the code and the data at build time, never typed by hand.

- `reference/cli.md`: every `lmcr` command, its usage, help and options, walked from the typer app;
- `reference/schema.md`: the store's schema page (`lmcr schema`), from the catalog's comments;
- `results.md`: the figures the benchmarks recorded in `bench/results/*.json` (see bench/record.py),
  each with its command, date, commit and machine, and the benchmarks that have recorded none;
- `img/`: the pictures the guide shows, taken from where the code writes them.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from mkdocs.structure.files import File, Files

REPO_ROOT = Path(__file__).resolve().parent.parent
BENCH_DIR = REPO_ROOT / "bench"
IMAGES = {
    "img/pour_me_some_water.png": REPO_ROOT / "bench" / "renders" / "pour_me_some_water.png",
    "img/pour_me_some_water.gif": REPO_ROOT / "bench" / "renders" / "pour_me_some_water.gif",
    "img/preview_screenshot.png": REPO_ROOT / "annotation" / "preview_screenshot.png",
}
RECORD_FIELDS = ("benchmark", "title", "command", "date", "commit", "machine", "figures")


def on_files(files: Files, config) -> Files:
    """Add the generated pages and the pictures to the site's files."""
    from lmcr.catalog import schema_page

    pages = {
        "reference/cli.md": cli_reference(),
        "reference/schema.md": schema_page(REPO_ROOT / "sql"),
        "results.md": results_page(BENCH_DIR),
    }
    for uri, text in pages.items():
        files.append(File.generated(config, uri, content=text))
    for uri, path in IMAGES.items():
        files.append(File.generated(config, uri, abs_src_path=str(path)))
    return files


# ---------------------------------------------------------------- the CLI reference


def cli_reference() -> str:
    """Markdown for every command of `lmcr` (sub-apps' commands under their group), in the app's order."""
    import typer

    from lmcr.cli import app

    root = typer.main.get_command(app)
    ctx = root.context_class(root, info_name="lmcr")
    lines = [
        "# Command reference",
        "",
        "Generated from the `lmcr` command line itself when the site is built: every command's usage, "
        "help and options, as `lmcr COMMAND --help` prints them.",
        "",
        "## lmcr",
        "",
        _usage(root, ctx),
        "",
        paragraphs(root.help or ""),
        "",
        *_options(root, ctx),
    ]
    for name, command, sub_ctx in _commands(root, ctx):
        lines += ["", f"## lmcr {name}", "", _usage(command, sub_ctx), "", paragraphs(command.help or "")]
        lines += ["", *_options(command, sub_ctx)]
    return "\n".join(lines).rstrip() + "\n"


def _commands(group, ctx, prefix: str = ""):
    """(full name, command, context) for each visible command, depth first."""
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        if command is None or command.hidden:
            continue
        sub_ctx = command.context_class(command, info_name=name, parent=ctx)
        if hasattr(command, "list_commands"):
            yield from _commands(command, sub_ctx, f"{prefix}{name} ")
        else:
            yield f"{prefix}{name}", command, sub_ctx


def _usage(command, ctx) -> str:
    return "```\n" + command.get_usage(ctx).strip() + "\n```"


def _options(command, ctx) -> list[str]:
    """A table of the command's arguments and options (the shell-completion helpers left out)."""
    rows = []
    for param in command.params:
        record = param.get_help_record(ctx)
        if record is None or param.name in ("install_completion", "show_completion"):
            continue
        flags, text = record
        rows.append(f"| `{flags}` | {escape_cell(paragraphs(text))} |")
    if not rows:
        return ["No arguments or options."]
    return ["| argument / option | meaning |", "|---|---|", *rows]


def paragraphs(text: str) -> str:
    """Help text as Markdown: lines of a paragraph joined, blank lines kept, click's \\b markers dropped."""
    blocks = [
        " ".join(line.strip() for line in block.splitlines() if line.strip() != "\b")
        for block in re.split(r"\n\s*\n", text.strip())
    ]
    return "\n\n".join(escape_html(block) for block in blocks if block)


def escape_html(text: str) -> str:
    """`<` and `>` outside code spans as entities, so `<path>` stays text and is no HTML tag."""
    parts = re.split(r"(`[^`]*`)", text)
    return "".join(part if part.startswith("`") else part.replace("<", "&lt;").replace(">", "&gt;") for part in parts)


def escape_cell(text: str) -> str:
    """Text that fits in one Markdown table cell."""
    return text.replace("\n\n", "<br>").replace("|", "\\|")


# ---------------------------------------------------------------- the results page


def load_records(results_dir: Path) -> list[dict]:
    """The recorded results, by benchmark then file name; a malformed file fails the build naming it."""
    records = []
    for path in sorted(results_dir.glob("*.json")):
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise ValueError(f"{path}: not a benchmark record: {exc}") from None
        missing = [f for f in RECORD_FIELDS if not isinstance(record, dict) or f not in record]
        if missing or not isinstance(record["figures"], dict):
            raise ValueError(f"{path}: not a benchmark record: missing {missing or ['figures as an object']}")
        records.append({**record, "file": path.name})
    return records


def benchmark_usage(script: Path) -> tuple[str, str]:
    """A benchmark script's one-line purpose and its usage line (from its docstring)."""
    doc = re.search(r'^"""(.*?)"""', script.read_text(encoding="utf-8"), re.S)
    text = doc.group(1).strip() if doc else ""
    usage = re.search(rf"python bench/{re.escape(script.name)}[^\n]*", text)
    return (text.splitlines()[0] if text else script.stem), (usage.group(0).strip() if usage else "")


def results_page(bench_dir: Path) -> str:
    """Markdown of every recorded benchmark result, and of every benchmark with none recorded yet."""
    records = load_records(bench_dir / "results")
    scripts = sorted(bench_dir.glob("bench_*.py"))
    recorded = {r["benchmark"] for r in records}
    lines = [
        "# Results",
        "",
        "Generated when the site is built from the JSON files the benchmarks write into `bench/results/` "
        "(`bench/record.py`). Every figure here is one a benchmark printed, with the exact command, the date "
        "(UTC), the commit (`-dirty`: with uncommitted changes) and the machine it ran on; to add or refresh "
        "one, run the benchmark and commit its JSON file. Nothing on this page is typed by hand.",
        "",
    ]
    for record in records:
        lines += [
            f"## {record['benchmark']}",
            "",
            escape_html(record["title"]),
            "",
            f"- command: `{record['command']}`",
            f"- date: {record['date']}",
            f"- commit: `{record['commit'] or 'unknown'}`",
            f"- machine: {escape_html(record['machine'])}"
            + (
                f" (load average {' / '.join(map(str, record['load_average']))} over 1 / 5 / 15 min)"
                if record.get("load_average")
                else ""
            ),
            f"- file: `bench/results/{record['file']}`",
            "",
            "| figure | value |",
            "|---|---|",
        ]
        lines += [
            f"| {escape_cell(escape_html(str(k)))} | {escape_cell(escape_html(_value(v)))} |"
            for k, v in record["figures"].items()
        ]
        lines.append("")
    missing = [s for s in scripts if s.stem not in recorded]
    lines += ["## Benchmarks with no recorded result yet", ""]
    if not missing:
        lines.append("Every benchmark has a recorded result.")
    for script in missing:
        purpose, usage = benchmark_usage(script)
        lines.append(f"- `{script.name}`: {escape_html(purpose)}" + (f" Run: `{usage}`" if usage else ""))
    return "\n".join(lines).rstrip() + "\n"


def _value(value) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return f"{value:,}"
    return str(value)
