"""Checkpoints: a directory per setting and version, every file hashed in `manifest.json`.

Layout: `<root>/<linearization>-<corpus>/<version>/{model.pt, model.json, vocab.json,
linearization.json, metrics.json, provenance.json, manifest.json}` and `<root>/<setting>/LATEST`
naming the version in use, published and verified by `lmcr.versions`. Only torch and the model file
are needed to load and score.
"""

from __future__ import annotations

import json
import pickle
from dataclasses import dataclass
from pathlib import Path

import torch

from lmcr.errors import one_line
from lmcr.lm.model import LMConfig, RecurrentLM
from lmcr.lm.vocab import Vocab
from lmcr.setting import Setting
from lmcr.versions import CheckpointError, publish_version, remove_stale_tmp, resolve, write_json  # noqa: F401 - the checkpoint API callers use
from lmcr.versions import set_latest as set_latest_version
from lmcr.versions import verify as verify_version

FILES = ("model.pt", "model.json", "vocab.json", "linearization.json", "metrics.json", "provenance.json")


@dataclass
class Checkpoint:
    path: Path
    model: RecurrentLM
    vocab: Vocab
    linearization: str
    metrics: dict
    provenance: dict
    articles: bool = True  # whether its text kept a/an/the (`lm.linearize`); checkpoints before the key did


def publish(
    root: Path,
    setting: Setting,
    model: RecurrentLM,
    vocab: Vocab,
    metrics: dict,
    provenance: dict,
    promote: bool = True,
    articles: bool = True,
) -> Path:
    """Write a new version of `setting` (a model of its linearisation) atomically; point LATEST at it when
    `promote` (callers that record the run first publish with promote=False and call `set_latest` after
    recording)."""

    def write(folder: Path) -> None:
        torch.save({k: v.cpu() for k, v in model.state_dict().items()}, folder / "model.pt")
        write_json(folder / "model.json", model.config.to_json())
        write_json(folder / "vocab.json", vocab.to_json())
        write_json(folder / "linearization.json", {"linearization": setting.linearization, "articles": articles})
        write_json(folder / "metrics.json", metrics)
        write_json(folder / "provenance.json", provenance)

    return publish_version(root, setting.name, FILES, write, promote)


def set_latest(root: Path, setting: Setting, version: str) -> None:
    """Point `setting`'s LATEST under the checkpoints `root` at `version`."""
    set_latest_version(root, setting.name, version)


def verify(path: Path) -> dict:
    """The manifest of a checkpoint version whose files are exactly the checkpoint's, each as hashed."""
    return verify_version(path, FILES)


def read_weights(file: Path, device: str = "cpu") -> dict[str, torch.Tensor]:
    """The state dict of a `model.pt`: names to tensors, unpickled weights-only, so that a pickle of
    anything else is refused without running it (torch's own message advises the unsafe way round; it is
    not relayed). Every failure is a CheckpointError naming the file."""
    if file.is_file() and file.stat().st_size == 0:
        raise CheckpointError(f"{file}: empty file (cut short when written?); retrain or restore the checkpoint")
    try:
        state = torch.load(file, map_location=device, weights_only=True)
    except pickle.UnpicklingError:
        raise CheckpointError(f"{file}: not a weights-only state dict; refusing to load it") from None
    except (EOFError, KeyError, ValueError, RuntimeError, OSError) as exc:  # cut short, not a torch file
        raise CheckpointError(
            f"{file}: not a torch weights file ({type(exc).__name__}: {one_line(exc, 200) or 'no reason given'})"
        ) from exc
    if not isinstance(state, dict) or not all(
        isinstance(k, str) and isinstance(v, torch.Tensor) for k, v in state.items()
    ):
        raise CheckpointError(f"{file}: not a state dict of named tensors; refusing to load it")
    return state


def load(path: Path, device: str = "cpu") -> Checkpoint:
    """Load a verified checkpoint (a version directory or a setting directory's LATEST)."""
    path = resolve(path)
    verify(path)

    def read(name: str) -> object:
        return json.loads((path / name).read_text(encoding="utf-8"))

    weights = read_weights(path / "model.pt", device)
    try:
        model = RecurrentLM(LMConfig(**read("model.json")))
        model.load_state_dict(weights)
        text = read("linearization.json")
        checkpoint = Checkpoint(
            path,
            model.eval(),
            Vocab.from_json(read("vocab.json")),
            text["linearization"],
            read("metrics.json"),
            read("provenance.json"),
            bool(text.get("articles", True)),
        )
    except (ValueError, KeyError, TypeError, RuntimeError, EOFError, OSError) as exc:
        raise CheckpointError(f"{path}: cannot load: {one_line(exc, 200) or type(exc).__name__}") from exc
    if not path.parent.name.startswith(f"{checkpoint.linearization}-"):
        raise CheckpointError(f"{path}: holds a {checkpoint.linearization} model, not one of {path.parent.name}")
    return checkpoint
