"""A language-model setting: a linearisation of the frames times a training corpus. Checkpoint folders
and flows spell it `sentence-all`, evaluation and the CLI `sentence_lm/all`; `Setting.parse` reads
either, and every place that needs a name asks the setting for it. Light: the CLI imports it at start."""

from __future__ import annotations

from dataclasses import dataclass

from lmcr.errors import LMCRError

LINEARIZATIONS = ("sentence", "frame")
# What ingest loads each input as; a setting trains on one of them or on all together.
SOURCE_CORPORA = ("youcook2", "recipes", "household")
CORPORA = (*SOURCE_CORPORA, "all")
# The scorer (method) name of each linearisation's language model.
LM_METHODS = {"sentence_lm": "sentence", "frame_lm": "frame"}
METHOD_OF = {linearization: method for method, linearization in LM_METHODS.items()}


class SettingError(LMCRError, ValueError):
    """A setting, linearisation or corpus name that is not one of the known ones."""


def check_corpus(corpus: str) -> str:
    """`corpus` when it is one of CORPORA (it may become part of SQL text), else SettingError."""
    if corpus not in CORPORA:
        raise SettingError(f"corpus must be one of {CORPORA}, not {corpus!r}")
    return corpus


@dataclass(frozen=True, order=True)
class Setting:
    linearization: str
    corpus: str = "all"

    def __post_init__(self) -> None:
        if self.linearization not in LINEARIZATIONS:
            raise SettingError(f"linearization must be one of {LINEARIZATIONS}, not {self.linearization!r}")
        check_corpus(self.corpus)

    @classmethod
    def parse(cls, text: str) -> Setting:
        """'sentence-all', 'sentence_lm/all' or 'sentence/all'; a bare linearisation or method means all."""
        head, sep, corpus = text.partition("/" if "/" in text else "-")
        linearization = LM_METHODS.get(head, head)
        if linearization not in LINEARIZATIONS:
            raise SettingError(
                f"unknown setting {text!r}: write linearization-corpus (e.g. sentence-all) or "
                f"method/corpus (e.g. sentence_lm/all)"
            )
        return cls(linearization, corpus if sep else "all")

    @property
    def name(self) -> str:
        """The checkpoint folder's name, 'sentence-all'."""
        return f"{self.linearization}-{self.corpus}"

    @property
    def method(self) -> str:
        """The scorer of this setting's LM, 'sentence_lm'."""
        return METHOD_OF[self.linearization]

    @property
    def label(self) -> str:
        """How evaluation names it, 'sentence_lm/all'."""
        return f"{self.method}/{self.corpus}"

    def __str__(self) -> str:
        return self.name


ALL_SETTINGS = tuple(Setting(lin, corpus) for lin in LINEARIZATIONS for corpus in CORPORA)
