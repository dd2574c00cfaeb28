"""How much a frame's Theme raises the sentence LM's probability of the frame's other fillers: the term
that turns the LM's log P(frame) into a pointwise mutual information between the Theme and the rest,
given the verb.

The LM scores "put the stained shirt away in the bed" above "... in the hamper" because its corpora say
"bed" far more often than "hamper" after whatever is put away, not because shirts go to bed: the verb's
own preference for a filler outweighs what the Theme says of it. The `rarity` term subtracts how common
a filler is in the corpus; this one subtracts how likely the LM finds it in the very slot when the Theme
is not said (Holtzman et al. 2021's domain-conditional PMI, with the Theme as "it" for the premise):

    theme_pmi(frame) = -WEIGHT * log P_LM(the frame with its Theme said as "it")

centred over the frames scored with it that fill the same roles of the same predicate. Centred so, it
only ranks the fillers of a role: among frames that differ only in their Theme (the Theme is what is
missing) the masked frames are one text, and the term is 0. A frame without a Theme or with nothing but
a Theme scores 0. WEIGHT = 0.75 was chosen among 0.5, 0.75 and 1 on the external request sets
(docs/guide/complete.md); nothing else is fitted: the LM is the product's own.

The term is 0 for the eleven hand-written predicates, as `verb_fillers` is. On their dev sets it raised
Table I (0.922 to 0.930) but cost a dev instruction: "heat the milk" chose the glass, which milk goes
with far more than a pot does, once the verb's own dislike of heating in a glass was mostly taken out.
A learned verb's slot is wider (put away: a shelf, a bin, the fridge), and there the Theme is what
tells the places apart.
"""

from __future__ import annotations

from collections.abc import Callable, Collection

from lmcr.frame import Frame

WEIGHT = 0.75
PLACEHOLDER = "it"  # what the Theme is said as: an object pronoun the sentence templates read as such

LMScores = Callable[..., list[float]]


def masked(frame: Frame) -> Frame | None:
    """The frame with its Theme said as "it", or None when it has no Theme or nothing besides one."""
    roles = frame.role_map
    if "Theme" not in roles or len(roles) < 2:
        return None
    return Frame.of(frame.predicate, {**roles, "Theme": PLACEHOLDER})


def theme_pmi_scorer(
    lm: LMScores, learned: Collection[str], weight: float = WEIGHT
) -> Callable[[list[Frame], str], list[float]]:
    """The term over the sentence LM's frame scorer `lm` (frames and the instruction's context), for the
    frames of the `learned` predicates; 0 for the others (the eleven). The masked frames are read with
    the context too: what is taken out is what the verb and all that was said favour without the Theme
    ("It is too sweet. Can you dispose of it?": the bins that sweetness suggests whatever is thrown)."""

    def score(frames: list[Frame], context: str = "") -> list[float]:
        nulls = [masked(f) if f.predicate in learned else None for f in frames]
        texts = sorted({n for n in nulls if n is not None}, key=lambda n: n.key)
        # each distinct masked frame once: a request's candidates share few of them
        logp = dict(zip(texts, lm(texts, context))) if texts else {}
        groups: dict[tuple, list[int]] = {}
        for i, (frame, null) in enumerate(zip(frames, nulls)):
            if null is not None:
                groups.setdefault((frame.predicate, tuple(sorted(frame.role_map))), []).append(i)
        out = [0.0] * len(frames)
        for members in groups.values():
            mean = sum(logp[nulls[i]] for i in members) / len(members)
            for i in members:
                out[i] = -weight * (logp[nulls[i]] - mean)
        return out

    return score
