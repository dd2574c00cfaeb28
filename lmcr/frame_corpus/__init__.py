"""The frames stage: ingested sentences -> frame corpora in the store (a stage, not linguistics: the
parser it runs lives in `lmcr.srl`)."""
