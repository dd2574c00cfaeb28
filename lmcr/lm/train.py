"""Training loop: bucketed batches, Adam with a linear decay at the end, gradient clipping, early stopping
on validation perplexity."""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace

import torch

from lmcr.errors import LMCRError
from lmcr.lm.data import bucket_batches
from lmcr.lm.hyperparams import TrainConfig
from lmcr.lm.model import RecurrentLM

PRECISIONS = ("auto", "bf16", "fp32")


def pick_device(requested: str | None) -> torch.device:
    return torch.device(requested or ("cuda" if torch.cuda.is_available() else "cpu"))


def native_bf16(device: torch.device) -> bool:
    """Whether `device` multiplies bfloat16 in hardware (else bf16 autocast is emulated and slower)."""
    if device.type == "cuda":
        return torch.cuda.is_bf16_supported()
    probes = ("_is_amx_tile_supported", "_is_avx512_bf16_supported")
    # The CPU's own flags are not enough: oneDNN may be held to a lower instruction set
    # (ONEDNN_MAX_CPU_ISA), and then it has no bf16 LSTM at all.
    return bf16_unsupported(device) is None and any(getattr(torch.cpu, probe, lambda: False)() for probe in probes)


class PrecisionError(LMCRError, ValueError):
    """A precision this machine cannot compute in, or no precision at all."""


def bf16_unsupported(device: torch.device) -> str | None:
    """Why `device` cannot run the LM in bfloat16, or None when it can. On a CPU, PyTorch's LSTM and
    products in bf16 go through oneDNN, which computes bf16 natively (AMX, AVX512-BF16, Arm BF16) or
    emulates it with AVX-512; on a CPU with neither (AVX2 only: many laptops, older AMD EPYC) it has no
    bf16 LSTM primitive at all."""
    if device.type == "cuda":
        return None if torch.cuda.is_bf16_supported() else "this CUDA device has no bfloat16"
    if device.type != "cpu":
        return None
    if torch.backends.mkldnn.is_available() and torch.ops.mkldnn._is_mkldnn_bf16_supported():
        return None
    return "this CPU has no bfloat16 support in oneDNN (it needs AVX-512, AMX or Arm BF16)"


def pick_precision(requested: str, device: torch.device) -> str:
    """The precision to compute in: "auto" is bf16 where the hardware multiplies it natively, else fp32;
    "bf16" where the device cannot is refused in one line, never a failure deep in a kernel."""
    if requested not in PRECISIONS:
        raise PrecisionError(f"precision must be one of {PRECISIONS}, not {requested!r}")
    if requested == "auto":
        return "bf16" if native_bf16(device) else "fp32"
    if requested == "bf16" and (reason := bf16_unsupported(device)):
        raise PrecisionError(f"precision bf16: {reason}; use --precision fp32 (or auto)")
    return requested


@contextmanager
def flushed_denormals() -> Iterator[None]:
    """Denormal floats flushed to zero for the block, then back to torch's default (off): denormals
    (squares of tiny gradients in Adam's second moments) are slow on x86 and useless to the model,
    but the setting is process-wide and scoring elsewhere should not inherit it."""
    torch.set_flush_denormal(True)
    try:
        yield
    finally:
        torch.set_flush_denormal(False)


def unigram_noise(seqs: list[list[int]], vocab_size: int, power: float = 0.75) -> torch.Tensor:
    """Sampling distribution for the sampled softmax: unigram counts to the 3/4 power, never zero."""
    counts = torch.bincount(torch.tensor([t for s in seqs for t in s[1:]]), minlength=vocab_size).float()
    weights = (counts + 1.0).pow(power)
    weights[0] = 0.0  # never sample padding
    return weights / weights.sum()


def computed_in(device: torch.device, precision: str) -> torch.autocast:
    """The block's products in `precision`: bfloat16 autocast for "bf16", plain fp32 otherwise (training
    steps and validation alike; losses are accumulated in fp32 either way)."""
    return torch.autocast(device.type, dtype=torch.bfloat16, enabled=precision == "bf16")


FINAL_LR_FRACTION = 0.01  # where the decay ends: not 0, so the last steps still move the weights a little


def learning_rate(config: TrainConfig, epoch: int, progress: float) -> float:
    """The rate for a step `progress` (0 to 1) of the way through `epoch` (1-based): `config.lr`, falling
    linearly to FINAL_LR_FRACTION of it over the last `config.decay_epochs` of `config.max_epochs`."""
    decay = min(config.decay_epochs, config.max_epochs)
    done = epoch - 1 + progress - (config.max_epochs - decay)  # epochs into the decay
    if decay <= 0 or done <= 0:
        return config.lr
    return config.lr * (1.0 - (1.0 - FINAL_LR_FRACTION) * min(done / decay, 1.0))


