"""The paper's Table I, read from its LaTeX source (the file is given by the user, never shipped):
per method, per verb and 'all', the published accuracy at lambda=1, k=6."""

from __future__ import annotations

import re
from pathlib import Path

from lmcr.errors import LMCRError
from lmcr.jsonl import decode_utf8, read_bytes

# The paper's column headings -> our method names. The paper's LMCR column is its language model over
# sentence-linearised frames trained on all corpora: our sentence_lm.
PAPER_METHODS = {
    "random": "random",
    "cooccur": "cooccur",
    "word2vec": "word2vec",
    "conceptnet": "conceptnet",
    "lmcr": "sentence_lm",
}


ACCURACY = re.compile(r"\d*\.\d+")  # a table cell holding a figure, '0.88' or '.88'


class PaperTableError(LMCRError, ValueError):
    """The file has no Table I the reader understands."""


def _plain(cell: str) -> str:
    """'\\textbf{0.88}' -> '0.88', '\\multicolumn{3}{r}{\\textbf{LMCR (Ours)}}' -> 'LMCR (Ours)'."""
    while True:
        inner = re.sub(r"\\[A-Za-z]+\*?(?:\{[^{}]*\})*?\{([^{}]*)\}", r"\1", cell)
        if inner == cell:
            return cell.replace("{", "").replace("}", "").strip()
        cell = inner


def _headings(header_rows: list[str]) -> dict[int, str]:
    """Column position -> method heading. Headings may be staggered over rows and span columns
    (\\multicolumn{n}): a heading of one column wins over a spanning one at the same position."""
    single, spans = {}, {}
    for row in header_rows:
        position = 0
        for cell in row.split("&"):
            width = int(m.group(1)) if (m := re.search(r"\\multicolumn\{(\d+)\}", cell)) else 1
            bold = re.search(r"\\textbf\{([^{}]*)\}", cell)
            if bold:
                name = bold.group(1).split("(")[0].strip().lower()
                target = single if width == 1 else spans
                for col in range(position, position + width):
                    target.setdefault(col, name)
            position += width
    return {**spans, **single}


def read_paper_table(tex: Path) -> dict[str, dict[str, float]]:
    """method -> verb ('all' for Overall) -> accuracy, from the table labelled `tab:res`."""
    source = decode_utf8(read_bytes(tex), str(tex))
    match = re.search(r"\\begin\{table\}(?:(?!\\end\{table\}).)*?\\label\{tab:res\}(.*?)\\end\{table\}", source, re.S)
    if not match:
        raise PaperTableError(f"{tex}: no table labelled tab:res (Table I)")
    body = match.group(1)
    try:
        head, rows = body.split(r"\midrule", 1)
    except ValueError:
        raise PaperTableError(f"{tex}: Table I has no \\midrule after its header") from None
    head = head.split(r"\toprule", 1)[-1]
    headings = _headings(head.split(r"\\"))
    table: dict[str, dict[str, float]] = {}
    for line in re.split(r"\\\\", rows.replace(r"\midrule", "").replace(r"\bottomrule", "")):
        cells = [_plain(c) for c in line.split("&")]
        values = [(position, cell) for position, cell in enumerate(cells[1:], 1) if ACCURACY.fullmatch(cell)]
        if not cells[0] or not values:
            continue
        verb = "all" if cells[0].lower() == "overall" else cells[0].lower()
        for position, cell in values:
            method = PAPER_METHODS.get(headings.get(position, ""))
            if method is None:
                raise PaperTableError(f"{tex}: Table I value {cell} of row {cells[0]!r} is under no known method")
            table.setdefault(method, {})[verb] = float(cell)
    if not table:
        raise PaperTableError(f"{tex}: Table I has no rows of accuracies")
    return table
