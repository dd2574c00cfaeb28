"""The documentation's generated pages (docs/hooks.py): the results page shows exactly what the benchmarks
recorded (bench/record.py) and names the benchmarks with no record; the command reference covers every
command and option of the CLI. `make test` builds the whole site with `mkdocs build --strict`."""

from __future__ import annotations

import importlib.util
import json
import sys

import pytest

from lmcr.checkout import REPO_ROOT


def load_module(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


hooks = load_module(REPO_ROOT / "docs" / "hooks.py", "docs_hooks")
record = load_module(REPO_ROOT / "bench" / "record.py", "bench_record")

SCRIPT = '"""Benchmark: how fast {0} is.\n\nUsage: python bench/{0}.py [--runs N]\n"""\n'


def bench_dir(tmp_path, *names):
    (tmp_path / "results").mkdir()
    for name in names:
        (tmp_path / f"{name}.py").write_text(SCRIPT.format(name), encoding="utf-8")
    return tmp_path


def test_a_benchmarks_record_is_on_the_results_page_and_the_others_are_named(tmp_path, monkeypatch):
    bench = bench_dir(tmp_path, "bench_fast", "bench_slow")
    monkeypatch.setattr(sys, "argv", ["bench/bench_fast.py", "--runs", "3"])
    record.write_results(
        str(bench / "results" / "bench_fast.json"),
        "bench_fast",
        "How fast it is.",
        {"median s": 0.412, "items": 12345, "target met": True},
    )
    written = json.loads((bench / "results" / "bench_fast.json").read_text(encoding="utf-8"))
    assert written["command"].endswith("bench_fast.py --runs 3") and written["date"] and written["machine"]
    page = hooks.results_page(bench)
    assert "## bench_fast\n\nHow fast it is.\n" in page
    assert "| median s | 0.412 |" in page and "| items | 12,345 |" in page and "| target met | yes |" in page
    assert f"`{written['command']}`" in page and written["date"] in page
    missing = page.split("## Benchmarks with no recorded result yet", 1)[1]
    assert "`bench_slow.py`" in missing and "python bench/bench_slow.py [--runs N]" in missing
    assert "bench_fast.py" not in missing


@pytest.mark.parametrize(
    "text, reason",
    [
        ("{not json", "not a benchmark record"),
        ('{"benchmark": "b", "figures": {}}', "missing"),
        ('["a list"]', "missing"),
    ],
)
def test_a_damaged_record_fails_the_build_naming_the_file(tmp_path, text, reason):
    bench = bench_dir(tmp_path, "bench_fast")
    (bench / "results" / "bench_fast.json").write_text(text, encoding="utf-8")
    with pytest.raises(ValueError, match=rf"bench_fast\.json: .*{reason}"):
        hooks.results_page(bench)


def test_the_committed_results_are_well_formed_and_come_from_existing_benchmarks():
    scripts = {p.stem for p in (REPO_ROOT / "bench").glob("bench_*.py")}
    for rec in hooks.load_records(REPO_ROOT / "bench" / "results"):
        assert rec["benchmark"] in scripts, rec["file"]
        assert rec["command"].startswith(("python bench/", "LMCR_")) and rec["figures"], rec["file"]


def test_the_command_reference_covers_every_command_and_option():
    import typer

    from lmcr.cli import app

    page = hooks.cli_reference()
    root = typer.main.get_command(app)
    ctx = root.context_class(root, info_name="lmcr")
    names = list(hooks._commands(root, ctx))
    assert {"complete", "execute", "annotate ingest", "sql"} <= {name for name, _, _ in names}
    for name, command, _ in names:
        section = page.split(f"\n## lmcr {name}\n", 1)[1].split("\n## ", 1)[0]
        assert command.get_short_help_str(200).split(".")[0][:40] in " ".join(section.split())
        for param in command.params:
            if param.name != "help":
                assert f"`{param.opts[0] if param.opts[0].startswith('-') else param.name}" in section, (name, param)


def test_help_text_becomes_markdown_that_cannot_break_a_table():
    assert (
        hooks.paragraphs("One line\nand the next.\n\n\b\nSecond <path> and `<kept>`.")
        == "One line and the next.\n\nSecond &lt;path&gt; and `<kept>`."
    )
    assert hooks.escape_cell("a | b\n\nc") == "a \\| b<br>c"
