"""The language model's and the training loop's settings, each default defined once: the CLI, the
flows and the library all read them from here (torch-free, so the command line starts fast)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

MIN_FREQ = 3  # words seen fewer times in the training text share <unk>
MAX_VOCAB = 30_000  # the most frequent words kept


@dataclass(frozen=True)
class LMConfig:
    vocab_size: int
    embedding: int = 256
    layers: int = 2
    dropout: float = 0.3
    # Training softmax over the targets plus this many shared negatives (0: full softmax), used only
    # when the vocabulary is over 8x larger: the full softmax over a 30k vocabulary is most of a CPU
    # training step, over a few thousand words it costs little and samples only add noise. Validation
    # perplexity and scoring are always exact.
    sampled: int = 1024

    @property
    def uses_sampling(self) -> bool:
        return 0 < self.sampled and 8 * self.sampled < self.vocab_size

    def to_json(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class TrainConfig:
    # Measured on the full sentence corpus without articles (13.3M training tokens, bf16; an H200 and a
    # 2-core CPU agree within 0.4): at lr 3e-3 the number of steps limits an epoch's gain, so 3,000-token
    # batches at a constant rate reach val ppl 35.0 / 29.1 / 26.7 / 25.9 after epochs 1-4 (2 cores: 345 s
    # an epoch), where 6,000-token batches reached 44.1 / 31.9 / 28.3 / 26.8 / 26.6 / 25.0 after epochs
    # 1-6, in 580-681 s each. On a CPU the smaller batches cost nothing in tokens/s (35-38k in bf16, about
    # 22k in fp32, on 2 cores). 2,000-token batches gained at first but not by epoch 3 (32.6 / 28.6 /
    # 26.7), lr 5e-3 did not gain (34.9 / 29.9 after epochs 1-2), larger batches lost (12k tokens, lr
    # 4e-3: 43.6 after 3), and so did a cosine decay over the whole run (33.7 after 3).
    # What gains is a linear decay at the end (`decay_epochs`). From the same state after 3 constant
    # epochs (H200), epoch 4 reached 26.30 at 3e-3, 25.87 at 3e-4, 25.57 at 7.5e-4 and 25.51 decaying
    # linearly to 1%; 4 constant epochs and a fifth that decays reached 24.92. On 2 cores in bf16 the
    # five reached 35.5 / 29.3 / 26.9 / 26.0 / 24.9, a store from scratch in 42.2 minutes.
    max_epochs: int = 5
    # The learning rate falls linearly, step by step, from `lr` to 1% of it over the last `decay_epochs`
    # of `max_epochs` (0: constant). A time budget that fits fewer epochs moves the decay to the last
    # that fits; a run stopped by patience or a target perplexity ends undecayed.
    decay_epochs: int = 1
    lr: float = 3e-3
    batch_tokens: int = 3000
    clip: float = 1.0
    patience: int = 1
    seed: int = 1234
    max_len: int = 60  # tokens per sequence; longer sentences are cut (recipes rarely exceed it)
    device: str | None = None  # None: CUDA when present, else CPU
    # No epoch starts that would likely end past this budget (None: no budget); 55 minutes keeps a
    # published setting inside an hour, the retrain schedule's slot.
    max_minutes: float | None = 55.0
    target_ppl: float | None = None  # stop once validation perplexity is this good
    # "auto": bfloat16 autocast where the hardware multiplies bf16 natively (CPUs with AMX or
    # AVX512-BF16, CUDA devices with bf16), else fp32; "bf16" / "fp32" force one. Weights, optimiser
    # state and scoring stay fp32; the epochs' validation runs in the training precision (on the full
    # corpus: 39.5 s instead of 65.2 s on 2 cores, val ppl 25.864 instead of 25.851). On this AMX CPU a
    # training step of the default model runs 26.4k vs 15.3k tokens/s; on the 3M-token bench (lr 1e-2)
    # val ppl after epochs 1 / 2 was 86.0 / 64.9 in bf16 vs 79.7 / 61.8 in fp32.
    precision: str = "auto"
    # Keep a/an/the in the training text (and hence in what the model scores)? False makes recipe prose
    # and terse household narrations ("pour milk into cup") one register; see `lm.linearize`.
    articles: bool = False

    def to_json(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class WarmStartConfig:
    """How a retrain continues the current checkpoint on new text instead of starting from random weights.

    The new documents' sequences are trained together with `replay` times as many old ones drawn at
    random: without the old text in the mix, the model drifts towards the new collection's wording and
    forgets the rest. The vocabulary stays the checkpoint's; when the vocabulary rebuilt from the whole
    corpus would differ from it in more than `max_vocab_change` of its words (added or dropped), new
    words would be left as `<unk>` and the retrain trains from scratch instead.
    """

    replay: float = 1.0
    # One pass: on the full corpora with a new file of 4.4% of the sentences, a second pass over the same
    # new and replayed sequences made validation worse (val ppl 26.3 after one, 26.7 after two).
    epochs: int = 1
    lr: float = 1e-3  # below training's 3e-3: the weights start near a minimum, a fresh Adam would overshoot
    # The rate decays over the pass as in training (`TrainConfig.decay_epochs`). On the full corpora,
    # continuing a checkpoint trained with the decay, both ways reached val ppl 24.7 (the LM alone on the
    # rated frames: 0.832 decaying, 0.830 constant); continuing one trained without it, decaying reached
    # 26.5 against 26.3. On the sample corpus of the retrain test, a constant 1e-3 made the candidate
    # score below the checkpoint it continued, and decaying did not.
    decay_epochs: int = 1
    max_vocab_change: float = 0.05
    seed: int = 1234

    def to_json(self) -> dict:
        return asdict(self)
