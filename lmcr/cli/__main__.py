"""`python -m lmcr.cli`: the `lmcr` command."""

from lmcr.cli import main

if __name__ == "__main__":
    main()
