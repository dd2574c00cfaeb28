"""A small word-level recurrent language model (the paper's choice), in one readable file.

Embedding -> LSTM layers -> dropout -> decoder tied to the embedding. Shapes: B batch, T time, E
embedding = hidden size (tying needs them equal), V vocabulary.
"""

from __future__ import annotations

import torch
from torch import nn
from torch.nn import functional as F

from lmcr.lm.hyperparams import LMConfig


class RecurrentLM(nn.Module):
    def __init__(self, config: LMConfig):
        super().__init__()
        self.config = config
        self.embed = nn.Embedding(config.vocab_size, config.embedding, padding_idx=0)
        self.rnn = nn.LSTM(
            config.embedding,
            config.embedding,
            config.layers,
            batch_first=True,
            dropout=config.dropout if config.layers > 1 else 0.0,
        )
        self.drop = nn.Dropout(config.dropout)
        self.decoder = nn.Linear(config.embedding, config.vocab_size)
        self.decoder.weight = self.embed.weight  # tied: fewer parameters, better perplexity
        nn.init.uniform_(self.embed.weight, -0.1, 0.1)
        nn.init.zeros_(self.decoder.bias)

    def forward(self, ids: torch.Tensor) -> torch.Tensor:
        """ids (B, T) -> next-token logits (B, T, V)."""
        hidden, _ = self.rnn(self.drop(self.embed(ids)))  # (B, T, E)
        return self.decoder(self.drop(hidden))  # (B, T, V)

    def token_logprobs(self, ids: torch.Tensor) -> torch.Tensor:
        """Log-probability of each next token: ids (B, T) -> (B, T-1), zero where the target is padding."""
        logits = self(ids[:, :-1])  # (B, T-1, V)
        targets = ids[:, 1:]  # (B, T-1)
        logp = F.log_softmax(logits, dim=-1).gather(-1, targets.unsqueeze(-1)).squeeze(-1)
        return logp * (targets != 0)

    def loss(self, ids: torch.Tensor, noise: torch.Tensor | None = None) -> tuple[torch.Tensor, int]:
        """Mean next-token cross-entropy over the non-padding targets of a batch, and their count.

        With `noise` (a sampling distribution over the vocabulary) in training mode, the softmax runs
        over each target and `config.sampled` shared negatives, with the usual log-Q correction."""
        targets = ids[:, 1:]
        if noise is None or not self.training or not self.config.uses_sampling:
            logits = self(ids[:, :-1])
            loss = F.cross_entropy(logits.reshape(-1, logits.size(-1)), targets.reshape(-1), ignore_index=0)
            return loss, int((targets != 0).sum())
        hidden, _ = self.rnn(self.drop(self.embed(ids[:, :-1])))  # (B, T, E)
        keep = targets != 0
        h = self.drop(hidden)[keep]  # (N, E)
        t = targets[keep]  # (N,)
        negatives = torch.multinomial(noise, self.config.sampled, replacement=True)  # (S,)
        log_q = torch.log(noise * self.config.sampled)
        w, b = self.decoder.weight, self.decoder.bias
        true_logit = (h * w[t]).sum(-1) + b[t] - log_q[t]  # (N,)
        neg_logit = h @ w[negatives].T + b[negatives] - log_q[negatives]  # (N, S)
        neg_logit = neg_logit.masked_fill(negatives.unsqueeze(0) == t.unsqueeze(1), float("-inf"))  # accidental hits
        logits = torch.cat([true_logit.unsqueeze(1), neg_logit], dim=1)  # (N, 1 + S): the target is column 0
        return F.cross_entropy(logits, torch.zeros_like(t)), int(t.numel())