@torch.no_grad()
def perplexity(
    model: RecurrentLM, seqs: list[list[int]], batch_tokens: int, device: torch.device, precision: str = "fp32"
) -> float:
    """exp(mean next-token cross-entropy) over all non-padding targets, computed in `precision` (the
    loss itself is always accumulated in fp32)."""
    model.eval()
    total, count = 0.0, 0
    for batch in bucket_batches(seqs, batch_tokens):
        with computed_in(device, precision):
            loss, n = model.loss(batch.to(device))
        total, count = total + float(loss) * n, count + n
    return math.exp(total / max(count, 1))


def train_lm(
    model: RecurrentLM,
    train: list[list[int]],
    val: list[list[int]],
    config: TrainConfig,
    on_epoch: Callable[[dict], None] | None = None,
) -> list[dict]:
    """Train for `config.max_epochs`, or fewer when validation perplexity stops improving, reaches the
    target, or the time budget would end first; the rate decays over the last epochs planned. The model
    ends with its best weights. Returns one metrics row per epoch (train/val perplexity, tokens/s,
    seconds, the rate at its end)."""
    torch.manual_seed(config.seed)
    device = pick_device(config.device)
    precision = pick_precision(config.precision, device)
    model.to(device)
    # One fused kernel per step instead of a loop over the parameters (6% of a CPU step at 3,000 tokens).
    optimizer = torch.optim.Adam(model.parameters(), lr=config.lr, fused=device.type in ("cpu", "cuda"))
    train = [s[: config.max_len] for s in train]
    noise = unigram_noise(train, model.config.vocab_size).to(device)
    best, best_state, waited, history = math.inf, None, 0, []
    planned, epoch_wall = config.max_epochs, 0.0
    budget_ends = time.perf_counter() + 60 * config.max_minutes if config.max_minutes else None
    for epoch in range(1, config.max_epochs + 1):
        if history and budget_ends is not None:
            # No epoch starts that would likely end past the budget (each takes about as long as the last,
            # validation included), and the decay moves to the last epochs that fit.
            planned = min(planned, epoch - 1 + int((budget_ends - time.perf_counter()) / (1.1 * epoch_wall)))
            if epoch > planned:
                break
        started = time.perf_counter()
        batches = bucket_batches(train, config.batch_tokens, seed=config.seed + epoch)
        with flushed_denormals():  # training steps only
            schedule = replace(config, max_epochs=planned)
            total, count = _train_epoch(model, optimizer, batches, schedule, epoch, noise, device, precision)
        seconds = time.perf_counter() - started
        val_ppl = perplexity(model, val, config.batch_tokens, device, precision)
        epoch_wall = time.perf_counter() - started
        # Under the sampled softmax the training number is the sampled objective's, not a perplexity.
        row = {
            "epoch": epoch,
            "train_ppl": math.exp(total / max(count, 1)),
            "val_ppl": val_ppl,
            "tokens_per_s": count / seconds,
            "seconds": seconds,
            "device": device.type,
            "precision": precision,
            "lr_end": optimizer.param_groups[0]["lr"],
            "objective": "sampled" if model.config.uses_sampling else "full",
        }
        history.append(row)
        if on_epoch:
            on_epoch(row)
        if val_ppl < best:
            best, best_state, waited = val_ppl, copy.deepcopy(model.state_dict()), 0
            if config.target_ppl and val_ppl <= config.target_ppl:
                break
        else:
            waited += 1
            if waited > config.patience:
                break
    if best_state is not None:
        model.load_state_dict(best_state)
    return history


def _train_epoch(
    model: RecurrentLM,
    optimizer: torch.optim.Optimizer,
    batches: list[torch.Tensor],
    schedule: TrainConfig,
    epoch: int,
    noise: torch.Tensor,
    device: torch.device,
    precision: str,
) -> tuple[float, int]:
    """One pass of training steps over `batches` at the rates of `schedule`, on `device` in `precision`;
    returns the summed training loss and the number of targets."""
    model.train()
    total, count = 0.0, 0
    for step, batch in enumerate(batches):
        for group in optimizer.param_groups:
            group["lr"] = learning_rate(schedule, epoch, (step + 1) / len(batches))
        with computed_in(device, precision):
            loss, n = model.loss(batch.to(device), noise)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), schedule.clip)
        optimizer.step()
        total, count = total + loss.item() * n, count + n
    return total, count
