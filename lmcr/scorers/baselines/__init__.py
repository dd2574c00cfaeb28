"""The paper's baselines (section III-E), each scoring complete frames like the language models do."""
