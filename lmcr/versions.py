"""Published versions: a folder per name and version, every file hashed in `manifest.json`, `LATEST`
naming the version in use. Language-model checkpoints and speech models are published this way.

A version is written under a temporary name and renamed; LATEST is replaced atomically; loading
re-hashes every file and refuses a mismatch, so a half-written or edited version is never used.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import time
from collections.abc import Callable
from pathlib import Path

from lmcr.errors import LMCRError
from lmcr.files import atomic_path, file_sha256

MANIFEST = "manifest.json"
VERSION_RE = re.compile(r"^v\d{8}-\d{6}-\d+$")
# A version being written: `.<version>.<pid>.tmp`; one whose process is gone was killed mid-publish.
TMP_RE = re.compile(r"^\.(v\d{8}-\d{6}-\d+)\.(\d+)\.tmp$")


class CheckpointError(LMCRError, RuntimeError):
    """A published version is missing, incomplete or was modified after publishing."""


def publish_version(
    root: Path, name: str, files: tuple[str, ...], write: Callable[[Path], None], promote: bool = True
) -> Path:
    """Write a new version of `name` (a folder under `root`: an LM setting's `Setting.name`, a speech
    model's name): `write(folder)` creates exactly `files` in a temporary folder, the manifest hashes them,
    the folder is renamed into place, and LATEST points at it when `promote`."""
    remove_stale_tmp(root / name)
    stamp, n = time.strftime("v%Y%m%d-%H%M%S"), 1
    while (root / name / f"{stamp}-{n}").exists():  # several versions within one second
        n += 1
    version = f"{stamp}-{n}"
    final = root / name / version
    tmp = root / name / f".{version}.{os.getpid()}.tmp"
    tmp.mkdir(parents=True)
    try:
        write(tmp)
        write_json(
            tmp / MANIFEST,
            {"setting": name, "version": version, "files": {name: file_sha256(tmp / name) for name in files}},
        )
        os.replace(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    if promote:
        set_latest(root, name, version)
    return final


def write_json(path: Path, data: object) -> None:
    path.write_text(json.dumps(data, indent=1, sort_keys=True), encoding="utf-8")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale_tmp(setting_dir: Path) -> list[Path]:
    """Remove half-written versions left by a killed publish (their process is gone); return them."""
    removed = []
    for path in setting_dir.glob(".v*.tmp") if setting_dir.is_dir() else []:
        match = TMP_RE.match(path.name)
        if match is None or not _alive(int(match.group(2))):  # the old unnamed-pid form is stale too
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
    return removed


def set_latest(root: Path, name: str, version: str) -> None:
    """Point the LATEST of `name`'s folder at `version` (atomic replace)."""
    if not VERSION_RE.match(version) or not (root / name / version / MANIFEST).is_file():
        raise CheckpointError(f"{root / name}: no published version {version!r}")
    with atomic_path(root / name / "LATEST") as tmp:
        tmp.write_text(version + "\n", encoding="utf-8")


def resolve(path: Path) -> Path:
    """A version directory, or a setting directory (its LATEST version). LATEST must name a version
    folder of that setting: a path elsewhere (`../frame-all/v...`) is refused."""
    path = Path(path)
    latest = path / "LATEST"
    if not latest.exists():
        return path
    try:
        version = latest.read_text(encoding="utf-8").strip()
    except (OSError, UnicodeDecodeError) as exc:
        raise CheckpointError(f"{latest}: unreadable") from exc
    if not VERSION_RE.match(version):
        raise CheckpointError(f"{latest}: {version[:80]!r} is not a version name of this setting")
    if not (path / version).is_dir():
        raise CheckpointError(f"{latest}: names {version}, which is not in {path}")
    return path / version


def verify(path: Path, files: tuple[str, ...]) -> dict:
    """Check that the manifest lists exactly `files`, that the folder holds exactly
    those (plus the manifest), that each hashes as listed, and that the manifest names this folder's
    setting and version; return the manifest or raise CheckpointError."""
    path = Path(path)
    manifest_path = path / MANIFEST
    if not manifest_path.is_file():
        raise CheckpointError(f"{path}: no manifest.json (not a published version)")
    try:
        manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
        listed = manifest["files"]
        setting, version = manifest["setting"], manifest["version"]
    except (ValueError, KeyError, TypeError) as exc:
        raise CheckpointError(f"{manifest_path}: malformed manifest") from exc
    if not isinstance(listed, dict) or set(listed) != set(files):
        raise CheckpointError(
            f"{manifest_path}: lists {sorted(listed) if isinstance(listed, dict) else listed!r}, "
            f"not the version's files {sorted(files)}"
        )
    present = {p.name for p in path.iterdir()} - {MANIFEST}
    if present != set(files):
        raise CheckpointError(f"{path}: holds {sorted(present ^ set(files))} beyond or short of the manifest")
    if (version, setting) != (path.name, path.parent.name):
        raise CheckpointError(f"{manifest_path}: is {setting}/{version}, not {path.parent.name}/{path.name}")
    for name, expected in listed.items():
        if file_sha256(path / name) != expected:
            raise CheckpointError(f"{path / name}: sha256 differs from the manifest (modified after publishing)")
    return manifest
