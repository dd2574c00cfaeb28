"""LMCR: completing incomplete robot instructions with commonsense learned from cooking text."""

__version__ = "0.1.0"
