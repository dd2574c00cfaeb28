"""Checkpoints: a directory per setting and version, every file hashed in `manifest.json`.

Layout: `<root>/<linearization>-<corpus>/<version>/{model.pt, model.json, vocab.json,
linearization.json, metrics.json, provenance.json, manifest.json}` and `<root>/<setting>/LATEST`
naming the version in use. A version is written under a temporary name and renamed; LATEST is
replaced atomically; loading re-hashes every file and refuses a mismatch. Only torch and the model
file are needed to load and score.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

import torch

from lmcr.errors import LMCRError, one_line
from lmcr.files import atomic_path, file_sha256
from lmcr.lm.model import LMConfig, RecurrentLM
from lmcr.lm.vocab import Vocab

FILES = ("model.pt", "model.json", "vocab.json", "linearization.json", "metrics.json", "provenance.json")
MANIFEST = "manifest.json"
VERSION_RE = re.compile(r"^v\d{8}-\d{6}-\d+$")
# A version being written: `.<version>.<pid>.tmp`; one whose process is gone was killed mid-publish.
TMP_RE = re.compile(r"^\.(v\d{8}-\d{6}-\d+)\.(\d+)\.tmp$")


class CheckpointError(LMCRError, RuntimeError):
    """A checkpoint is missing, incomplete or was modified after publishing."""


@dataclass
class Checkpoint:
    path: Path
    model: RecurrentLM
    vocab: Vocab
    linearization: str
    metrics: dict
    provenance: dict


def _write_json(path: Path, data: object) -> None:
    path.write_text(json.dumps(data, indent=1, sort_keys=True), encoding="utf-8")


def publish(root: Path, setting: str, model: RecurrentLM, vocab: Vocab, linearization: str,
            metrics: dict, provenance: dict, promote: bool = True) -> Path:
    """Write a new version of `setting` atomically; point LATEST at it when `promote` (callers that
    record the run first publish with promote=False and call `set_latest` after recording)."""
    remove_stale_tmp(root / setting)
    stamp, n = time.strftime("v%Y%m%d-%H%M%S"), 1
    while (root / setting / f"{stamp}-{n}").exists():  # several versions within one second
        n += 1
    version = f"{stamp}-{n}"
    final = root / setting / version
    tmp = root / setting / f".{version}.{os.getpid()}.tmp"
    tmp.mkdir(parents=True)
    try:
        torch.save({k: v.cpu() for k, v in model.state_dict().items()}, tmp / "model.pt")
        _write_json(tmp / "model.json", model.config.to_json())
        _write_json(tmp / "vocab.json", vocab.to_json())
        _write_json(tmp / "linearization.json", {"linearization": linearization})
        _write_json(tmp / "metrics.json", metrics)
        _write_json(tmp / "provenance.json", provenance)
        _write_json(tmp / MANIFEST, {"setting": setting, "version": version,
                                     "files": {name: file_sha256(tmp / name) for name in FILES}})
        os.replace(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    if promote:
        set_latest(root, setting, version)
    return final


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


def set_latest(root: Path, setting: str, version: str) -> None:
    """Point the setting's LATEST at `version` (atomic replace)."""
    if not VERSION_RE.match(version) or not (root / setting / version / MANIFEST).is_file():
        raise CheckpointError(f"{root / setting}: no published version {version!r}")
    with atomic_path(root / setting / "LATEST") as tmp:
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


def verify(path: Path) -> dict:
    """Check that the manifest lists exactly the checkpoint's files, that the folder holds exactly
    those (plus the manifest), that each hashes as listed, and that the manifest names this folder's
    setting and version; return the manifest or raise CheckpointError."""
    path = Path(path)
    manifest_path = path / MANIFEST
    if not manifest_path.is_file():
        raise CheckpointError(f"{path}: no manifest.json (not a published checkpoint)")
    try:
        manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
        listed = manifest["files"]
        setting, version = manifest["setting"], manifest["version"]
    except (ValueError, KeyError, TypeError) as exc:
        raise CheckpointError(f"{manifest_path}: malformed manifest") from exc
    if not isinstance(listed, dict) or set(listed) != set(FILES):
        raise CheckpointError(f"{manifest_path}: lists {sorted(listed) if isinstance(listed, dict) else listed!r}, "
                              f"not the checkpoint's files {sorted(FILES)}")
    present = {p.name for p in path.iterdir()} - {MANIFEST}
    if present != set(FILES):
        raise CheckpointError(f"{path}: holds {sorted(present ^ set(FILES))} beyond or short of the manifest")
    if (version, setting) != (path.name, path.parent.name):
        raise CheckpointError(f"{manifest_path}: is {setting}/{version}, not {path.parent.name}/{path.name}")
    for name, expected in listed.items():
        if file_sha256(path / name) != expected:
            raise CheckpointError(f"{path / name}: sha256 differs from the manifest (modified after publishing)")
    return manifest


def load(path: Path, device: str = "cpu") -> Checkpoint:
    """Load a verified checkpoint (a version directory or a setting directory's LATEST)."""
    path = resolve(path)
    verify(path)

    def read(name: str) -> object:
        return json.loads((path / name).read_text(encoding="utf-8"))

    try:
        model = RecurrentLM(LMConfig(**read("model.json")))
        model.load_state_dict(torch.load(path / "model.pt", map_location=device, weights_only=True))
        checkpoint = Checkpoint(path, model.eval(), Vocab.from_json(read("vocab.json")),
                                read("linearization.json")["linearization"], read("metrics.json"), read("provenance.json"))
    except (ValueError, KeyError, TypeError, RuntimeError, EOFError, OSError) as exc:
        raise CheckpointError(f"{path}: cannot load: {one_line(exc, 200)}") from exc
    if not path.parent.name.startswith(f"{checkpoint.linearization}-"):
        raise CheckpointError(f"{path}: holds a {checkpoint.linearization} model, not one of {path.parent.name}")
    return checkpoint
