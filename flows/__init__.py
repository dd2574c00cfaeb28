"""Prefect flows: thin task wrappers around `lmcr` and one readable flow per pipeline."""
