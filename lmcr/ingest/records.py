"""The sentence schema every ingest adapter produces, and the rejects that go to quarantine."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from lmcr.errors import LMCRError
from lmcr.text import count_words, normalize, split_sentences

KINDS = ("instruction", "ingredient", "title", "comment")
# Instructions and comments are running prose and are split into sentences; titles and ingredient
# lines are already one unit each.
PROSE_KINDS = frozenset({"instruction", "comment"})


class IngestError(LMCRError, RuntimeError):
    """An input file cannot be read at all (missing, undecodable, not the format it claims)."""

    def __init__(self, source_file: str, position: int | None, reason: str):
        where = f"{source_file}:{position}" if position else source_file
        super().__init__(f"{where}: {reason}")
        self.source_file, self.position, self.reason = source_file, position, reason

    def __reduce__(self):  # raised in parser processes: must unpickle with its three arguments
        return IngestError, (self.source_file, self.position, self.reason)


@dataclass
class ParsedFile:
    """Everything read from one input: documents, their sentences, and rejected records.

    `records_in` counts the units the adapter read (a video annotation, a JSON line, a recipe block,
    a recipe element); every one ends up loaded or rejected, never neither.
    """

    source_file: str
    format: str
    corpus: str
    documents: list[dict] = field(default_factory=list)
    sentences: list[dict] = field(default_factory=list)
    rejects: list[dict] = field(default_factory=list)
    records_in: int = 0
    records_loaded: int = 0

    def reject(self, position: int | None, reason: str, record: object = "") -> None:
        """Quarantine one input record with the reason it failed validation."""
        self.records_in += 1
        self.rejects.append(
            {
                "stage": "ingest",
                "corpus": self.corpus,
                "source_file": self.source_file,
                "position": position,
                "reason": reason,
                "record": str(record)[:2000].encode("utf-8", "backslashreplace").decode("utf-8"),
            }
        )

    def add_document(
        self,
        doc_id: str,
        source: str,
        position: int,
        parts: Iterable[tuple],
        *,
        title: str | None = None,
        category: str | None = None,
        subset: str | None = None,
        url: str | None = None,
        records: int = 1,
    ) -> None:
        """Add one document from its parts; a document with no text at all is rejected.

        Each part is `(kind, text)` or `(kind, text, extra_columns)`; `records` is how many input
        records the document stands for (a YouCook2 video stands for its annotations).
        """
        sentences = list(self._sentences(doc_id, source, position, parts))
        if not sentences:
            for _ in range(records):
                self.reject(position, f"document {doc_id!r} has no text", title or doc_id)
            return
        self.records_in += records
        self.records_loaded += records
        self.documents.append(
            {
                "corpus": self.corpus,
                "source": source,
                "doc_id": doc_id,
                "title": normalize(title) if title else None,
                "category": category,
                "subset": subset,
                "url": url,
                "source_file": self.source_file,
                "position": position,
            }
        )
        self.sentences.extend(sentences)

    def _sentences(self, doc_id: str, source: str, position: int, parts: Iterable[tuple]):
        sent_id = 0
        for kind, raw, *extra in parts:
            if kind not in KINDS:  # a bug in a format's parser, not in its input
                raise ValueError(f"unknown sentence kind {kind!r}")
            pieces = split_sentences(raw) if kind in PROSE_KINDS else [normalize(raw)]
            for text in pieces:
                if not text:
                    continue
                yield {
                    "corpus": self.corpus,
                    "source": source,
                    "doc_id": doc_id,
                    "sent_id": sent_id,
                    "kind": kind,
                    "text": text,
                    "n_words": count_words(text),
                    "source_file": self.source_file,
                    "position": position,
                    "seg_start": None,
                    "seg_end": None,
                    **(extra[0] if extra else {}),
                }
                sent_id += 1

    @property
    def words(self) -> int:
        return sum(s["n_words"] for s in self.sentences)
