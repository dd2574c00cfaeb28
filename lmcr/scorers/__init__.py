"""Frame scorers behind one interface: complete frames in, one float each out (higher = more plausible).

`registry` names every method and builds its scorer from `resources` (what the scorers read: checkpoints,
the store, vectors, ConceptNet); `lm_checkpoints` finds the language models an LM scorer loads and
`caches` what count-based scorers keep on disk. The project's own scorers are flat modules here
(`frame_counts`, `similar_verbs`, `rarity`, `context_pmi`, with `mixture` weighing the corpora they
pool); the paper's baselines (section III-E) are the subpackage `baselines`, apart because they are
what the method is compared against, never part of the default completion, and share helpers (terms,
vectors, retrofitting) that nothing else uses.
"""
