"""The `lmcr ingest` command: summary output, skip on re-run, one-line errors with non-zero exit."""

from __future__ import annotations

from typer.testing import CliRunner

from lmcr.cli import app
from lmcr.setting import Setting

runner = CliRunner()


def test_ingest_sample_then_rerun(sample_dir, tmp_path, monkeypatch):
    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path))
    args = [
        "ingest",
        "--youcook2",
        str(sample_dir / "youcook2"),
        "--recipes",
        str(sample_dir / "nyc"),
        "--recipes",
        str(sample_dir / "feeding_america"),
        "--workers",
        "1",
    ]
    first = runner.invoke(app, args)
    assert first.exit_code == 0, first.output
    assert "youcook2" in first.output and "4 loaded, 0 unchanged" in first.output
    assert (tmp_path / "lmcr.duckdb").exists()
    second = runner.invoke(app, args)
    assert "0 loaded, 4 unchanged (skipped)" in second.output


def test_ingest_errors_are_one_line(sample_dir, tmp_path, monkeypatch):
    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path))
    missing = runner.invoke(app, ["ingest", "--recipes", str(tmp_path / "nope.jsonl")])
    assert missing.exit_code == 1 and "nope.jsonl: no such file or folder" in missing.output
    bad = tmp_path / "bad.xml"
    bad.write_text("<cookbook>\n<recipe>\n</cookbook>")
    broken = runner.invoke(app, ["ingest", "--recipes", str(bad)])
    assert broken.exit_code == 1 and "bad.xml:3: malformed XML" in broken.output
    nothing = runner.invoke(app, ["ingest"])
    assert nothing.exit_code == 1 and "nothing to ingest" in nothing.output


def test_version_and_fixed_choices():
    import lmcr

    assert runner.invoke(app, ["--version"]).stdout.strip() == f"lmcr {lmcr.__version__}"
    typo = runner.invoke(app, ["train", "--corpus", "recipe"])
    assert typo.exit_code == 1 and "'youcook2', 'recipes', 'household', 'all'" in typo.output


def test_train_passes_its_settings_seed_included(monkeypatch, tmp_path):
    from lmcr.lm import run

    seen = {}
    monkeypatch.setattr(
        run, "train_setting", lambda *args, **kw: seen.update(setting=args[2], config=args[4]) or tmp_path / "v1"
    )
    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path))
    result = runner.invoke(app, ["train", "--corpus", "household", "--seed", "7", "--max-epochs", "2"])
    assert result.exit_code == 0, result.output
    assert seen["config"].seed == 7 and seen["config"].max_epochs == 2 and "published" in result.output
    assert seen["setting"] == Setting("sentence", "household")


def test_light_commands_do_not_import_the_heavy_libraries():
    import subprocess
    import sys

    code = "import sys, lmcr.cli; print(','.join(m for m in ('torch', 'gensim', 'scipy', 'spacy') if m in sys.modules))"
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert loaded == ""


def _commands(group, prefix=()):
    import typer.main

    click_group = typer.main.get_group(group) if not hasattr(group, "commands") else group
    for name, command in click_group.commands.items():
        if hasattr(command, "commands"):
            yield from _commands(command, prefix + (name,))
        else:
            yield prefix + (name,), command


def test_every_option_and_argument_has_help():
    import typer.main

    missing = [
        f"{' '.join(path)} {param.name}"
        for path, command in _commands(typer.main.get_group(app))
        for param in command.params
        if not getattr(param, "help", None)
    ]
    missing += [f"lmcr {param.name}" for param in typer.main.get_group(app).params if not param.help]
    assert missing == []


def test_data_dir_option_is_the_environment_variable(sample_dir, tmp_path, monkeypatch):
    monkeypatch.delenv("LMCR_DATA_DIR", raising=False)
    monkeypatch.delenv("LMCR_DB", raising=False)
    data = tmp_path / "elsewhere"
    result = runner.invoke(
        app, ["--data-dir", str(data), "ingest", "--recipes", str(sample_dir / "nyc"), "--workers", "1"]
    )
    assert result.exit_code == 0, result.output
    assert (data / "lmcr.duckdb").exists()
    listed = runner.invoke(app, ["--data-dir", str(data), "query", "corpus_summary", "--format", "json"])
    import json

    row = json.loads(listed.stdout.splitlines()[0])
    assert row["corpus"] == "recipes" and all(isinstance(row[k], int) for k in row if k != "corpus")


def test_a_data_dir_that_is_a_file_is_one_line(tmp_path, monkeypatch):
    monkeypatch.delenv("LMCR_DB", raising=False)
    afile = tmp_path / "afile"
    afile.write_text("x")
    result = runner.invoke(app, ["--data-dir", str(afile), "migrate"])
    assert result.exit_code == 1 and f"{afile} is a file, not a folder" in result.output
    assert len(result.output.strip().splitlines()) == 1 and afile.read_text() == "x"
