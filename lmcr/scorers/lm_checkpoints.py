"""Which language-model checkpoints an LM scorer loads: the setting folder under the checkpoints root,
and under a corpus mixture the all-corpora LM plus each weighted corpus's LM at its share."""

from __future__ import annotations

from pathlib import Path

from lmcr.scorers.resources import MethodResources, corpus_words
from lmcr.setting import LM_METHODS, Setting


def lm_checkpoint_dir(checkpoints: Path, linearization: str, corpus: str) -> Path:
    """The setting folder `<checkpoints>/<linearization>-<corpus>`, or `checkpoints` itself when it is one
    checkpoint (a setting or version folder) of that linearisation."""
    setting = checkpoints / Setting(linearization, corpus).name
    if setting.exists():
        return setting
    if (checkpoints / "LATEST").exists() or (checkpoints / "manifest.json").exists():
        return checkpoints
    from lmcr.lm.checkpoint import CheckpointError

    raise CheckpointError(
        f"no {linearization} checkpoint for corpus {corpus!r} under {checkpoints} "
        f"(run `lmcr train --linearization {linearization} --corpus {corpus}`)"
    )


def load_lm(res: MethodResources, linearization: str, corpus: str):
    """The `LMScorer` of the `linearization` checkpoint trained on `corpus`."""
    from lmcr.lm import checkpoint as ckpt
    from lmcr.lm.score import LMScorer

    loaded = ckpt.load(lm_checkpoint_dir(res.checkpoints, linearization, corpus))
    if loaded.linearization != linearization:
        raise ckpt.CheckpointError(f"{loaded.path} is a {loaded.linearization} model, not {linearization}")
    return LMScorer(loaded)


def lm_experts(res: MethodResources) -> list[tuple[str, float]]:
    """(corpus, interpolation weight) of the LMs an LM scorer mixes: the setting's own alone, or under a
    mixture the all-corpora LM and each weighted corpus's LM at its share of the weighted words."""
    if not res.mixed:
        return [(res.corpus, 1.0)]
    shares = res.mixture.shares(corpus_words(res))
    return [("all", 1.0 - sum(shares.values())), *shares.items()]


def lm_settings(method: str, res: MethodResources) -> list[Setting]:
    """The LM checkpoints the scorer of `method` ('a+b' sums) may load under `res`: each LM part's
    linearisation in the setting's corpus, or, under a mixture, in `all` and in each weighted corpus (the
    experts of `lm_experts`, counted before a corpus without words drops out)."""
    corpora = ["all", *(c for c, _ in res.mixture.weights)] if res.mixed else [res.corpus]
    return [Setting(LM_METHODS[part], corpus) for part in method.split("+") if part in LM_METHODS for corpus in corpora]


def lm_version_dir(res: MethodResources, linearization: str, corpus: str | None = None) -> Path:
    """The checkpoint version folder an LM scorer of `linearization` loads (a setting's LATEST resolved)."""
    from lmcr.lm import checkpoint as ckpt

    return ckpt.resolve(lm_checkpoint_dir(res.checkpoints, linearization, corpus or res.corpus))
