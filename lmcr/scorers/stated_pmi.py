"""How much what a request states raises the sentence LM's probability of each candidate filler: the term
that turns the LM's log P(frame) into a pointwise mutual information between the candidates and the
stated fillers, given the verb.

The LM scores "put the stained shirt away in the bed" above "... in the hamper" because its corpora say
"bed" far more often than "hamper" after whatever is put away, not because shirts go to bed: the verb's
own preference for a filler outweighs what the Theme says of it. The `rarity` term subtracts how common
a filler is in the corpus; this one subtracts how likely the LM finds it in the very slot when what was
stated is not said (Holtzman et al. 2021's domain-conditional PMI, with "it" for the stated fillers):

    stated_pmi(frame) = -WEIGHT * log P_LM(the frame with its stated fillers said as "it", then the context)

centred over the frames scored with it that fill the same roles of the same predicate. The frames of one
request are scored together, so within such a group the stated roles are those every frame fills alike
and the candidates' roles those that vary: "put the stained shirt away" masks the Theme ("put it away in
the hamper"), "dispose of it in the recycling bin" the bin ("dispose of the coke in it"). Where every role
varies (nothing but a pronoun was said: "Can you dispose of it?") the Theme is masked; a group of one
frame, or of frames alike, scores 0. Centred so, the term only ranks the fillers of a role. Candidates
for a tool (`TOOLS`) are left to the verb's own preference: one cleans with a cloth and cuts with a knife
whatever is cleaned or cut; where a thing goes depends on the thing. On the external sets the
term had moved only tools the wrong way (4 COAT items: the cloth to a towel, the knife to a butter
knife), and none the right way.

The masked frames are read with the instruction's context too: what is taken out is what the verb and
all that was said favour without the stated filler ("It is too sweet. Can you dispose of it?": the bins
sweetness suggests whatever is thrown). WEIGHT = 0.75 was chosen among 0.5, 0.75 and 1 on the external
request sets (docs/guide/complete.md); nothing else is fitted: the LM is the product's own.

The term is 0 for the eleven hand-written predicates, as `verb_fillers` is. Measured with the Theme
masked and no role excepted, it raised their Table I (0.922 to 0.930) but cost a dev instruction: "heat
the milk" chose the glass, which milk goes with far more than a pot does, once the verb's own dislike of
heating in a glass was mostly taken out (a tool again). With tools excepted it gave Table I 0.926 and
the same dev instructions as without it, while a request's LM reading took half as long again or more
(the masked frames were then a second reading of as many texts: "pour me some water" among 40 objects,
p50 6.7 ms without the term, 10.6 ms with it): not worth it where it changes nothing the dev sets see.
The masked frames are now read in the sentence LM's own pass (`lm_frames`, `registry.SharedLM`).
"""

from __future__ import annotations

from collections.abc import Callable, Collection

from lmcr.frame import Frame
from lmcr.scorers.within_role import centred, role_sets

WEIGHT = 0.75
PLACEHOLDER = "it"  # what a stated filler is said as: an object pronoun the sentence templates read as such
# the roles whose candidates the term leaves to the verb's own preference (see the module's docstring)
TOOLS = frozenset({"Instrument"})

LMScores = Callable[..., list[float]]


def stated_roles(group: list[Frame]) -> list[str]:
    """The roles a group of frames (one predicate, one role set) fills alike: what the request stated. The
    Theme when every role varies; none when no role does (nothing to rank)."""
    maps = [f.role_map for f in group]
    alike = [r for r in maps[0] if len({m[r] for m in maps}) == 1]
    if len(alike) == len(maps[0]):
        return []
    return alike or ["Theme"]


def masked(frame: Frame, roles: Collection[str]) -> Frame:
    """The frame with the fillers of `roles` said as "it"."""
    return Frame.of(frame.predicate, {r: PLACEHOLDER if r in roles else v for r, v in frame.roles})


def _read(frame: Frame, learned: Collection[str]) -> bool:
    """Whether the term reads a frame's group: a learned predicate's, with a Theme and another role."""
    return frame.predicate in learned and "Theme" in frame.role_map and len(frame.roles) > 1


class StatedPMI:
    """The term over the sentence LM's frame scorer `lm` (frames and the instruction's context): for the
    frames of the `learned` predicates that have a Theme and another role and whose candidates fill no
    tool role; 0 for the others (the eleven among them). `lm_frames` are the masked frames it reads: a sum
    with the sentence LM reads them in the LM's own pass (`registry.SummedScorer`)."""

    def __init__(self, lm: LMScores, learned: Collection[str], weight: float = WEIGHT):
        self.lm, self.learned, self.weight = lm, learned, weight

    def _masked(self, frames: list[Frame]) -> tuple[list[list[int]], dict[int, Frame]]:
        """(the role sets it reads, the masked frame of each of their frames)."""
        groups = [g for g in role_sets(frames) if _read(frames[g[0]], self.learned)]
        nulls: dict[int, Frame] = {}
        for members in groups:
            hide = stated_roles([frames[i] for i in members])
            if hide and not TOOLS & (set(frames[members[0]].role_map) - set(hide)):
                nulls |= {i: masked(frames[i], hide) for i in members}
        return groups, nulls

    def lm_frames(self, frames: list[Frame]) -> list[Frame]:
        """The masked frames the term reads for `frames` (`_distinct`)."""
        return _distinct(self._masked(frames)[1])

    def __call__(self, frames: list[Frame], context: str = "") -> list[float]:
        groups, nulls = self._masked(frames)
        texts = _distinct(nulls)
        logp = dict(zip(texts, self.lm(texts, context))) if texts else {}
        return centred({i: -logp[null] for i, null in nulls.items()}, groups, len(frames), self.weight)


def _distinct(nulls: dict[int, Frame]) -> list[Frame]:
    """The masked frames, each once, in a fixed order: when the Theme is masked, the candidates for one
    place share one."""
    return sorted(set(nulls.values()), key=lambda n: n.key)


def stated_pmi_scorer(lm: LMScores, learned: Collection[str], weight: float = WEIGHT) -> StatedPMI:
    """The term (`StatedPMI`) over the sentence LM's frame scorer `lm`, for the `learned` predicates."""
    return StatedPMI(lm, learned, weight)
