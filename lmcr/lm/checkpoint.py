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
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

import torch

from lmcr.files import atomic_path, file_sha256
from lmcr.lm.model import LMConfig, RecurrentLM
from lmcr.lm.vocab import Vocab

FILES = ("model.pt", "model.json", "vocab.json", "linearization.json", "metrics.json", "provenance.json")


class CheckpointError(RuntimeError):
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
    """Write a new version of `setting` atomically; point LATEST at it when `promote`."""
    stamp, n = time.strftime("v%Y%m%d-%H%M%S"), 1
    while (root / setting / f"{stamp}-{n}").exists():  # several versions within one second
        n += 1
    version = f"{stamp}-{n}"
    final = root / setting / version
    tmp = root / setting / f".{version}.tmp"
    tmp.mkdir(parents=True)
    try:
        torch.save({k: v.cpu() for k, v in model.state_dict().items()}, tmp / "model.pt")
        _write_json(tmp / "model.json", model.config.to_json())
        _write_json(tmp / "vocab.json", vocab.to_json())
        _write_json(tmp / "linearization.json", {"linearization": linearization})
        _write_json(tmp / "metrics.json", metrics)
        _write_json(tmp / "provenance.json", provenance)
        _write_json(tmp / "manifest.json", {"setting": setting, "version": version,
                                            "files": {name: file_sha256(tmp / name) for name in FILES}})
        os.replace(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    if promote:
        set_latest(root, setting, version)
    return final


def set_latest(root: Path, setting: str, version: str) -> None:
    """Point the setting's LATEST at `version` (atomic replace)."""
    with atomic_path(root / setting / "LATEST") as tmp:
        tmp.write_text(version + "\n", encoding="utf-8")


def resolve(path: Path) -> Path:
    """A version directory, or a setting directory (its LATEST version)."""
    path = Path(path)
    if (path / "LATEST").exists():
        return path / (path / "LATEST").read_text(encoding="utf-8").strip()
    return path


def verify(path: Path) -> dict:
    """Re-hash every file listed in the manifest; return the manifest or raise CheckpointError."""
    manifest_path = path / "manifest.json"
    if not manifest_path.exists():
        raise CheckpointError(f"{path}: no manifest.json (not a published checkpoint)")
    manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
    for name, expected in manifest["files"].items():
        file = path / name
        if not file.exists():
            raise CheckpointError(f"{file}: listed in the manifest but missing")
        if file_sha256(file) != expected:
            raise CheckpointError(f"{file}: sha256 differs from the manifest (modified after publishing)")
    return manifest


def load(path: Path, device: str = "cpu") -> Checkpoint:
    """Load a verified checkpoint (a version directory or a setting directory's LATEST)."""
    path = resolve(path)
    verify(path)

    def read(name: str) -> object:
        return json.loads((path / name).read_text(encoding="utf-8"))

    model = RecurrentLM(LMConfig(**read("model.json")))
    model.load_state_dict(torch.load(path / "model.pt", map_location=device, weights_only=True))
    model.eval()
    return Checkpoint(path, model, Vocab.from_json(read("vocab.json")), read("linearization.json")["linearization"],
                      read("metrics.json"), read("provenance.json"))
