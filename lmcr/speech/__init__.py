"""Speech in, offline: WAV audio -> a domain language model constrains pocketsphinx -> a transcript with
its n-best list and confidence, which the SRL parser turns into frames.

`audio` reads and checks WAV files, `domain_lm` builds the versioned n-gram model from the corpora
and the lexicon, `recognize` decodes with it.
"""
