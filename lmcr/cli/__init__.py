"""The `lmcr` command line: a command per stage (formats in the project's CLI contract), one module per
group of commands. A command checks its arguments and calls the library once; the app, its one-line
error handling and the helpers the groups share are in `common`.

- `corpus`: ingest, frames, srl, srl-eval
- `store`: migrate, schema, sql, query
- `models`: train, score, evaluate, mixture, complete
- `robot`: speech-lm, listen, execute, robot, serve
- `ratings`: annotate tasks, ingest, quality
"""

from __future__ import annotations

from lmcr.cli.common import OneLineErrors, app, fail

# the groups register their commands on `app` when imported, in this order (the order of `lmcr --help`)
# isort: off
from lmcr.cli import corpus, store, models, robot, ratings  # noqa: F401, E402
# isort: on

__all__ = ["OneLineErrors", "app", "fail", "main"]


def main() -> None:
    """Console-script entry point."""
    app(prog_name="lmcr")
