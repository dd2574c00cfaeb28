"""Semantic role labelling of instructions and recipe text: verb frames (predicate, roles, fillers) read
from spaCy's dependency parse with the lexicon's rules, learned compounds and role priors, and scored
against gold frames."""
