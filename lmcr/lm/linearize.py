"""Linearisations and the tokeniser shared by training and scoring.

Frame-based: `(pour, Theme: water, Destination: cup)` -> "pour water cup" (predicate, then role values
in the lexicon's role order; generic frames in their stored order). Sentence-based: the predicate's
template from the lexicon, "pour water into the cup". Both are lowercased and tokenised by `tokens`,
which is also what the sentence LM's training sentences go through: one casing policy everywhere.

Registers: recipe prose says "pour the milk into the bowl", kitchen narrations "pour milk into cup". A
model trained with `articles=False` (the default since household narrations joined the corpora) drops
a/an/the from its training text and from every text it scores, so both registers are one language and
the template it scores, "pour milk into cup", reads like either. The checkpoint records the choice and
its scorer follows it (older checkpoints kept articles).
"""

from __future__ import annotations

import re

from lmcr.lexicon import Lexicon, load_lexicon
from lmcr.setting import LINEARIZATIONS, SettingError

_TOKEN = re.compile(r"[a-z]+(?:'[a-z]+)?|\d+(?:[./]\d+)?")
NUMBER = "<num>"
ARTICLES = frozenset({"a", "an", "the"})


def tokens(text: str, articles: bool = True) -> list[str]:
    """Lowercase word tokens; numbers become one placeholder (quantities say nothing about plausibility);
    without `articles`, a/an/the are left out (one register for prose and terse narrations)."""
    return [NUMBER if t[0].isdigit() else t for t in _TOKEN.findall(text.lower()) if articles or t not in ARTICLES]


def frame_text(predicate: str, roles: dict[str, str | None], lex: Lexicon | None = None) -> str:
    """'pour water cup': predicate and filled role values, robot predicates in lexicon role order."""
    lex = lex or load_lexicon()
    spec = lex.predicates.get(predicate)
    order = list(spec.roles) if spec else list(roles)
    return " ".join([predicate] + [roles[r] for r in order if roles.get(r)])


def sentence_text(predicate: str, roles: dict[str, str], lex: Lexicon | None = None) -> str:
    """'pour water into the cup': the lexicon's sentence template with every role filled (a learned
    predicate's template for the roles the frame has). A role the frame does not have at all is not said,
    nor the preposition that introduces it (`without_roles`)."""
    lex = lex or load_lexicon()
    spec = lex.predicates.get(predicate)
    if spec is None:
        raise KeyError(f"no sentence template for predicate {predicate!r}")
    template = spec.template(roles)
    slots = re.findall(r"\{(\w+)\}", template)
    template = without_roles(template, [r for r in slots if r not in roles])
    missing = [r for r in slots if r in roles and not roles[r]]
    if missing:  # a bug: scorers are only given complete frames
        raise ValueError(f"cannot linearise {predicate} with {missing} unfilled")
    return template.format(**roles)


def without_roles(template: str, absent: list[str]) -> str:
    """The template without the phrases of the `absent` roles: each role's slot with the preposition (and
    "the") before it ("eat {Theme} with the {Instrument}" without the Instrument: "eat {Theme}"), or the
    bare slot of an object (without the Theme: "eat with the {Instrument}"). A purpose clause's frame
    has only the roles the clause states and the thing asked for ("bring me something to eat": eat, Theme
    the thing), and no template of a verb was written for it."""
    for role in absent:
        template = re.sub(rf"(?: [a-z]+(?: the)?)? ?\{{{role}\}}", "", template, count=1)
    return template.strip()


def linearize(linearization: str, predicate: str, roles: dict[str, str], lex: Lexicon | None = None) -> str:
    """The text a model of the given linearisation scores for a complete frame."""
    if linearization == "frame":
        return frame_text(predicate, roles, lex)
    if linearization == "sentence":
        return sentence_text(predicate, roles, lex)
    raise SettingError(f"linearization must be one of {LINEARIZATIONS}, not {linearization!r}")
